#include "stimuli/explorer/ao_bakes.h"

#include "renderer/core/ambient_occlusion.h"

namespace lucent::explorer {

AmbientOcclusionBakes::~AmbientOcclusionBakes() {
    if (worker_.joinable()) worker_.join();
}

std::string AmbientOcclusionBakes::key(const Mesh& mesh, int rays) {
    return mesh.content_hash + "/" + std::to_string(mesh.vertex_count()) + "/r" +
           std::to_string(rays);
}

std::string AmbientOcclusionBakes::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

void AmbientOcclusionBakes::collect() {
    if (running_ || !worker_.joinable()) return;
    worker_.join();
    std::lock_guard lock(mutex_);
    if (!finished_key_.empty()) results_[finished_key_] = std::move(finished_);
    finished_key_.clear();
    finished_.clear();
}

const std::vector<float>* AmbientOcclusionBakes::find_or_start(
    const std::shared_ptr<const Mesh>& mesh, int rays) {
    collect();
    if (forget_ && !running_) {
        results_.clear();
        forget_ = false;
        std::lock_guard lock(mutex_);
        failed_key_.clear();
        fresh_ = true;
    }
    const std::string wanted = key(*mesh, rays);
    if (auto it = results_.find(wanted); it != results_.end()) return &it->second;
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
    worker_ = std::thread([this, mesh, rays, wanted, fresh] {
        AoBakeOptions options;
        options.rays = rays;
        options.progress = [this](std::size_t done, std::size_t total) {
            progress_ =
                total ? static_cast<float>(done) / static_cast<float>(total) : 1.f;
        };
        try {
            std::vector<float> ao = fresh
                                        ? bake_ambient_occlusion(*mesh, options)
                                        : load_or_bake_ambient_occlusion(*mesh, options);
            std::lock_guard lock(mutex_);
            finished_key_ = wanted;
            finished_ = std::move(ao);
        } catch (const std::exception& e) {
            std::lock_guard lock(mutex_);
            error_ = std::string("ambient occlusion: ") + e.what();
            failed_key_ = wanted;
        }
        running_ = false;
    });
    return nullptr;
}

}  // namespace lucent::explorer
