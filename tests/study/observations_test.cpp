// Issue 51 item 3: a study database as the one table the statistics read. Every answer
// the test gave (study_fixtures.h's deterministic answers), of every trial kind, comes
// back as one observation with its stimulus's factors; `lucent export --format
// observations` writes the same rows.
#include "study/observations.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/csv.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// Runs one full session of `p` and checks every stored answer against the answers given.
void expect_every_answer_observed(const Protocol& p, const std::string& name) {
    const auto dir = lucent::test::scratch_dir("observations_" + name);
    const std::string path = (dir / "study.db").string();
    std::vector<TrialRow> trials;
    {
        Store store(path);
        const int64_t session = lucent::test::run_full_session(store, p, "P1", 9);
        trials = store.trials(session);
    }
    const StudyObservations read = read_observations(path, {.analysis = false});
    const std::vector<common::Observation>& rows = read.table.rows;
    std::size_t i = 0;
    std::set<std::string> kinds_seen;
    for (const TrialRow& t : trials) {
        if (!t.answered) continue;
        const TrialOutcome given = lucent::test::outcome_for(p, t);
        for (const Response& r : given.responses) {
            ASSERT_LT(i, rows.size()) << name;
            const common::Observation& row = rows[i++];
            kinds_seen.insert(row.kind);
            SCOPED_TRACE(name + " trial " + std::to_string(t.position));
            EXPECT_EQ(row.participant, "P1");
            EXPECT_EQ(row.trial, t.position);
            EXPECT_EQ(row.block, t.block);
            EXPECT_EQ(row.kind, task_name(t.task));
            EXPECT_EQ(row.question, r.question);
            EXPECT_EQ(row.practice, t.practice);
            EXPECT_EQ(row.is_catch, t.is_catch);
            EXPECT_EQ(row.rt_ms, r.rt_ms);
            if (t.task == Task::adjust) {
                EXPECT_EQ(row.response, given.final_value);
                EXPECT_EQ(row.measures.at("adjustments"),
                          static_cast<double>(given.adjustments.size()));
                EXPECT_EQ(row.measures.at("start_value"), t.start_value.value());
            } else {
                EXPECT_EQ(row.response, r.rating);
            }
            if (t.task == Task::staircase) {
                EXPECT_EQ(row.measures.at("intensity"), given.intensity.value());
                EXPECT_EQ(row.procedure, t.staircase);
            }
            if (is_scaling_task(t.task)) {
                EXPECT_EQ(row.shown, t.shown);
                EXPECT_TRUE(row.factors.empty());
                const Block& block = *p.find_block(t.block);
                for (std::size_t k = 0; k < t.shown.size() && !block.series.empty(); ++k)
                    EXPECT_EQ(
                        row.measures.at("value_" + std::to_string(k + 1)),
                        std::stod(
                            p.find_stimulus(t.shown[k])->parameters.at(block.series)));
            } else {
                ASSERT_EQ(row.shown, std::vector<std::string>{t.stimulus});
                const Stimulus& stimulus = *p.find_stimulus(t.stimulus);
                std::vector<std::string> factors;
                for (const auto& [factor, level] : row.factors) {
                    factors.push_back(factor);
                    EXPECT_EQ(level, p.level_of(stimulus, factor)) << factor;
                }
                std::vector<std::string> expected = stimulus.varies;
                if (expected.empty())
                    for (const auto& [knob, value] : stimulus.parameters)
                        expected.push_back(knob);
                EXPECT_EQ(factors, expected);
            }
        }
    }
    EXPECT_EQ(i, rows.size()) << name << ": more observations than answers";
    std::set<std::string> kinds_planned;
    for (const Block& b : p.blocks) kinds_planned.insert(task_name(b.task));
    EXPECT_EQ(kinds_seen, kinds_planned) << name;

    // The wide CSV: a header and one line per observation, a column per factor.
    const std::string csv = (dir / "observations.csv").string();
    EXPECT_EQ(export_file(path, "observations", csv, false).rows,
              static_cast<int>(read_observations(path).table.rows.size()));
    std::ifstream in(csv);
    std::string header;
    std::getline(in, header);
    const std::vector<std::string> columns = common::split_csv_line(header);
    for (const std::string& factor : read.table.factor_columns())
        EXPECT_NE(std::find(columns.begin(), columns.end(), factor), columns.end())
            << factor;
}

TEST(Observations, EveryRatingAndForcedChoiceIsOneObservation) {
    expect_every_answer_observed(lucent::test::choice_protocol(), "choices");
}

TEST(Observations, EveryAdjustAndStaircaseAnswerIsOneObservation) {
    expect_every_answer_observed(lucent::test::matching_protocol(), "matching");
}

// Issue 51 item 1: the experimenter's own factors (a stimulus's `factors`, named levels
// no renderer reads) are columns of the observation table like its parameters.
TEST(Observations, AnOwnFactorIsAColumnBesideTheParameters) {
    std::string text = lucent::test::kSmallProtocol;
    for (const auto& [id, lighting] :
         {std::pair{"a", "front"}, std::pair{"b", "front"}, std::pair{"c", "back"}}) {
        const std::string entry = std::string("id = \"") + id + "\"";
        const std::string varies = "varies = [\"thickness_exponent\"]";
        const std::size_t at = text.find(varies, text.find(entry));
        text.replace(at, varies.size(),
                     std::string("factors = { lighting = \"") + lighting +
                         "\" }\nvaries = [\"thickness_exponent\", \"lighting\"]");
    }
    const Protocol p = parse_protocol(text, "own_factors.toml");
    EXPECT_EQ(p.find_stimulus("c")->factors.at("lighting"), "back");
    EXPECT_EQ(p.levels_of("lighting").at("c"), "back");

    const auto dir = lucent::test::scratch_dir("observations_own_factor_levels");
    const std::string path = (dir / "study.db").string();
    {
        Store store(path);
        lucent::test::run_full_session(store, p, "P1", 9);
    }
    std::map<std::string, std::set<std::string>> lighting_of;
    for (const common::Observation& o : read_observations(path).table.rows) {
        std::vector<std::string> names;
        for (const auto& [factor, level] : o.factors) {
            names.push_back(factor);
            if (factor == "lighting") lighting_of[o.shown.at(0)].insert(level);
        }
        EXPECT_EQ(names, (std::vector<std::string>{"thickness_exponent", "lighting"}));
    }
    const std::map<std::string, std::set<std::string>> expected = {
        {"a", {"front"}}, {"b", {"front"}}, {"c", {"back"}}};
    EXPECT_EQ(lighting_of, expected);
}

TEST(Observations, TheAnalysisViewLeavesPracticeOut) {
    const auto dir = lucent::test::scratch_dir("observations_practice");
    const std::string path = (dir / "study.db").string();
    const Protocol p = lucent::test::choice_protocol();
    {
        Store store(path);
        lucent::test::run_full_session(store, p, "P1", 9);
    }
    int practice = 0;
    for (const common::Observation& o :
         read_observations(path, {.analysis = false}).table.rows)
        practice += o.practice;
    ASSERT_GT(practice, 0);  // the protocol has practice trials, so this can fail
    const StudyObservations analysed = read_observations(path);
    for (const common::Observation& o : analysed.table.rows) EXPECT_FALSE(o.practice);
    EXPECT_EQ(analysed.table.rows.size() + static_cast<std::size_t>(practice),
              read_observations(path, {.analysis = false}).table.rows.size());
    EXPECT_THROW(read_observations((dir / "missing.db").string()), StoreError);
}

}  // namespace
}  // namespace lucent::study
