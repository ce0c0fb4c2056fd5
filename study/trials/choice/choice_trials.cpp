#include "study/trials/choice/choice_trials.h"

#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/portable_random.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"

namespace lucent::study {

using common::portable_shuffle;
using common::uniform_below;

namespace {

// The keys of a pair, triad or quadruple block (design notes: Block in protocol.h).
void read_choice_block(const Protocol& p, TableReader& r, Block& b) {
    read_block_question(p, r, b);
    const std::string task = task_name(b.task);
    const int n = static_cast<int>(b.stimuli.size());
    const int shown = pictures_per_trial(b.task);
    if (n < shown)
        r.fail(r.raw().get("stimuli"), "stimuli",
               "a " + task + " block needs at least " + std::to_string(shown) +
                   " stimuli, got " + std::to_string(n));
    b.design = r.string("design", "all");
    if (b.design != "all" && !(b.task == Task::pair && b.design == "cyclic"))
        r.fail(r.raw().get("design"), "design",
               b.task == Task::pair
                   ? "must be \"all\" or \"cyclic\", got '" + b.design + "'"
                   : "must be \"all\" for a " + task + " block, got '" + b.design + "'");
    b.neighbours = r.integer("neighbours", 0, 0, 100000);
    if (b.design == "cyclic") {
        // (i, i+d) and (i, i+n-d) are the same pairs: d up to n/2 gives every pair once.
        if (b.neighbours < 1 || b.neighbours > n / 2)
            r.fail(r.raw().get("neighbours"), "neighbours",
                   "a cyclic design needs 1 <= neighbours <= " + std::to_string(n / 2) +
                       " for " + std::to_string(n) + " stimuli");
    } else if (r.raw().get("neighbours")) {
        r.fail(r.raw().get("neighbours"), "neighbours", "only a cyclic design has them");
    }
    read_presentation(r, b, shown, b.task != Task::pair);
    b.identical_catch = r.integer("identical_catch", 0, 0, 1000);
    if (b.identical_catch > 0 && b.task != Task::pair)
        r.fail(r.raw().get("identical_catch"), "identical_catch",
               "only pair blocks have identical-pair catch trials");
    b.obvious_catch = r.strings("obvious_catch");
    if (!b.obvious_catch.empty()) {
        if (b.obvious_catch.size() != 2 || b.obvious_catch[0] == b.obvious_catch[1])
            r.fail(r.raw().get("obvious_catch"), "obvious_catch",
                   "must name two different stimuli: [low, high]");
        for (const std::string& id : b.obvious_catch)
            check_stimulus_ref(p, r, "obvious_catch", id);
    }
    b.obvious_catch_repeats =
        r.integer("obvious_catch_repeats", b.obvious_catch.empty() ? 0 : 1, 0, 1000);
    if (b.obvious_catch.empty() && b.obvious_catch_repeats > 0)
        r.fail(r.raw().get("obvious_catch_repeats"), "obvious_catch_repeats",
               "needs obvious_catch");
    b.series = r.string("series", "");
    if (!b.series.empty()) {
        std::optional<double> previous;
        for (const std::string& id : b.stimuli) {
            const std::optional<double> v = p.numeric_parameter(id, b.series);
            if (!v)
                r.fail(
                    r.raw().get("series"), "series",
                    "stimulus '" + id + "' has no numeric parameter '" + b.series + "'");
            if (b.task != Task::pair && previous && !(*v > *previous))
                r.fail(r.raw().get("stimuli"), "stimuli",
                       "an MLDS series must be listed in increasing '" + b.series +
                           "': '" + id + "' does not follow its predecessor");
            previous = v;
        }
    }
    b.practice = r.integer("practice", 0, 0, 100);
}

}  // namespace

namespace {

PlannedTrial choice_trial(const Block& block, std::vector<std::string> shown) {
    PlannedTrial t;
    t.block = block.id;
    t.task = block.task;
    t.stimulus = shown.front();
    t.shown = std::move(shown);
    return t;
}

// `count` orientations (false: the design's order), half of them flipped; an odd one
// out is flipped or not at random.
std::vector<char> balanced_flips(size_t count, std::mt19937_64& rng) {
    std::vector<char> flips(count);
    for (size_t i = 0; i < count; ++i) flips[i] = i % 2 == 1;
    if (count % 2 == 1) flips.back() = rng() % 2 == 1;
    portable_shuffle(flips, rng);
    return flips;
}

}  // namespace

std::vector<PlannedTrial> choice_block_trials(const Block& block, std::mt19937_64& rng) {
    const std::vector<std::string>& s = block.stimuli;
    const int n = static_cast<int>(s.size());
    // The design's groups, as indices into the series in increasing order.
    std::vector<std::vector<int>> groups;
    if (block.task == Task::pair && block.design == "cyclic") {
        for (int d = 1; d <= block.neighbours; ++d)
            for (int i = 0; i < n; ++i) {
                // With n even, d = n/2 pairs each stimulus with its opposite once, not
                // twice.
                if (2 * d == n && i >= d) continue;
                const int j = (i + d) % n;
                groups.push_back({std::min(i, j), std::max(i, j)});
            }
    } else {
        const int k = pictures_per_trial(block.task);
        std::vector<int> g(k);
        // Every increasing k-subset, in lexicographic order.
        std::function<void(int, int)> choose = [&](int from, int depth) {
            if (depth == k) {
                groups.push_back(g);
                return;
            }
            for (int i = from; i <= n - (k - depth); ++i) {
                g[depth] = i;
                choose(i + 1, depth + 1);
            }
        };
        choose(0, 0);
    }
    // Screen order: a pair's order, a triad forwards or backwards, a quadruple's pairs
    // which first; the two orientations of each group equally often over the repeats
    // (and over the groups when the repeats are odd).
    std::vector<PlannedTrial> trials;
    auto oriented = [&](const std::vector<int>& g, bool flip) {
        std::vector<std::string> shown;
        if (block.task == Task::quadruple) {
            const std::vector<int> order =
                flip ? std::vector<int>{g[2], g[3], g[0], g[1]} : g;
            for (int i : order) shown.push_back(s[i]);
        } else {
            for (int i : g) shown.push_back(s[i]);
            if (flip) std::reverse(shown.begin(), shown.end());
        }
        return shown;
    };
    for (int r = 0; r + 1 < block.repeats; r += 2)
        for (const std::vector<int>& g : groups) {
            trials.push_back(choice_trial(block, oriented(g, false)));
            trials.push_back(choice_trial(block, oriented(g, true)));
        }
    if (block.repeats % 2 == 1) {
        const std::vector<char> flips = balanced_flips(groups.size(), rng);
        for (size_t i = 0; i < groups.size(); ++i)
            trials.push_back(choice_trial(block, oriented(groups[i], flips[i])));
    }
    // Identical pairs: no right answer (they measure a preference for a side); the
    // stimuli taken in turn from a random start.
    const size_t start = n > 0 ? uniform_below(rng, static_cast<uint64_t>(n)) : 0;
    for (int i = 0; i < block.identical_catch; ++i) {
        const std::string& id = s[(start + i) % n];
        PlannedTrial t = choice_trial(block, {id, id});
        t.is_catch = true;
        t.catch_id = "identical";
        trials.push_back(t);
    }
    if (!block.obvious_catch.empty()) {
        const std::string& low = block.obvious_catch[0];
        const std::string& high = block.obvious_catch[1];
        const std::vector<char> flips = balanced_flips(block.obvious_catch_repeats, rng);
        for (char flip : flips) {
            std::vector<std::string> shown;
            int expected = 0;
            if (block.task == Task::pair)
                shown = {low, high};
            else if (block.task == Task::triad)  // (low, low) against (low, high)
                shown = {low, low, high};
            else
                shown = {low, low, low, high};
            expected = 2;
            if (flip) {
                if (block.task == Task::quadruple)
                    shown = {shown[2], shown[3], shown[0], shown[1]};
                else
                    std::reverse(shown.begin(), shown.end());
                expected = 1;
            }
            PlannedTrial t = choice_trial(block, shown);
            t.is_catch = true;
            t.catch_id = "obvious";
            t.expected = expected;
            trials.push_back(t);
        }
    }
    return trials;
}

namespace {

class ChoiceKind : public TrialKind {
public:
    ChoiceKind(const char* name, std::vector<std::vector<int>> groups)
        : name_(name), groups_(std::move(groups)) {
        for (const std::vector<int>& group : groups_)
            for (int k : group) pictures_ = std::max(pictures_, k + 1);
    }
    const char* name() const override { return name_; }
    bool is_choice() const override { return true; }
    bool is_scaling() const override { return true; }
    int pictures_per_trial() const override { return pictures_; }
    int answers(const Block&) const override { return static_cast<int>(groups_.size()); }
    TrialScreen screen() const override { return TrialScreen::choice; }
    std::vector<std::vector<int>> answer_groups(const Block&) const override {
        return groups_;
    }
    const char* analysed_as() const override { return "choices"; }
    void read_block(const Protocol& p, TableReader& keys, Block& b) const override {
        read_choice_block(p, keys, b);
    }
    std::vector<PlannedTrial> plan_block(const Protocol&, const Block& block,
                                         std::mt19937_64& rng) const override {
        return choice_block_trials(block, rng);
    }
    // The unordered set of stimuli: the same pair (group) shown either way is one level.
    std::string sequence_level(
        const PlannedTrial& trial,
        const std::map<std::string, std::string>& level_of_stimulus) const override {
        if (trial.shown.empty())
            return TrialKind::sequence_level(trial, level_of_stimulus);
        std::vector<std::string> ids = trial.shown;
        std::sort(ids.begin(), ids.end());
        std::string level = "choice";
        for (const std::string& id : ids) level += " " + id;
        return level;
    }

private:
    const char* name_;
    std::vector<std::vector<int>> groups_;
    int pictures_ = 0;
};

}  // namespace

const TrialKind& pair_trial_kind() {
    static const ChoiceKind kind("pair", {{0}, {1}});
    return kind;
}

const TrialKind& triad_trial_kind() {
    static const ChoiceKind kind("triad", {{0, 1}, {1, 2}});
    return kind;
}

const TrialKind& quadruple_trial_kind() {
    static const ChoiceKind kind("quadruple", {{0, 1}, {2, 3}});
    return kind;
}

}  // namespace lucent::study
