#include "study/adaptive/staircase_block.h"

#include <algorithm>
#include <stdexcept>

#include "study/adaptive/quest.h"

namespace lucent::study::adaptive {

double guess_rate(const Block& block) { return 1.0 / block.answers(); }

std::unique_ptr<AdaptiveProcedure> make_procedure(const Block& block,
                                                  const Block::Procedure& p) {
    if (p.method == "quest") {
        QuestSettings q;
        q.start = p.start;
        q.start_sd = p.start_sd;
        q.p_threshold = p.p_threshold;
        q.n_trials = p.n_trials;
        q.beta = p.beta;
        q.delta = p.delta;
        q.gamma = guess_rate(block);
        q.grain = p.grain;
        // The grid reaches every delta the block allows, wherever the prior is centred.
        q.range = p.quest_range > 0 ? p.quest_range : 2 * (p.max_delta - p.min_delta);
        q.min_value = p.min_delta;
        q.max_value = p.max_delta;
        return std::make_unique<Quest>(q);
    }
    StaircaseSettings s;
    s.start = p.start;
    s.n_up = p.n_up;
    s.n_down = p.n_down;
    s.step_sizes = p.step_sizes;
    s.step_type = parse_step_type(p.step_type);
    s.min_value = p.min_delta;
    s.max_value = p.max_delta;
    s.n_trials = p.n_trials;
    if (p.n_reversals > 0) s.n_reversals = p.n_reversals;
    return std::make_unique<Staircase>(s);
}

StaircaseBlock::StaircaseBlock(const Block& block) : block_(block.id) {
    if (block.task != Task::staircase)
        throw std::invalid_argument("block '" + block.id + "' is not a staircase block");
    for (const std::string& standard : block.stimuli)
        for (const Block::Procedure& p : block.procedures)
            procedures_[standard + "/" + p.id] = make_procedure(block, p);
}

void StaircaseBlock::replay(const std::vector<TrialRow>& trials) {
    std::vector<const TrialRow*> answered;
    for (const TrialRow& t : trials)
        if (t.block == block_ && t.answered && !t.skipped && !t.practice)
            answered.push_back(&t);
    std::sort(answered.begin(), answered.end(), [](const TrialRow* a, const TrialRow* b) {
        return a->position < b->position;
    });
    for (const TrialRow* t : answered) {
        const std::string where =
            "block '" + block_ + "', trial " + std::to_string(t->position + 1);
        if (!has(t->staircase))
            throw std::runtime_error(where + ": staircase '" + t->staircase +
                                     "' is not one of the block's");
        if (!t->intensity || !t->choice)
            throw std::runtime_error(where +
                                     ": answered without its delta or its choice");
        AdaptiveProcedure& p = at(t->staircase);
        if (p.finished())
            throw std::runtime_error(where + ": staircase '" + t->staircase +
                                     "' had already finished");
        p.next();
        p.add_response(*t->choice == t->expected, *t->intensity);
    }
}

Proposal StaircaseBlock::propose(const std::string& label) { return at(label).next(); }

bool StaircaseBlock::answer(const std::string& label, bool correct,
                            std::optional<double> shown) {
    AdaptiveProcedure& p = at(label);
    p.add_response(correct, shown);
    return p.finished();
}

bool StaircaseBlock::finished(const std::string& label) const {
    return at(label).finished();
}

const AdaptiveProcedure& StaircaseBlock::procedure(const std::string& label) const {
    return at(label);
}

std::vector<std::string> StaircaseBlock::labels() const {
    std::vector<std::string> out;
    for (const auto& [label, p] : procedures_) out.push_back(label);
    return out;
}

AdaptiveProcedure& StaircaseBlock::at(const std::string& label) const {
    const auto it = procedures_.find(label);
    if (it == procedures_.end())
        throw std::out_of_range("block '" + block_ + "': no staircase '" + label + "'");
    return *it->second;
}

}  // namespace lucent::study::adaptive
