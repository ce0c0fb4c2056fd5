#include "study/trials/rating/rating_trials.h"

#include "study/trial_plan.h"

namespace lucent::study {
namespace {

class RatingKind : public TrialKind {
public:
    const char* name() const override { return "rating"; }
    bool is_choice() const override { return false; }
    bool is_scaling() const override { return false; }
    bool rated_on_questions() const override { return true; }
    int pictures_per_trial() const override { return 1; }
    int answers(const Block&) const override { return 0; }
    TrialScreen screen() const override { return TrialScreen::scales; }
    const char* analysed_as() const override { return "ratings"; }
    std::vector<Question> questions(const Protocol& protocol,
                                    const Block*) const override {
        return protocol.questions;
    }
    // A rating block has no keys of its own: its questions are the protocol's.
    void read_block(const Protocol&, TableReader&, Block&) const override {}
    // Each stimulus `repeats` times, then the block's catch trials.
    std::vector<PlannedTrial> plan_block(const Protocol& protocol, const Block& block,
                                         std::mt19937_64&) const override {
        std::vector<PlannedTrial> trials;
        for (int r = 0; r < block.repeats; ++r)
            for (const std::string& id : block.stimuli) {
                PlannedTrial t;
                t.block = block.id;
                t.stimulus = id;
                trials.push_back(t);
            }
        for (const CatchTrial& c : protocol.catch_trials) {
            if (c.block != block.id) continue;
            PlannedTrial t;
            t.block = block.id;
            t.stimulus = c.stimulus;
            t.is_catch = true;
            t.catch_id = c.id;
            t.prompt = c.prompt;
            t.expected = c.expected;
            t.tolerance = c.tolerance;
            trials.push_back(t);
        }
        return trials;
    }
};

}  // namespace

const TrialKind& rating_trial_kind() {
    static const RatingKind kind;
    return kind;
}

}  // namespace lucent::study
