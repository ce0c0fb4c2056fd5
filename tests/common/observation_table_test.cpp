// The one table of observations (issue 51 item 3): its factor columns, the ratings the
// one-way tests read out of it, and its wide CSV.
#include "common/observation_table.h"

#include <gtest/gtest.h>

#include <sstream>

#include "common/csv.h"

namespace lucent::common {
namespace {

Observation rating(const std::string& participant, double value,
                   std::vector<std::pair<std::string, std::string>> factors) {
    Observation o;
    o.participant = participant;
    o.kind = "rating";
    o.analysed_as = "ratings";
    o.question = "q";
    o.shown = {"s"};
    o.response = value;
    o.factors = std::move(factors);
    return o;
}

TEST(ObservationTable, FactorColumnsAreEachFactorOnceInTheOrderFirstMet) {
    ObservationTable table;
    table.rows.push_back(rating("P1", 1, {{"b", "1"}, {"a", "2"}}));
    table.rows.push_back(rating("P1", 2, {{"c", "x"}, {"b", "3"}}));
    EXPECT_EQ(table.factor_columns(), (std::vector<std::string>{"b", "a", "c"}));
}

TEST(ObservationTable, FactorRatingsAreAnsweredRatingsOfNoPracticeOrCatchTrial) {
    ObservationTable table;
    table.rows.push_back(rating("kept", 1, {{"a", "1"}, {"b", "2"}}));
    Observation practice = rating("practice", 2, {{"a", "1"}});
    practice.practice = true;
    Observation catch_trial = rating("catch", 3, {{"a", "1"}});
    catch_trial.is_catch = true;
    Observation unanswered = rating("unanswered", 4, {{"a", "1"}});
    unanswered.response.reset();
    Observation choice = rating("choice", 1, {{"a", "1"}});
    choice.kind = "pair";
    choice.analysed_as = "choices";
    // A kind of another name that its kind says is analysed as ratings is one.
    Observation other_kind = rating("kept", 5, {{"a", "3"}});
    other_kind.kind = "probe";
    Observation not_analysed = rating("not analysed", 5, {{"a", "3"}});
    not_analysed.analysed_as = "";
    for (const Observation& o :
         {practice, catch_trial, unanswered, choice, other_kind, not_analysed})
        table.rows.push_back(o);
    const std::vector<FactorRating> rows = factor_ratings(table);
    ASSERT_EQ(rows.size(), 3u);
    for (const FactorRating& r : rows) EXPECT_EQ(r.observation->participant, "kept");
    EXPECT_EQ(*rows[0].factor, "a");
    EXPECT_EQ(*rows[1].level, "2");
    EXPECT_EQ(rows[2].observation->kind, "probe");
}

TEST(ObservationTable, TheWideCsvHasAColumnPerMeasureAndFactorAndNoClash) {
    ObservationTable table;
    Observation o = rating("P, 1", 0.1, {{"trial", "t1"}, {"light", "back"}});
    o.trial = 3;
    o.measures["intensity"] = 0.25;
    table.rows.push_back(o);
    table.rows.push_back(rating("P2", 7, {{"light", "front"}}));
    std::ostringstream out;
    write_observation_csv(out, table);
    std::istringstream in(out.str());
    std::string line;
    std::vector<std::vector<std::string>> rows;
    while (std::getline(in, line)) rows.push_back(split_csv_line(line));
    ASSERT_EQ(rows.size(), 3u);
    const std::vector<std::string> header = {
        "participant", "session",   "trial",     "block",        "kind",  "analysed_as",
        "question",    "practice",  "catch",     "expected",     "shown", "response",
        "rt_ms",       "procedure", "intensity", "factor:trial", "light"};
    EXPECT_EQ(rows[0], header);
    EXPECT_EQ(rows[1][0], "P, 1");  // quoted, read back whole
    EXPECT_EQ(rows[1][2], "3");
    EXPECT_EQ(rows[1][5], "ratings");
    EXPECT_EQ(rows[1][11], "0.1");  // the shortest exact text
    EXPECT_EQ(rows[1][14], "0.25");
    EXPECT_EQ(rows[1][15], "t1");
    EXPECT_EQ(rows[2][14], "");  // no intensity
    EXPECT_EQ(rows[2][15], "");
    EXPECT_EQ(rows[2][16], "front");
}

}  // namespace
}  // namespace lucent::common
