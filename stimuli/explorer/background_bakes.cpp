#include "stimuli/explorer/background_bakes.h"

namespace lucent::explorer {

BackgroundBakes::~BackgroundBakes() {
    if (worker_.joinable()) worker_.join();
}

std::string BackgroundBakes::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

void BackgroundBakes::collect() {
    if (running_ || !worker_.joinable()) return;
    worker_.join();
    std::lock_guard lock(mutex_);
    if (!finished_key_.empty()) results_[finished_key_] = std::move(finished_);
    finished_key_.clear();
    finished_ = {};
}

const TextureData* BackgroundBakes::find(const std::string& content_hash) const {
    auto it = results_.find(content_hash);
    return it == results_.end() ? nullptr : &it->second;
}

const TextureData* BackgroundBakes::find_or_start(const Pass& upload) {
    collect();
    if (forget_ && !running_) {
        results_.clear();
        forget_ = false;
        std::lock_guard lock(mutex_);
        failed_key_.clear();
        fresh_ = true;
    }
    const std::string wanted = upload.data.content_hash;
    if (const TextureData* data = find(wanted)) return data;
    if (running_) return nullptr;
    {
        std::lock_guard lock(mutex_);
        if (failed_key_ == wanted) return nullptr;
        error_.clear();
    }
    running_ = true;
    progress_ = 0.f;
    const bool fresh = fresh_;
    fresh_ = false;
    // The producer owns what it reads (the mesh by shared pointer), so it may outlive
    // the frame that planned it.
    worker_ =
        std::thread([this, source = upload.data, name = upload.name, wanted, fresh] {
            ProduceOptions options;
            options.use_caches = !fresh;
            options.progress = [this](std::size_t done, std::size_t total) {
                progress_ =
                    total ? static_cast<float>(done) / static_cast<float>(total) : 1.f;
            };
            try {
                TextureData data = source.produce(options);
                std::lock_guard lock(mutex_);
                finished_key_ = wanted;
                finished_ = std::move(data);
            } catch (const std::exception& e) {
                std::lock_guard lock(mutex_);
                error_ = name + ": " + e.what();
                failed_key_ = wanted;
            }
            running_ = false;
        });
    return nullptr;
}

}  // namespace lucent::explorer
