// A trial kind that only this test defines, registered with one line: the protocol reads
// its block's own keys, refuses its bad values with file, line and key, lists it among
// the tasks; the plan lays its trials out and shuffles them as the kind says; a store
// keeps its answers (refusing what the kind does not carry) and the observation table
// reads them back. Its own binary, so the other suites never see the extra kind.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/cli_main.h"
#include "app/commands.h"
#include "common/csv.h"
#include "study/observations.h"
#include "study/protocol.h"
#include "study/serve/web_study.h"
#include "study/session/session_flow.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"
#include "study/trials/trial_kind.h"
#include "tests/study/serve/web_page.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// "probe": one picture, a yes/no question about it on the scales screen (its own
// question, its labels the two points); its key `flashes` (1..5) is how often each
// stimulus is probed per repeat.
class ProbeKind : public TrialKind {
public:
    const char* name() const override { return "probe"; }
    bool is_choice() const override { return false; }
    bool is_scaling() const override { return false; }
    int pictures_per_trial() const override { return 1; }
    int answers(const Block&) const override { return 2; }
    TrialScreen screen() const override { return TrialScreen::scales; }
    const char* analysed_as() const override { return "ratings"; }
    std::vector<Question> questions(const Protocol&, const Block* b) const override {
        return {Question{b->question_id, b->question, b->labels}};
    }
    void read_block(const Protocol& p, TableReader& keys, Block& b) const override {
        read_block_question(p, keys, b);
        b.neighbours = keys.integer("flashes", 1, 1, 5);  // an integer field it may use
        b.labels = {"yes", "no"};
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
params = { contrast = 1 }

[[stimuli]]
id = "b"
image = "b.png"
params = { contrast = 2 }

[[blocks]]
id = "probes"
task = "probe"
stimuli = ["a", "b"]
question = "Did it flicker?"
repeats = 2
flashes = 3
)toml";

std::string error_of(const std::string& text) {
    return test::protocol_error_of(text, "probe.toml", KnobCheck::lenient);
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
    EXPECT_NE(range.find("probe.toml:21:"), std::string::npos) << range;
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

// The probe's answers as stored: (stimulus, rating) per trial, in trial order.
std::vector<std::pair<std::string, int>> stored_answers(const std::string& path) {
    Database db(path, SQLITE_OPEN_READONLY);
    Statement s = db.prepare(
        "SELECT st.stimulus_key, r.rating, r.question FROM responses r JOIN trials t ON "
        "t.id = r.trial_id JOIN stimuli st ON st.id = t.stimulus_id ORDER BY t.position");
    std::vector<std::pair<std::string, int>> out;
    while (s.step()) {
        EXPECT_EQ(s.text(2), "probes");
        out.emplace_back(s.text(0), static_cast<int>(s.integer(1)));
    }
    return out;
}

// The lab's flow (the runner draws what it says): each probe trial is the scales screen
// with the kind's own question and two points; digits answer it, one response each.
TEST(TrialKinds, TheLabFlowAsksTheKindsQuestionOnTheScalesScreen) {
    const Protocol p =
        parse_protocol(kProbeProtocol, "probe.toml", "", KnobCheck::lenient);
    const auto dir = lucent::test::scratch_dir("registered_kind_lab");
    const std::string path = (dir / "lab.db").string();
    Store store(path);
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study, "P1", &number);
    const SessionRow session =
        store.create_session(study, pid, plan_trials(p, 5, number), 5, {});
    store.set_consent(session.id);
    int64_t now = 1'000'000'000;
    SessionFlow flow(p, store, session.id, store.trials(session.id), true, now);
    std::vector<std::pair<std::string, int>> pressed;
    for (int guard = 0; guard < 5000 && !flow.finished(); ++guard) {
        now += 16'000'000;
        flow.tick(now);
        flow.presented(flow.serial(), now);
        if (flow.rating()) {
            const std::vector<Question> scales = flow.questions();
            ASSERT_EQ(scales.size(), 1u);
            EXPECT_EQ(scales[0].id, "probes");
            EXPECT_EQ(scales[0].text, "Did it flicker?");
            EXPECT_EQ(scales[0].points(), 2);
            EXPECT_EQ(flow.view().points, std::vector<int>{2});
            const int digit = 1 + static_cast<int>(pressed.size()) % 2;
            pressed.emplace_back(flow.trial()->stimulus, digit);
            flow.key({Key::Digit, 3, now += 50'000'000});  // off the scale: ignored
            flow.key({Key::Digit, digit, now += 50'000'000});
            flow.key({Key::Enter, 0, now += 50'000'000});
        } else if (flow.screen() != Screen::Trial && flow.screen() != Screen::Blank) {
            flow.key({Key::Enter, 0, now += 300'000'000});
        }
    }
    ASSERT_TRUE(flow.finished());
    EXPECT_EQ(pressed.size(), 12u);
    EXPECT_EQ(stored_answers(path), pressed);
}

// The page's side (WebStudy, as lucent serve answers lucent.js): the trial names the
// scales screen and carries the kind's question; the page's clicks are stored.
TEST(TrialKinds, ThePageGetsTheScalesScreenWithTheKindsQuestion) {
    const Protocol p = parse_protocol(
        std::string(kProbeProtocol) +
            "\n[screens]\nconsent = \"Do you agree?\"\n[online]\ncompletion_code = "
            "\"DONE\"\n",
        "probe.toml", "", KnobCheck::lenient);
    const auto dir = lucent::test::scratch_dir("registered_kind_page");
    const std::string path = (dir / "page.db").string();
    std::unique_ptr<StudyStore> store = open_study_store(path, StoreOptions{});
    WebStudyOptions o;
    o.secret = "test secret";
    o.environment.machine_id = "server";
    o.environment.software_version = "test";
    o.environment.build_hash = "test";
    for (const Stimulus& s : p.stimuli) o.images[s.id] = {64, 48};
    WebStudy web(p, *store, o);
    lucent::test::Page page{lucent::test::direct(web)};
    page.open({{"participant", "P1"}});
    int trials = 0;
    for (int guard = 0; guard < 100 && page.state["screen"] != "done"; ++guard) {
        if (page.state["screen"] != "trial") {
            page.enter();
            continue;
        }
        const nlohmann::json& trial = page.state["trial"];
        EXPECT_EQ(trial["screen"], "scales");
        EXPECT_EQ(trial["task"], "probe");
        ASSERT_EQ(trial["questions"].size(), 1u);
        EXPECT_EQ(trial["questions"][0]["id"], "probes");
        EXPECT_EQ(trial["questions"][0]["labels"], nlohmann::json::array({"yes", "no"}));
        page.answer(trials++);
    }
    ASSERT_EQ(page.state["screen"], "done");
    EXPECT_EQ(trials, 12);
    const std::vector<std::pair<std::string, int>> stored = stored_answers(path);
    ASSERT_EQ(stored.size(), 12u);
    for (size_t k = 0; k < stored.size(); ++k)  // the page's rating, on the 2 points
        EXPECT_EQ(stored[k].second,
                  std::min(2, lucent::test::page_rating(static_cast<int>(k), 0, false)))
            << k;
}

int run_lucent(std::vector<std::string> args) {
    args.insert(args.begin(), "lucent");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    return app::run_cli(static_cast<int>(argv.size()), argv.data(),
                        {app::register_analyze, app::register_export});
}

// Exported as every kind is (one row per answer, with the stimulus's factors), and
// analysed as its kind says (its answers are ratings of its question): the report's
// descriptives per level equal the stored answers' means, computed here in SQL.
TEST(TrialKinds, TheKindsAnswersAreExportedAndAnalysedAsItsKindSays) {
    const Protocol p =
        parse_protocol(kProbeProtocol, "probe.toml", "", KnobCheck::lenient);
    const auto dir = lucent::test::scratch_dir("registered_kind_analysis");
    const std::string path = (dir / "probe.db").string();
    {
        Store store(path);
        for (int k = 1; k <= 3; ++k)
            lucent::test::run_full_session(store, p, "P" + std::to_string(k), 10 + k);
    }
    const std::string csv = (dir / "observations.csv").string();
    ASSERT_EQ(run_lucent({"export", path, "--format", "observations", "--out", csv}), 0);
    std::ifstream exported(csv);
    std::string line;
    std::getline(exported, line);
    const std::vector<std::string> header = common::split_csv_line(line);
    const auto column = [&](const std::string& name) {
        return static_cast<size_t>(std::find(header.begin(), header.end(), name) -
                                   header.begin());
    };
    ASSERT_LT(column("contrast"), header.size()) << line;
    int rows = 0;
    while (std::getline(exported, line)) {
        const std::vector<std::string> f = common::split_csv_line(line);
        EXPECT_EQ(f[column("kind")], "probe");
        EXPECT_EQ(f[column("analysed_as")], "ratings");
        EXPECT_EQ(f[column("contrast")], f[column("shown")] == "a" ? "1" : "2");
        ++rows;
    }
    EXPECT_EQ(rows, 36);

    const std::string out = (dir / "report").string();
    ASSERT_EQ(run_lucent({"analyze", path, "--out", out, "--model", "anova"}), 0);
    std::map<std::string, double> expected;  // contrast level -> mean answer
    {
        Database db(path, SQLITE_OPEN_READONLY);
        Statement s = db.prepare(
            "SELECT sp.value, avg(r.rating) FROM responses r JOIN trials t ON t.id = "
            "r.trial_id JOIN stimulus_parameters sp ON sp.stimulus_id = t.stimulus_id "
            "WHERE sp.name = 'contrast' AND t.practice = 0 GROUP BY sp.value");
        while (s.step()) expected[s.text(0)] = s.real(1);
    }
    ASSERT_EQ(expected.size(), 2u);
    std::ifstream descriptives(std::filesystem::path(out) / "descriptives.csv");
    std::getline(descriptives, line);
    const std::vector<std::string> desc_header = common::split_csv_line(line);
    std::map<std::string, double> reported;
    while (std::getline(descriptives, line)) {
        const std::vector<std::string> f = common::split_csv_line(line);
        std::map<std::string, std::string> cell;
        for (size_t i = 0; i < f.size() && i < desc_header.size(); ++i)
            cell[desc_header[i]] = f[i];
        if (cell["question"] == "probes" && cell["factor"] == "contrast")
            reported[cell["level"]] = std::stod(cell["mean"]);
    }
    ASSERT_EQ(reported.size(), 2u) << "no descriptives of the probe's answers";
    for (const auto& [level, mean] : expected) EXPECT_NEAR(reported[level], mean, 1e-12);
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
