#include "analysis/mixed/model_frame.h"

#include <gtest/gtest.h>

#include <sstream>

#include "analysis/data/long_table.h"

namespace lucent::analysis::mixed {
namespace {

DataFrame parse(const std::string& text) {
    std::istringstream in(text);
    return DataFrame::read_csv(in, "table.csv");
}

TEST(ModelFrame, LevelsSortAsRSortsThem) {
    EXPECT_EQ(default_level_order({"10", "2", "1", "2"}),
              (std::vector<std::string>{"1", "2", "10"}));
    EXPECT_EQ(default_level_order({"warm", "cold", "Warm"}),
              (std::vector<std::string>{"Warm", "cold", "warm"}));
}

TEST(ModelFrame, TreatmentContrastsNameColumnsAsR) {
    const DataFrame frame = parse("y,temp,x\r\n1,warm,0.5\r\n2,cold,1\n3,\"warm\",2\n");
    const FixedDesign design =
        fixed_design(frame, {{"temp", true, {}}, {"x", false, {}}}, true);
    EXPECT_EQ(design.names, (std::vector<std::string>{"(Intercept)", "tempwarm", "x"}));
    EXPECT_EQ(design.term_of_column,
              (std::vector<std::string>{"(Intercept)", "temp", "x"}));
    Eigen::MatrixXd expected(3, 3);
    expected << 1, 1, 0.5, 1, 0, 1, 1, 1, 2;
    EXPECT_EQ(design.x, expected);
    EXPECT_EQ(columns_of_term(design, "temp"), std::vector<int>{1});
}

TEST(ModelFrame, BadTablesNameFileLineAndColumn) {
    auto message = [](const std::string& text, auto&& use) {
        try {
            use(parse(text));
        } catch (const InputError& error) {
            return std::string(error.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(message("y,g\n1,a\n2\n", [](const DataFrame&) {}),
              "table.csv:3: expected 2 fields, found 1");
    EXPECT_EQ(message("y,g\n1,a\nx,b\n", [](const DataFrame& f) { f.numeric("y"); }),
              "table.csv:3: column 'y': 'x' is not a finite number");
    EXPECT_EQ(message("y,g\n1,a\n", [](const DataFrame& f) { f.text("z"); }),
              "table.csv: no column 'z'");
    EXPECT_EQ(message("y,g\n1,a\n", [](const DataFrame& f) { f.factor("g", {"b"}); }),
              "table.csv:2: column 'g': 'a' is not one of its levels");
    EXPECT_EQ(message("y,y\n", [](const DataFrame&) {}),
              "table.csv:1: column names must be distinct and not empty ('y')");
}

}  // namespace
}  // namespace lucent::analysis::mixed
