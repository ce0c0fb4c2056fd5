// Number text: 17 significant digits and the shortest form both read back (strtod) to
// the very double written, for values that are awkward in decimal; checked parsing
// takes whole, finite numbers only.
#include "common/number_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace lucent::common {
namespace {

// Awkward doubles: not exact in decimal, subnormal, signed zero, near the range's ends.
const double kAwkward[] = {0.1,
                           1.0 / 3.0,
                           2.0 / 3.0,
                           -0.0,
                           0.0,
                           1e308,
                           -1e308,
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::denorm_min(),
                           3 * std::numeric_limits<double>::denorm_min(),
                           std::nextafter(1.0, 2.0),
                           123456789012345678.0,
                           0.3 - 0.1};

bool same_double(double a, double b) {
    return a == b && std::signbit(a) == std::signbit(b);
}

TEST(NumberText, FullPrecisionIsSeventeenSignificantDigits) {
    // 0.1 is 0.1000000000000000055511151231257827... as a double.
    EXPECT_EQ(full_precision_text(0.1), "0.10000000000000001");
    // 1/3 is 0.333333333333333314829616256247390992939472198486328125.
    EXPECT_EQ(full_precision_text(1.0 / 3.0), "0.33333333333333331");
    EXPECT_EQ(full_precision_text(-0.0), "-0");
    EXPECT_EQ(full_precision_text(1e308), "1e+308");
    EXPECT_EQ(full_precision_text(0.5), "0.5");
    EXPECT_EQ(full_precision_text(std::numeric_limits<double>::denorm_min()),
              "4.9406564584124654e-324");
}

TEST(NumberText, ShortestIsTheFewestDigitsThatReadBack) {
    EXPECT_EQ(shortest_text(0.1), "0.1");
    EXPECT_EQ(shortest_text(1.0 / 3.0), "0.3333333333333333");
    EXPECT_EQ(shortest_text(-0.0), "-0");
    EXPECT_EQ(shortest_text(1e308), "1e+308");
    EXPECT_EQ(shortest_text(std::numeric_limits<double>::denorm_min()), "5e-324");
    EXPECT_EQ(shortest_text(0.3 - 0.1), "0.19999999999999998");
}

TEST(NumberText, NineDigitsReadEveryFloatBack) {
    EXPECT_EQ(nine_digit_text(0.1), "0.1");
    EXPECT_EQ(nine_digit_text(1.0 / 3.0), "0.333333333");
    EXPECT_EQ(nine_digit_text(0.3 - 0.1), "0.2");
    EXPECT_EQ(nine_digit_text(123456789012.0), "1.23456789e+11");
    EXPECT_EQ(nine_digit_text(-0.0), "-0");
    EXPECT_EQ(nine_digit_text(std::numeric_limits<double>::infinity()), "inf");
    // 9 significant digits are enough for any float (FLT_DECIMAL_DIG).
    for (const float f :
         {0.1f, 1.0f / 3.0f, 3.4e38f, 1.17549435e-38f, 16777217.0f, 2.5e-7f})
        EXPECT_EQ(std::strtof(nine_digit_text(f).c_str(), nullptr), f) << f;
}

TEST(NumberText, BothFormsReadBackToTheSameDouble) {
    for (const double value : kAwkward) {
        const std::string full = full_precision_text(value);
        const std::string shortest = shortest_text(value);
        EXPECT_TRUE(same_double(std::strtod(full.c_str(), nullptr), value)) << full;
        EXPECT_TRUE(same_double(std::strtod(shortest.c_str(), nullptr), value))
            << shortest;
        EXPECT_LE(shortest.size(), full.size()) << shortest << " " << full;
    }
}

TEST(NumberText, ParseFiniteTakesWholeFiniteNumbersOnly) {
    EXPECT_EQ(parse_finite("1.5"), 1.5);
    EXPECT_EQ(parse_finite("-2e-3"), -0.002);
    EXPECT_EQ(parse_finite(".5"), 0.5);
    EXPECT_EQ(parse_finite("1E2"), 100.0);
    for (const char* text : {"", " 1.5", "1.5 ", "+1", "1.5x", "0x10", "inf", "-inf",
                             "nan", "infinity", "1e400", "-1e400", "1,5", "--1"})
        EXPECT_FALSE(parse_finite(text).has_value()) << text;
    EXPECT_TRUE(same_double(*parse_finite("-0"), -0.0));
    EXPECT_EQ(*parse_finite("4.9406564584124654e-324"),
              std::numeric_limits<double>::denorm_min());
}

TEST(NumberText, ParseFiniteNumberAllowsBlanksAndAPlus) {
    EXPECT_EQ(parse_finite_number(" 2.5 "), 2.5);
    EXPECT_EQ(parse_finite_number("+2.5"), 2.5);
    EXPECT_EQ(parse_finite_number("\t-3\n"), -3.0);
    for (const char* text : {"", "   ", "inf", "1e400", "++1", "+", "1 2", "nan"})
        EXPECT_FALSE(parse_finite_number(text).has_value()) << text;
}

}  // namespace
}  // namespace lucent::common
