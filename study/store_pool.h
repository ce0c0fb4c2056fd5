#pragma once
// A bounded set of store connections shared by the threads of one process (`lucent
// serve`): each request borrows one store for its duration, so requests of different
// participants run at once, each in its own transactions, and a request beyond the pool
// waits a bounded time, then is told the store is busy (StoreUnavailable: 503 with
// Retry-After), never hangs. A pooled PostgreSQL store reconnects by itself after the
// server went away; an SQLite file takes its writers in turn under its busy timeout.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "study/study_store.h"

namespace lucent::study {

class StorePool {
public:
    // `connections` stores opened by the name `db` (open_study_store), each with
    // `options`; a request waits up to `wait` for one. Throws as opening does.
    StorePool(const std::string& db, size_t connections, const StoreOptions& options,
              std::chrono::milliseconds wait);
    // One store owned elsewhere, lent to one request at a time (tests, a single file).
    explicit StorePool(StudyStore& store,
                       std::chrono::milliseconds wait = std::chrono::seconds(2));
    StorePool(const StorePool&) = delete;
    StorePool& operator=(const StorePool&) = delete;

    // A borrowed store, given back when the lease ends.
    class Lease {
    public:
        Lease(Lease&& other) noexcept;
        Lease(const Lease&) = delete;
        Lease& operator=(const Lease&) = delete;
        Lease& operator=(Lease&&) = delete;
        ~Lease();
        StudyStore& operator*() const { return *store_; }
        StudyStore* operator->() const { return store_; }

    private:
        friend class StorePool;
        Lease(StorePool& pool, StudyStore& store) : pool_(&pool), store_(&store) {}
        StorePool* pool_;
        StudyStore* store_;
    };

    // A free store, waiting up to the pool's wait; StoreUnavailable (one line: how many
    // connections, how long it waited) when none came free.
    Lease lease();
    size_t size() const { return all_.size(); }
    std::chrono::milliseconds wait() const { return wait_; }
    // The store's name (file path or URI) for messages.
    const std::string& name() const { return all_.front()->name(); }

private:
    void give_back(StudyStore& store);

    std::vector<std::unique_ptr<StudyStore>> owned_;
    std::vector<StudyStore*> all_;
    std::vector<StudyStore*> free_;
    std::chrono::milliseconds wait_;
    std::mutex mutex_;
    std::condition_variable freed_;
};

}  // namespace lucent::study
