// The choices CSV: read, written, read again; one-line errors naming file:line and
// column.
#include "analysis/data/choice_table.h"

#include <gtest/gtest.h>

#include <sstream>

#include "analysis/data/long_table.h"
#include "scaling_test_data.h"

namespace lucent::analysis {
namespace {

const char* kHeader =
    "participant,session,trial,block,task,question,practice,catch,expected,shown_1,"
    "shown_2,shown_3,shown_4,value_1,value_2,value_3,value_4,choice,rt_ms\n";

std::string error_of(const std::string& text) {
    std::istringstream in(text);
    try {
        read_choice_csv(in, "c.csv");
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(ChoiceTable, TaskNames) {
    EXPECT_EQ(parse_choice_task("triad"), ChoiceTask::triad);
    EXPECT_FALSE(parse_choice_task("rating"));
    EXPECT_STREQ(choice_task_name(ChoiceTask::quadruple), "quadruple");
    EXPECT_EQ(shown_count(ChoiceTask::pair), 2);
    EXPECT_EQ(shown_count(ChoiceTask::quadruple), 4);
}

TEST(ChoiceTable, ReadsWritesAndReadsBack) {
    std::istringstream in(
        std::string(kHeader) +
        "P1,u1,3,b,quadruple,q,0,1,2,a,b,\"c,1\",d,0,0.5,1,1.5,2,812.5\n"
        "P1,u1,4,b,pair,q,1,0,,a,b,,,,,,,1,10\n"
        "P2,u2,1,b,pair,q,0,0,,a,b,,,,,,,1,10\r\n");
    const ChoiceTable t = read_choice_csv(in, "c.csv");
    ASSERT_EQ(t.rows.size(), 2u);  // the practice trial is left out
    const ChoiceRow& r = t.rows[0];
    EXPECT_EQ(r.task, ChoiceTask::quadruple);
    EXPECT_TRUE(r.is_catch);
    EXPECT_EQ(r.expected, 2);
    EXPECT_EQ(r.shown[2], "c,1");
    EXPECT_EQ(*r.value[3], 1.5);
    EXPECT_EQ(r.choice, 2);
    EXPECT_EQ(r.rt_ms, 812.5);
    EXPECT_EQ(r.source_line, 2u);
    EXPECT_EQ(t.rows[1].source_line, 4u);
    EXPECT_FALSE(t.rows[1].value[0]);
    std::ostringstream out;
    write_choice_csv(out, t);
    std::istringstream again(out.str());
    const ChoiceTable back = read_choice_csv(again, "again.csv");
    ASSERT_EQ(back.rows.size(), 2u);
    EXPECT_EQ(back.rows[0].shown, r.shown);
    EXPECT_EQ(back.rows[0].value, r.value);
    EXPECT_EQ(back.rows[0].expected, r.expected);
    EXPECT_EQ(back.rows[1].participant, "P2");
}

TEST(ChoiceTable, ColumnsInAnyOrderAndOptionalOnes) {
    std::istringstream in("choice,shown_2,shown_1,task,participant\n2,x,y,pair,P\n");
    const ChoiceTable t = read_choice_csv(in, "c.csv");
    ASSERT_EQ(t.rows.size(), 1u);
    EXPECT_EQ(t.rows[0].shown[0], "y");
    EXPECT_EQ(t.rows[0].choice, 2);
}

TEST(ChoiceTable, ErrorsNameFileLineAndColumn) {
    EXPECT_EQ(error_of("participant,task,shown_1,shown_2\n"),
              "c.csv:1: header lacks column 'choice' (expected the columns of lucent "
              "export --format choices: participant,...,shown_1,...,choice,rt_ms)");
    EXPECT_EQ(error_of(std::string(kHeader) + "P,u,1,b,pair,q,0,0,,a,b,,,,,,,3,1\n"),
              "c.csv:2: column 18 (choice): expected 1 or 2, got '3'");
    EXPECT_EQ(error_of(std::string(kHeader) + "P,u,1,b,pairs,q,0,0,,a,b,,,,,,,1,1\n"),
              "c.csv:2: column 5 (task): task 'pairs' is not one of pair, triad, "
              "quadruple");
    EXPECT_EQ(error_of(std::string(kHeader) + "P,u,1,b,triad,q,0,0,,a,b,,,,,,,1,1\n"),
              "c.csv:2: column 12 (shown_3): a triad shows 3 stimuli; this one is empty");
    EXPECT_EQ(error_of(std::string(kHeader) + "P,u,1,b,pair,q,0,0,,a,b,,,x,,,,1,1\n"),
              "c.csv:2: column 14 (value_1): 'x' is not a finite number");
    EXPECT_EQ(error_of(std::string(kHeader) + "P,u,1,b,pair,q,0,0\n"),
              "c.csv:2: expected 19 fields, found 8");
    EXPECT_EQ(error_of(""), "c.csv: empty file (no header)");
}

TEST(ChoiceTable, ReadsTheMldsDataSet) {
    const ChoiceTable t =
        read_choice_csv(testing::scaling_data_path("mlds_quadruple.csv"));
    EXPECT_EQ(t.rows.size(), 210u);
}

}  // namespace
}  // namespace lucent::analysis
