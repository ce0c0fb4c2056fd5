// The table of observations read back from its CSV (issue 51 item 3): what
// write_observation_csv writes reads back the same, and bad input is refused naming the
// line, the column and the field.
#include "analysis/data/observation_csv.h"

#include <gtest/gtest.h>

#include <sstream>

#include "analysis/data/long_table.h"

namespace lucent::analysis {
namespace {

std::string error_of(const std::string& csv) {
    std::istringstream in(csv);
    try {
        read_observation_csv(in, "obs.csv");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ObservationCsv, WhatIsWrittenReadsBackTheSame) {
    common::ObservationTable table;
    common::Observation rating;
    rating.participant = "P, 1";
    rating.session = "s1";
    rating.trial = 4;
    rating.block = "b";
    rating.kind = "rating";
    rating.analysed_as = "ratings";
    rating.question = "translucent";
    rating.shown = {"a"};
    rating.response = 0.1;
    rating.rt_ms = 512.25;
    rating.factors = {{"trial", "t1"}, {"light", "back"}};
    common::Observation pair;
    pair.participant = "P2";
    pair.kind = "pair";
    pair.analysed_as = "choices";
    pair.is_catch = true;
    pair.expected = 2;
    pair.shown = {"a", "b"};
    pair.response = 2;
    pair.measures = {{"value_1", 10}, {"value_2", 15.5}};
    common::Observation staircase;
    staircase.participant = "P3";
    staircase.kind = "staircase";
    staircase.analysed_as = "thresholds";
    staircase.shown = {"std"};
    staircase.expected = 1;
    staircase.response = 1;
    staircase.procedure = "std/a";
    staircase.measures = {{"intensity", 0.0625}};
    // A kind the analysis does not know by name, read as its column says.
    common::Observation probe = rating;
    probe.kind = "probe";
    probe.analysed_as = "ratings";
    table.rows = {rating, pair, staircase, probe};
    std::ostringstream out;
    common::write_observation_csv(out, table);
    std::istringstream in(out.str());
    const common::ObservationTable back = read_observation_csv(in, "obs.csv");
    ASSERT_EQ(back.rows.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        const common::Observation& a = table.rows[i];
        const common::Observation& b = back.rows[i];
        EXPECT_EQ(a.participant, b.participant);
        EXPECT_EQ(a.session, b.session);
        EXPECT_EQ(a.trial, b.trial);
        EXPECT_EQ(a.block, b.block);
        EXPECT_EQ(a.kind, b.kind);
        EXPECT_EQ(a.analysed_as, b.analysed_as);
        EXPECT_EQ(a.question, b.question);
        EXPECT_EQ(a.is_catch, b.is_catch);
        EXPECT_EQ(a.expected, b.expected);
        EXPECT_EQ(a.shown, b.shown);
        EXPECT_EQ(a.response, b.response);  // exactly: the shortest text reads back
        EXPECT_EQ(a.rt_ms, b.rt_ms);
        EXPECT_EQ(a.measures, b.measures);
        EXPECT_EQ(a.procedure, b.procedure);
    }
    // Factor columns come back in column order; "factor:trial" is the factor trial.
    EXPECT_EQ(back.rows[0].factors, (std::vector<std::pair<std::string, std::string>>{
                                        {"trial", "t1"}, {"light", "back"}}));
    EXPECT_TRUE(back.rows[1].factors.empty());
}

TEST(ObservationCsv, BadInputNamesTheLineColumnAndField) {
    const std::string header = "participant,kind,shown,response\n";
    EXPECT_NE(error_of("participant,shown,response\nP1,a,3\n")
                  .find("obs.csv:1: header lacks column 'kind'"),
              std::string::npos);
    EXPECT_EQ(error_of(header + "P1,rating,a,3\nP1,ratng,a,3\n"),
              "obs.csv:3: column 2 (kind): 'ratng' is not one of rating, pair, triad, "
              "quadruple, adjust, staircase (another kind needs the analysed_as column)");
    // Without the column, each built-in kind is read as what it is analysed as.
    {
        std::istringstream in(header + "P1,rating,a,3\nP1,pair,a b,1\n");
        const common::ObservationTable t = read_observation_csv(in, "obs.csv");
        EXPECT_EQ(t.rows[0].analysed_as, "ratings");
        EXPECT_EQ(t.rows[1].analysed_as, "choices");
    }
    const std::string with_analysis = "participant,kind,analysed_as,shown,response\n";
    EXPECT_EQ(error_of(with_analysis + "P1,probe,rating,a,1\n"),
              "obs.csv:2: column 3 (analysed_as): 'rating' is not one of ratings, "
              "choices, matches, thresholds or empty");
    EXPECT_EQ(error_of(with_analysis + "P1,probe,choices,a,1\n"),
              "obs.csv:2: column 3 (analysed_as): a probe trial is not a pair, triad or "
              "quadruple: the scaling reads no other choice");
    EXPECT_EQ(error_of(with_analysis + "P1,,ratings,a,1\n"),
              "obs.csv:2: column 2 (kind): kind is empty");
    EXPECT_EQ(error_of(header + "P1,pair,a,1\n"),
              "obs.csv:2: column 3 (shown): a pair shows 2 stimuli, 1 are named");
    EXPECT_EQ(error_of(header + "P1,rating,a,seven\n"),
              "obs.csv:2: column 4 (response): 'seven' is not a finite number");
    EXPECT_EQ(error_of(header + ",rating,a,3\n"),
              "obs.csv:2: column 1 (participant): participant is empty");
    EXPECT_EQ(error_of(header + "P1,rating,a\n"),
              "obs.csv:2: expected 4 fields, found 3");
    EXPECT_EQ(error_of("participant,kind,shown,response,light,factor:light\n"),
              "obs.csv:1: column 6: 'factor:light' twice");
    EXPECT_EQ(error_of(""), "obs.csv: empty file (no header)");
}

TEST(ObservationCsv, TheHeaderIsKnownByItsKindAndResponseColumns) {
    EXPECT_TRUE(is_observation_header("participant,kind,shown,response,light"));
    EXPECT_FALSE(
        is_observation_header("participant,stimulus,factor,level,question,rating"));
    EXPECT_FALSE(is_observation_header("participant,session,trial,task,shown_1,choice"));
}

}  // namespace
}  // namespace lucent::analysis
