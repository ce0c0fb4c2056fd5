// A trial kind that only this test defines, registered with one line: the protocol reads
// its block's own keys, refuses its bad values with file, line and key, lists it among
// the tasks; the plan lays its trials out and shuffles them as the kind says; a store
// keeps its answers (refusing what the kind does not carry) and the observation table
// reads them back. Its own binary, so the other suites never see the extra kind.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "study/observations.h"
#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"
#include "study/trials/trial_kind.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// "probe": one picture, a yes/no question about it; its key `flashes` (1..5) is how
// often each stimulus is probed per repeat.
class ProbeKind : public TrialKind {
public:
    const char* name() const override { return "probe"; }
    bool is_choice() const override { return false; }
    bool is_scaling() const override { return false; }
    int pictures_per_trial() const override { return 1; }
    int answers(const Block&) const override { return 2; }
    void read_block(const Protocol& p, TableReader& keys, Block& b) const override {
        read_block_question(p, keys, b);
        b.neighbours = keys.integer("flashes", 1, 1, 5);  // an integer field it may use
    }
    std::vector<PlannedTrial> plan_block(const Protocol&, const Block& b,
                                         std::mt19937_64&) const override {
        std::vector<PlannedTrial> trials;
        for (int r = 0; r < b.repeats * b.neighbours; ++r)
            for (const std::string& id : b.stimuli) {
                PlannedTrial t;
                t.block = b.id;
                t.task = task();
                t.stimulus = id;
                t.shown = {id};
                trials.push_back(t);
            }
        return trials;
    }
    static Task task();
};

const ProbeKind kProbe;
const TrialKindRegistration kProbeRegistration(kProbe);  // the one registry line
Task ProbeKind::task() { return kProbeRegistration.task(); }

const char* kProbeProtocol = R"toml(
[study]
name = "probes"

[[stimuli]]
id = "a"
image = "a.png"

[[stimuli]]
id = "b"
image = "b.png"

[[blocks]]
id = "probes"
task = "probe"
stimuli = ["a", "b"]
question = "Did it flicker?"
repeats = 2
flashes = 3
)toml";

std::string error_of(const std::string& text) {
    try {
        parse_protocol(text, "probe.toml", "", KnobCheck::lenient);
    } catch (const ProtocolError& e) {
        return e.what();
    }
    return "";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
}

TEST(TrialKinds, TheBuiltInConstantsNameTheirKindsInTheRegistrysOrder) {
    const std::vector<Task> tasks = all_tasks();
    ASSERT_GE(tasks.size(), 7u);
    const char* names[] = {"rating", "pair", "triad", "quadruple", "adjust", "staircase"};
    const Task constants[] = {Task::rating,    Task::pair,   Task::triad,
                              Task::quadruple, Task::adjust, Task::staircase};
    for (int i = 0; i < 6; ++i) {
        EXPECT_EQ(tasks[i], constants[i]) << names[i];
        EXPECT_STREQ(task_name(constants[i]), names[i]);
        EXPECT_EQ(parse_task(names[i]), constants[i]) << names[i];
    }
    EXPECT_EQ(pictures_per_trial(Task::quadruple), 4);
    EXPECT_TRUE(is_scaling_task(Task::triad));
    EXPECT_FALSE(is_scaling_task(Task::staircase));
    EXPECT_TRUE(is_choice_task(Task::staircase));
    EXPECT_FALSE(is_choice_task(Task::adjust));
}

TEST(TrialKinds, ARegisteredKindIsNamedAndParsedLikeABuiltIn) {
    EXPECT_EQ(parse_task("probe"), ProbeKind::task());
    EXPECT_EQ(all_tasks().back(), ProbeKind::task());
    EXPECT_STREQ(task_name(ProbeKind::task()), "probe");
    const std::string names = task_names_text();
    EXPECT_NE(names.find("\"staircase\" or \"probe\""), std::string::npos) << names;
    // An unknown task's message lists the registered kind too.
    const std::string e =
        error_of(replaced(kProbeProtocol, "task = \"probe\"", "task = \"probes\""));
    EXPECT_NE(e.find("probe.toml:"), std::string::npos) << e;
    EXPECT_NE(e.find("key 'blocks.task'"), std::string::npos) << e;
    EXPECT_NE(e.find("or \"probe\", got 'probes'"), std::string::npos) << e;
}

