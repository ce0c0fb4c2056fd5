#pragma once
// The explorer's bakes (uploads of ProductionCost::bake: the AO, or any technique's), run
// on a background thread so the window stays responsive and shows the bake's progress.
// Results are kept by content hash; a disk cache behind the producer (the AO's,
// core/ambient_occlusion.h) makes a second look-up instant. GL-free: a FrameExecutor
// gets the results through its UploadProducer (view_renderer.cpp).
#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include "renderer/core/frame_plan.h"

namespace lucent::explorer {

class BackgroundBakes {
public:
    BackgroundBakes() = default;
    ~BackgroundBakes();  // waits for a running bake
    BackgroundBakes(const BackgroundBakes&) = delete;
    BackgroundBakes& operator=(const BackgroundBakes&) = delete;

    // The data of the bake `upload` (is_bake()) when ready; otherwise starts producing it
    // (one at a time) and returns nullptr.
    const TextureData* find_or_start(const Pass& upload);
    // A finished bake by content hash, or nullptr.
    const TextureData* find(const std::string& content_hash) const;
    // Drops every result and bakes again without caches ("re-bake").
    void forget_all() { forget_ = true; }
    bool busy() const { return running_; }
    float progress() const { return progress_; }  // of the running bake, in [0, 1]
    std::string error() const;                    // of the last failed bake, else ""

private:
    void collect();  // moves a finished bake's result into results_

    std::map<std::string, TextureData> results_;  // by content hash
    std::thread worker_;
    std::atomic<bool> running_{false};
    std::atomic<float> progress_{0.f};
    bool forget_ = false;
    bool fresh_ = false;
    mutable std::mutex mutex_;  // guards the fields below, written by the worker
    std::string finished_key_;
    TextureData finished_;
    std::string error_;
    std::string failed_key_;  // not retried until forget_all()
};

}  // namespace lucent::explorer
