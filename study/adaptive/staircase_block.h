#pragma once
// The adaptive procedures of one staircase block (issue 31) as a session runs them: one
// per standard and [[blocks.staircases]] entry, named "<standard>/<id>" as the plan's
// slots are. They hold no state of their own beyond the answers: a resumed session (or
// another station, or the browser) rebuilds them by replaying the answered slots in
// order, so the next delta is the same wherever the session goes on. GL-free.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "study/adaptive/staircase.h"
#include "study/protocol.h"
#include "study/store_types.h"

namespace lucent::study::adaptive {

// The guess rate of a staircase block's trials: 1/2 for a pair, 1/3 for an odd one out.
double guess_rate(const Block& block);

// A block's procedure as configured: a Staircase ("updown") or a Quest whose guess rate
// is the trial's. Deltas are held within [min_delta, max_delta].
std::unique_ptr<AdaptiveProcedure> make_procedure(const Block& block,
                                                  const Block::Procedure& procedure);

class StaircaseBlock {
public:
    // Throws std::invalid_argument naming the block when it is not a staircase block.
    explicit StaircaseBlock(const Block& block);

    // Replays the block's answered slots (`trials`: a session's trials, any order; other
    // blocks' and unanswered or skipped slots are ignored) in position order. Throws
    // std::runtime_error naming the trial when a slot's label is not one of the block's,
    // when an answered slot lacks its delta or its choice, or when its procedure had
    // already finished.
    void replay(const std::vector<TrialRow>& trials);

    bool has(const std::string& label) const { return procedures_.count(label) > 0; }
    // The delta of the next slot of `label`. Throws std::logic_error when the procedure
    // has finished or waits for an answer, std::out_of_range for an unknown label.
    Proposal propose(const std::string& label);
    // The answer to the slot last proposed for `label`; `shown` when the delta shown
    // differed (a pre-rendered ladder's nearest step). True when the procedure has now
    // finished: its remaining slots are to be skipped.
    bool answer(const std::string& label, bool correct,
                std::optional<double> shown = std::nullopt);
    bool finished(const std::string& label) const;
    const AdaptiveProcedure& procedure(const std::string& label) const;
    std::vector<std::string> labels() const;

private:
    AdaptiveProcedure& at(const std::string& label) const;

    std::string block_;
    std::map<std::string, std::unique_ptr<AdaptiveProcedure>> procedures_;
};

}  // namespace lucent::study::adaptive
