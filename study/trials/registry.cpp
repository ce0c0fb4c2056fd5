// Every trial kind, one line each. The built-ins' order is their Task constants'
// (trial_kind.h); the check below refuses a list that disagrees with them.
#include <array>
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/trials/adjust/adjust_trials.h"
#include "study/trials/choice/choice_trials.h"
#include "study/trials/rating/rating_trials.h"
#include "study/trials/staircase/staircase_trials.h"
#include "study/trials/trial_kind.h"

namespace lucent::study {
namespace {

struct BuiltIn {
    Task task;
    const TrialKind& (*kind)();
};

constexpr BuiltIn kBuiltIns[] = {
    {Task::rating, rating_trial_kind}, {Task::pair, pair_trial_kind},
    {Task::triad, triad_trial_kind},   {Task::quadruple, quadruple_trial_kind},
    {Task::adjust, adjust_trial_kind}, {Task::staircase, staircase_trial_kind},
};

// A Task is looked up on every question asked of its kind: a fixed table read without
// a lock; registering (rare, at start-up) takes the mutex.
struct Registry {
    std::mutex mutex;
    std::array<std::atomic<const TrialKind*>, 256> kinds{};
    std::atomic<std::size_t> count = 0;
    Registry() {
        for (const BuiltIn& b : kBuiltIns) {
            if (b.task.index() != count)
                throw std::logic_error("trials/registry.cpp: built-in kind '" +
                                       std::string(b.kind().name()) +
                                       "' is listed out of its Task constant's order");
            kinds[count++].store(&b.kind());
        }
    }
};

Registry& registry() {
    static Registry r;
    return r;
}

}  // namespace

const char* screen_name(TrialScreen screen) {
    switch (screen) {
        case TrialScreen::scales:
            return "scales";
        case TrialScreen::choice:
            return "choice";
        case TrialScreen::adjust:
            return "adjust";
        case TrialScreen::staircase:
            return "staircase";
    }
    return "scales";
}

std::vector<Question> TrialKind::questions(const Protocol&, const Block*) const {
    return {};
}

std::vector<std::vector<int>> TrialKind::answer_groups(const Block& block) const {
    std::vector<std::vector<int>> groups;
    for (int k = 0; k < pictures(block); ++k) groups.push_back({k});
    return groups;
}

const TrialKind& Task::kind() const {
    const TrialKind* kind = registry().kinds[index_].load(std::memory_order_acquire);
    if (!kind)
        throw std::logic_error("trial kind " + std::to_string(index_) +
                               " is not registered");
    return *kind;
}

std::vector<Task> all_tasks() {
    std::vector<Task> tasks;
    for (std::size_t i = 0; i < registry().count.load(); ++i)
        tasks.emplace_back(static_cast<std::uint8_t>(i));
    return tasks;
}

TrialKindRegistration::TrialKindRegistration(const TrialKind& kind) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const std::size_t n = r.count.load();
    for (std::size_t i = 0; i < n; ++i)
        if (std::string(r.kinds[i].load()->name()) == kind.name())
            throw std::logic_error(std::string("trial kind '") + kind.name() +
                                   "' is registered twice");
    if (n == r.kinds.size()) throw std::logic_error("more than 256 trial kinds");
    task_ = Task(static_cast<std::uint8_t>(n));
    r.kinds[n].store(&kind, std::memory_order_release);
    r.count.store(n + 1);
}

}  // namespace lucent::study
