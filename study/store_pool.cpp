#include "study/store_pool.h"

#include <stdexcept>

namespace lucent::study {

StorePool::StorePool(const std::string& db, size_t connections,
                     const StoreOptions& options, std::chrono::milliseconds wait)
    : wait_(wait) {
    if (connections == 0)
        throw std::invalid_argument("a store pool needs at least one connection");
    for (size_t i = 0; i < connections; ++i) {
        owned_.push_back(open_study_store(db, options));
        all_.push_back(owned_.back().get());
    }
    free_ = all_;
}

StorePool::StorePool(StudyStore& store, std::chrono::milliseconds wait)
    : all_{&store}, free_{&store}, wait_(wait) {}

StorePool::Lease::Lease(Lease&& other) noexcept
    : pool_(other.pool_), store_(other.store_) {
    other.pool_ = nullptr;
}

StorePool::Lease::~Lease() {
    if (pool_) pool_->give_back(*store_);
}

StorePool::Lease StorePool::lease() {
    std::unique_lock lock(mutex_);
    if (!freed_.wait_for(lock, wait_, [&] { return !free_.empty(); }))
        throw StoreUnavailable(name() + ": all " + std::to_string(all_.size()) +
                               " store connections stayed busy for " +
                               std::to_string(wait_.count()) + " ms");
    StudyStore* store = free_.back();
    free_.pop_back();
    return Lease(*this, *store);
}

void StorePool::give_back(StudyStore& store) {
    {
        std::lock_guard lock(mutex_);
        free_.push_back(&store);
    }
    freed_.notify_one();
}

}  // namespace lucent::study
