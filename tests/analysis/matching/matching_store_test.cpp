// Matching and thresholds from a real study database (schema 7): sessions written
// through the store's API (open_study_store, create_session, record_trial with final
// values and adjustments, or the delta shown), a simulated matcher with a known bias and
// a simulated detector with a known threshold answering them; read back as
// the study's observations (study/observations.h) and analysed end to end into the
// report. Expected values are what the test recorded itself, never the store's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "analysis/data/long_table.h"
#include "analysis/data/matching_table.h"
#include "analysis/matching/matching_report.h"
#include "analysis/report/report.h"
#include "app/cli_main.h"
#include "app/commands.h"
#include "study/adaptive/staircase_block.h"
#include "study/observations.h"
#include "study/study_store.h"
#include "study/trial_plan.h"
#include "tests/analysis/matching/matching_fixtures.h"

namespace lucent::analysis {
namespace {

namespace fs = std::filesystem;

// The matches and staircases of a study database, as lucent analyze reads them.
MatchingTable read_matching(const std::string& db, const std::string& sessions = "") {
    try {
        study::StudyObservations read =
            study::read_observations(db, {.sessions = sessions});
        MatchingTable table = matching_of(read.table, std::move(read.protocol));
        table.sessions_note = read.selection.note;
        return table;
    } catch (const study::StoreError& e) {
        throw InputError(e.what());
    }
}

struct Recorded {
    std::vector<MatchRow> matches;
    std::vector<StaircaseRow> staircases;
};

// One session of `code`: every adjust trial matched by `matcher`, every staircase slot
// answered by `detector` through the block's procedures, until `stop_after` trials (then
// the session stays running). What was recorded is appended to `recorded`.
void run_session(study::StudyStore& store, const study::Protocol& p,
                 const std::string& code, uint64_t seed,
                 const study::MatchObserver& matcher,
                 const study::DetectionObserver& detector, Recorded& recorded,
                 int stop_after = -1) {
    const int64_t study_id = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study_id, code, &number);
    const study::SessionRow s = store.create_session(
        study_id, pid, study::plan_trials(p, seed, number), seed, {});
    const study::Block& m = *p.find_block("m");
    const study::Block& j = *p.find_block("j");
    study::adaptive::StaircaseBlock procedures(j);
    std::mt19937_64 rng(seed);
    int answered = 0;
    for (const study::TrialRow& t : store.trials(s.id)) {
        if (stop_after >= 0 && answered >= stop_after) break;
        study::TrialOutcome o;
        o.onset_ns = 1'000'000'000LL * (t.position + 1);
        o.confirm_ns = o.onset_ns + 1'500'000'000LL;
        study::Response r;
        r.rt_ms = 1500;
        r.first_choice_ns = o.onset_ns + 100;
        r.final_choice_ns = o.confirm_ns;
        if (t.task == study::Task::adjust) {
            // A picture's target has no knob value: the matcher aims at 4 there.
            const double target = p.numeric_parameter(t.stimulus, m.knob).value_or(4.0);
            const double value =
                study::simulated_match(matcher, target, m.range_min, m.range_max, rng);
            r.question = m.question_id;
            r.rating = 1;
            r.changes = 1;
            o.final_value = value;
            o.adjustments = {{*t.start_value, o.onset_ns + 400'000'000LL, "key"},
                             {value, o.onset_ns + 1'200'000'000LL, "fine_key"}};
            MatchRow row = testing::match_row(code, t.stimulus, value);
            row.trial = t.position;
            row.adjustments = 2;
            recorded.matches.push_back(row);
        } else if (t.task == study::Task::staircase) {
            if (procedures.finished(t.staircase)) continue;  // the store skipped it
            const double delta = procedures.propose(t.staircase).intensity;
            const bool correct = study::simulated_detection(
                detector, delta, study::adaptive::guess_rate(j), rng);
            o.finishes_staircase = procedures.answer(t.staircase, correct);
            o.intensity = delta;
            r.question = j.question_id;
            r.rating = correct ? t.expected : 3 - t.expected;
            StaircaseRow row;
            row.participant = code;
            row.trial = t.position;
            row.block = t.block;
            row.standard = t.stimulus;
            row.staircase = t.staircase;
            row.intensity = delta;
            row.expected = t.expected;
            row.choice = r.rating;
            row.correct = correct;
            recorded.staircases.push_back(row);
        } else {
            continue;
        }
        o.responses.push_back(r);
        store.record_trial(s.id, t.id, o);
        ++answered;
    }
    if (stop_after < 0) store.set_status(s.id, "completed", true);
}

std::string read(const fs::path& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(MatchingStore, ReadsBackWhatTheStoreRecordedAndReportsIt) {
    const study::Protocol p = testing::protocol();
    const fs::path dir = fs::path(::testing::TempDir()) / "matching_store";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string db = (dir / "study.db").string();
    Recorded kept, left_out;
    {
        auto store = study::open_study_store(db);
        run_session(*store, p, "P01", 11, {0.4, 0.1, false}, {1.0, 0.4, 0.0}, kept);
        run_session(*store, p, "P02", 12, {0.4, 0.1, false}, {1.0, 0.4, 0.0}, kept);
        // A session left running after 5 trials: not completed, so left out.
        run_session(*store, p, "P03", 13, {0.4, 0.1, false}, {1.0, 0.4, 0.0}, left_out,
                    5);
    }
    const MatchingTable table = read_matching(db);
    ASSERT_TRUE(table.protocol);
    EXPECT_NE(table.sessions_note.find("2 of 3 sessions analysed"), std::string::npos)
        << table.sessions_note;
    ASSERT_EQ(table.matches.size(), kept.matches.size());
    for (std::size_t i = 0; i < kept.matches.size(); ++i) {
        const MatchRow& a = table.matches[i];
        const MatchRow& b = kept.matches[i];
        EXPECT_EQ(a.participant, b.participant);
        EXPECT_EQ(a.target, b.target);
        EXPECT_EQ(a.trial, b.trial);
        EXPECT_EQ(a.final_value, b.final_value);  // exactly: a REAL round-trips
        EXPECT_EQ(a.match, "match");
        EXPECT_EQ(a.knob, "thickness_exponent");
        EXPECT_EQ(a.adjustments, 2);
        EXPECT_TRUE(a.start_value.has_value());
    }
    ASSERT_EQ(table.staircases.size(), kept.staircases.size());
    for (std::size_t i = 0; i < kept.staircases.size(); ++i) {
        const StaircaseRow& a = table.staircases[i];
        const StaircaseRow& b = kept.staircases[i];
        EXPECT_EQ(a.participant, b.participant);
        EXPECT_EQ(a.trial, b.trial);
        EXPECT_EQ(a.staircase, b.staircase);
        EXPECT_EQ(a.intensity, b.intensity);
        EXPECT_EQ(a.expected, b.expected);
        EXPECT_EQ(a.choice, b.choice);
        EXPECT_EQ(a.correct, b.correct);
    }
    // "all" takes the running session too.
    const MatchingTable all = read_matching(db, "all");
    EXPECT_EQ(all.matches.size() + all.staircases.size(),
              kept.matches.size() + kept.staircases.size() + 5);
    EXPECT_THROW(read_matching(db, "some"), InputError);

    // The analysis: the matcher's bias 0.4 on "front" (thickness exponent 2).
    const auto conditions = analyse_matches(table.matches, &*table.protocol);
    for (const ConditionMatch& c : conditions)
        if (c.target == "front") {
            ASSERT_TRUE(c.bias);
            EXPECT_NEAR(*c.bias, 0.4, 0.1);
            EXPECT_LE(*c.bias_ci_low, 0.4);
            EXPECT_GE(*c.bias_ci_high, 0.4);
        }
    ThresholdOptions options;
    options.bootstrap = 100;
    const ThresholdAnalysis thresholds =
        analyse_thresholds(table.staircases, &*table.protocol, options);
    ASSERT_EQ(thresholds.thresholds.size(), 2u);  // P01 and P02 on std1
    for (const StandardThreshold& s : thresholds.thresholds) {
        ASSERT_TRUE(s.jnd) << s.participant << ": " << s.jnd_text;
        EXPECT_NEAR(*s.jnd, 1.0, 0.35) << s.participant;
    }
    const MatchingSection section = matching_section(conditions, thresholds);
    ReportOptions report;
    report.source = db;
    report.inputs = {db};
    report.extra_blocks = section.blocks;
    report.extra_files = section.files;
    const auto written = write_report({}, dir / "report", report);
    const std::string html = read(dir / "report" / "report.html");
    EXPECT_NE(html.find(">Matching<"), std::string::npos);
    EXPECT_NE(html.find(">Thresholds<"), std::string::npos);
    static const std::regex bad(
        R"((^|[^A-Za-z])-?(nan|NaN|NAN|inf|Inf|INF)([^A-Za-z]|$))");
    for (const fs::path& f : written) EXPECT_FALSE(std::regex_search(read(f), bad)) << f;

    // The same through `lucent analyze` (in process), with the Weibull too.
    for (const std::string family : {"gaussian", "weibull"}) {
        const std::string out = (dir / ("cli_" + family)).string();
        std::vector<std::string> args = {"lucent", "analyze",     db,   "--out",
                                         out,      "--bootstrap", "50", "--psychometric",
                                         family};
        std::vector<char*> argv;
        for (std::string& a : args) argv.push_back(a.data());
        ASSERT_EQ(app::run_cli(static_cast<int>(argv.size()), argv.data(),
                               {app::register_analyze}),
                  app::kExitOk)
            << family;
        const std::string cli_html = read(fs::path(out) / "report.html");
        EXPECT_NE(cli_html.find(">Matching<"), std::string::npos);
        EXPECT_NE(cli_html.find(">Thresholds<"), std::string::npos);
        EXPECT_NE(cli_html.find(family == "weibull" ? "Weibull" : "cumulative Gaussian"),
                  std::string::npos);
        EXPECT_NE(cli_html.find("2 of 3 sessions analysed"), std::string::npos);
        for (const auto& f : fs::directory_iterator(out))
            EXPECT_FALSE(std::regex_search(read(f.path()), bad)) << f.path();
    }
}

TEST(MatchingStore, ADatabaseWithoutSuchTrialsGivesNoRows) {
    const fs::path dir = fs::path(::testing::TempDir()) / "matching_store_empty";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string db = (dir / "study.db").string();
    {
        auto store = study::open_study_store(db);
        store->ensure_study(testing::protocol());
    }
    const MatchingTable table = read_matching(db);
    EXPECT_TRUE(table.matches.empty());
    EXPECT_TRUE(table.staircases.empty());
    EXPECT_THROW(read_matching((dir / "missing.db").string()), InputError);
}

}  // namespace
}  // namespace lucent::analysis