TEST(TrialKinds, TheProtocolReadsTheKindsOwnKeysAndRefusesItsBadOnes) {
    const Protocol p =
        parse_protocol(kProbeProtocol, "probe.toml", "", KnobCheck::lenient);
    ASSERT_EQ(p.blocks.size(), 1u);
    const Block& b = p.blocks[0];
    EXPECT_EQ(b.task, ProbeKind::task());
    EXPECT_EQ(b.neighbours, 3);
    EXPECT_EQ(b.question, "Did it flicker?");
    EXPECT_EQ(b.question_id, "probes");
    EXPECT_EQ(b.answers(), 2);
    EXPECT_EQ(b.pictures(), 1);
    EXPECT_FALSE(p.has_rating_trials());  // no [[questions]] needed

    const std::string range =
        error_of(replaced(kProbeProtocol, "flashes = 3", "flashes = 9"));
    EXPECT_NE(range.find("probe.toml:19:"), std::string::npos) << range;
    EXPECT_NE(range.find("key 'blocks.flashes': must lie in [1, 5], got 9"),
              std::string::npos)
        << range;
    const std::string unknown =
        error_of(replaced(kProbeProtocol, "flashes = 3", "flashes = 3\nflash = 2"));
    EXPECT_NE(unknown.find("key 'blocks.flash': unknown key"), std::string::npos)
        << unknown;
    const std::string question =
        error_of(replaced(kProbeProtocol, "question = \"Did it flicker?\"\n", ""));
    EXPECT_NE(question.find("key 'blocks.question': is required"), std::string::npos)
        << question;
}

TEST(TrialKinds, ThePlanLaysOutAndShufflesTheKindsTrials) {
    const Protocol p =
        parse_protocol(kProbeProtocol, "probe.toml", "", KnobCheck::lenient);
    const TrialPlan plan = plan_trials(p, 7, 0);
    ASSERT_EQ(plan.trials.size(), 12u);  // 2 stimuli x 2 repeats x 3 flashes
    std::map<std::string, int> count;
    for (const PlannedTrial& t : plan.trials) {
        EXPECT_EQ(t.task, ProbeKind::task());
        EXPECT_EQ(t.shown, std::vector<std::string>{t.stimulus});
        ++count[t.stimulus];
    }
    EXPECT_EQ(count, (std::map<std::string, int>{{"a", 6}, {"b", 6}}));
    // Shuffled (the kind keeps the default), and differently for another seed.
    std::set<std::vector<std::string>> orders;
    for (uint64_t seed = 1; seed <= 5; ++seed) {
        std::vector<std::string> order;
        for (const PlannedTrial& t : plan_trials(p, seed, 0).trials)
            order.push_back(t.stimulus);
        orders.insert(order);
    }
    EXPECT_GT(orders.size(), 1u);
}

TEST(TrialKinds, AStoreKeepsTheKindsAnswersAndTheObservationsReadThemBack) {
    const Protocol p =
        parse_protocol(kProbeProtocol, "probe.toml", "", KnobCheck::lenient);
    const auto dir = lucent::test::scratch_dir("registered_kind_store");
    const std::string path = (dir / "probe.db").string();
    {
        Store store(path);
        lucent::test::run_full_session(store, p, "P1", 3);
        // What the kind does not carry is refused, as for every built-in.
        const int64_t study = store.ensure_study(p);
        int number = 0;
        const int64_t pid = store.ensure_participant(study, "P2", &number);
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p, 4, number), 4, {});
        const TrialRow first = store.trials(s.id).front();
        EXPECT_EQ(first.task, ProbeKind::task());
        TrialOutcome outcome = lucent::test::outcome_for(p, first);
        outcome.final_value = 0.5;
        try {
            store.record_trial(s.id, first.id, outcome);
            ADD_FAILURE() << "a final value on a probe trial was stored";
        } catch (const StoreError& e) {
            EXPECT_NE(
                std::string(e.what()).find("is a probe trial but carries a final value"),
                std::string::npos)
                << e.what();
        }
    }
    const StudyObservations read = read_observations(path, {});
    std::map<std::string, int> answers;  // stimulus -> answers
    for (const common::Observation& row : read.table.rows) {
        if (row.participant != "P1") continue;
        EXPECT_EQ(row.kind, "probe");
        EXPECT_EQ(row.question, "probes");
        ASSERT_TRUE(row.response);
        EXPECT_TRUE(*row.response == 1 || *row.response == 2) << *row.response;
        ++answers[row.shown.at(0)];
    }
    EXPECT_EQ(answers, (std::map<std::string, int>{{"a", 6}, {"b", 6}}));
}

TEST(TrialKinds, ASecondKindOfTheSameNameIsRefused) {
    class Impostor : public ProbeKind {
    public:
        const char* name() const override { return "pair"; }
    };
    static const Impostor impostor;
    EXPECT_THROW(TrialKindRegistration{impostor}, std::logic_error);
}

}  // namespace
}  // namespace lucent::study
