#pragma once
// Ambient-occlusion bakes for the explorer, run on a background thread so the window
// stays responsive and shows the bake's progress. Results are kept per (mesh, rays); the
// disk cache (core/ambient_occlusion.h) makes a second look-up instant. GL-free.
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent::explorer {

class AmbientOcclusionBakes {
public:
    AmbientOcclusionBakes() = default;
    ~AmbientOcclusionBakes();  // waits for a running bake
    AmbientOcclusionBakes(const AmbientOcclusionBakes&) = delete;
    AmbientOcclusionBakes& operator=(const AmbientOcclusionBakes&) = delete;

    // The per-vertex AO of (mesh, rays) when ready; otherwise starts its bake (one at a
    // time) and returns nullptr.
    const std::vector<float>* find_or_start(const std::shared_ptr<const Mesh>& mesh,
                                            int rays);
    // Drops every result and bakes again without the disk cache ("re-bake").
    void forget_all() { forget_ = true; }
    bool busy() const { return running_; }
    float progress() const { return progress_; }  // of the running bake, in [0, 1]
    std::string error() const;                    // of the last failed bake, else ""

private:
    static std::string key(const Mesh& mesh, int rays);
    void collect();  // moves a finished bake's result into results_

    std::map<std::string, std::vector<float>> results_;
    std::thread worker_;
    std::atomic<bool> running_{false};
    std::atomic<float> progress_{0.f};
    bool forget_ = false;
    bool fresh_ = false;
    mutable std::mutex mutex_;  // guards the fields below, written by the worker
    std::string finished_key_;
    std::vector<float> finished_;
    std::string error_;
    std::string failed_key_;  // not retried until forget_all()
};

}  // namespace lucent::explorer
