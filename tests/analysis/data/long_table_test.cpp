// The long CSV reader: CRLF, quotes, missing ratings, exact decimal origin, scale checks
// and error messages that name the line.
#include "analysis/data/long_table.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

#include "analysis/data/decimal.h"
#include "analysis/data/grouping.h"

namespace lucent::analysis {
namespace {

LongTable read(const std::string& text, RatingScale scale = {}) {
    std::istringstream in(text);
    return read_long_csv(in, "ratings.csv", scale);
}

std::string error_of(const std::string& text, RatingScale scale = {}) {
    try {
        read(text, scale);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(LongTable, ReadsCrlfQuotesAndMissingRatings) {
    const LongTable t = read(
        "rating,question,level,factor,stimulus,participant\r\n"
        "5,translucent,18,thickness,img1,p1\r\n"
        "\"3\",\"looks, realistic\",18,thickness,img1,p1\r\n"
        ",translucent,25,thickness,img2,p1\r\n");
    ASSERT_EQ(t.rows.size(), 3u);
    EXPECT_EQ(t.rows[1].question, "looks, realistic");
    EXPECT_DOUBLE_EQ(t.origin + *t.rows[0].rating, 5.0);
    EXPECT_DOUBLE_EQ(t.origin + *t.rows[1].rating, 3.0);
    EXPECT_FALSE(t.rows[2].rating.has_value());
    const auto pairs = split_by_question_and_factor(t, "translucent");
    ASSERT_EQ(pairs.size(), 1u);
    ASSERT_EQ(pairs[0].data.groups.size(), 2u);
    EXPECT_TRUE(pairs[0].data.groups[1].values.empty());  // level 25: an empty group
    EXPECT_EQ(pairs[0].missing_ratings, 1u);
}

TEST(LongTable, RatingsOutsideTheScaleNameTheLine) {
    const std::string csv =
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,7\n"
        "p1,b,f,2,q,9\n";
    const std::string message = error_of(csv);
    EXPECT_NE(message.find("ratings.csv:3"), std::string::npos) << message;
    EXPECT_NE(message.find("1..7"), std::string::npos) << message;
    EXPECT_NO_THROW(read(csv, parse_scale("0..10")));
    EXPECT_NO_THROW(read(csv, parse_scale("any")));
    EXPECT_NE(error_of(csv, parse_scale("1..5")).find("ratings.csv:2"),
              std::string::npos);
}

TEST(LongTable, BadInputIsReportedNotCrashed) {
    EXPECT_NE(error_of("participant,stimulus,factor,level,question\n").find("rating"),
              std::string::npos);
    EXPECT_NE(
        error_of("participant,stimulus,factor,level,question,rating\np,s,f,1,q,abc\n")
            .find("ratings.csv:2"),
        std::string::npos);
    EXPECT_NE(
        error_of("participant,stimulus,factor,level,question,rating\np,s,f,1,q,nan\n")
            .find("not a finite number"),
        std::string::npos);
    EXPECT_NE(error_of("participant,stimulus,factor,level,question,rating\np,s,f,1\n")
                  .find("expected 6 fields"),
              std::string::npos);
    EXPECT_NE(error_of("").find("empty"), std::string::npos);
    EXPECT_THROW(parse_scale("7..1"), InputError);
    EXPECT_THROW(parse_scale("1-7"), InputError);
}

TEST(LongTable, TablesFromOtherReadersAreCheckedToo) {
    // The study database reader fills LongTable directly; check_scale names its row.
    LongTable t;
    t.rows.push_back({"p1", "s1", "f", "1", "q", 3.0, 12});
    t.rows.push_back({"p1", "s2", "f", "2", "q", 8.0, 13});
    EXPECT_THROW(check_scale(t, RatingScale{}, "study.db"), InputError);
    try {
        check_scale(t, RatingScale{}, "study.db");
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("study.db:13"), std::string::npos);
    }
    t.rows[1].rating = std::nan("");
    EXPECT_THROW(check_scale(t, RatingScale{true}, "study.db"), InputError);
}

TEST(Decimal, DifferencesAreExact) {
    // 1e12 + 0.4 is not representable; its difference from 1e12 + 0.2 is, nearly: 0.2.
    EXPECT_EQ(exact_difference("1000000000000.4", "1000000000000.2"), 0.2);
    EXPECT_EQ(exact_difference("107.8681568", "107.8681465"), 0.0000103);
    EXPECT_EQ(exact_difference("1.5e3", "1000"), 500.0);
}

TEST(Decimal, PlainDecimalsRoundOnceLikeStrtod) {
    // Short plain decimals take an integer fast path; its result must be the correctly
    // rounded difference. Against origin 0 that is what strtod (correctly rounded) gives.
    std::mt19937_64 engine(9);
    for (int i = 0; i < 20000; ++i) {
        const int digits = 1 + static_cast<int>(engine() % 17);
        const int fraction = static_cast<int>(engine() % digits);  // digits after '.'
        char buffer[24];
        int length = 0;
        if (engine() % 2) buffer[length++] = '-';
        for (int d = 0; d < digits; ++d) {
            if (fraction > 0 && d == digits - fraction) buffer[length++] = '.';
            buffer[length++] = static_cast<char>('0' + engine() % 10);
        }
        const std::string text(buffer, length);
        EXPECT_EQ(exact_difference(text, "0"), std::strtod(text.c_str(), nullptr))
            << text;
    }
    // Differences that are exact in binary come back exactly, whatever the magnitudes.
    EXPECT_EQ(exact_difference("123456789012345.75", "123456789012345.5"), 0.25);
    EXPECT_EQ(exact_difference("-3", "4.125"), -7.125);
    EXPECT_EQ(exact_difference("7", "1"), 6.0);
    // Longer texts and exponents take the decimal path.
    EXPECT_EQ(exact_difference("1234567890123456789.5", "1234567890123456789"), 0.5);
    EXPECT_EQ(exact_difference("2.5e1", "5"), 20.0);
}

TEST(LongTable, OriginKeepsDigitsOfHugeValues) {
    const LongTable t = read(
        "participant,stimulus,factor,level,question,rating\n"
        "1,,f,1,q,1000000000000.4\n"
        "2,,f,1,q,1000000000000.3\n"
        "3,,f,2,q,1000000000000.5\n",
        RatingScale{true});
    EXPECT_NEAR(*t.rows[1].rating - *t.rows[0].rating, -0.1, 1e-15);
    EXPECT_NEAR(*t.rows[2].rating - *t.rows[0].rating, 0.1, 1e-15);
}

TEST(Grouping, NumericLevelsSortNumerically) {
    const LongTable t = read(
        "participant,stimulus,factor,level,question,rating\n"
        "p,s,r,30,q,1\np,s,r,18,q,2\np,s,r,25,q,3\n");
    const auto pairs = split_by_question_and_factor(t);
    ASSERT_EQ(pairs[0].data.groups.size(), 3u);
    EXPECT_EQ(pairs[0].data.groups[0].level, "18");
    EXPECT_EQ(pairs[0].data.groups[2].level, "30");
}

TEST(LongTable, QuotedFieldsSpanLinesAndUnterminatedQuotesNameTheirLine) {
    const LongTable t = read(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,s1,f,1,\"two\nlines, \"\"quoted\"\"\",4\n"
        "p1,s2,f,2,q,5\n");
    ASSERT_EQ(t.rows.size(), 2u);
    EXPECT_EQ(t.rows[0].question, "two\nlines, \"quoted\"");
    EXPECT_EQ(t.rows[1].source_line, 4u);  // physical lines: the quoted field took two
    const std::string message = error_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,s1,f,1,q,4\n"
        "p1,s2,f,2,\"open,5\n"
        "p1,s3,f,3,q,6\n");
    EXPECT_NE(message.find("ratings.csv:3: unterminated quoted field"), std::string::npos)
        << message;
}

TEST(LongTable, FileAndStreamReadersAgree) {
    // read_long_csv(path) maps the file; the stream reader copies it: same table.
    std::ostringstream csv;
    csv << "\xEF\xBB\xBFparticipant , stimulus,factor,level,question,rating\r\n";
    std::mt19937 random(5);
    for (int i = 0; i < 2000; ++i) {
        csv << 'p' << i % 17 << ", s" << i % 101 << ",f," << i % 3 << ",q" << i % 2
            << ',';
        if (i % 97 == 0)
            csv << "NA";
        else
            csv << 1 + random() % 7;
        csv << (i % 2 ? "\r\n" : "\n");
    }
    csv << "p1,s1,f,0,q0,2.5\n";  // one non-integer rating takes the exact decimal path
    const std::string text = csv.str();
    const auto path = std::filesystem::temp_directory_path() /
                      ("lucent-long-table-" + std::to_string(::getpid()) + ".csv");
    {
        std::ofstream out(path, std::ios::binary);
        out << text;
    }
    const LongTable from_file = read_long_csv(path, RatingScale{});
    const LongTable from_stream = read(text);
    std::filesystem::remove(path);
    ASSERT_EQ(from_file.rows.size(), 2001u);
    ASSERT_EQ(from_stream.rows.size(), from_file.rows.size());
    EXPECT_EQ(from_file.origin, from_stream.origin);
    for (std::size_t i = 0; i < from_file.rows.size(); ++i) {
        const RatingRow &a = from_file.rows[i], &b = from_stream.rows[i];
        ASSERT_EQ(a.participant, b.participant) << i;
        ASSERT_EQ(a.stimulus, b.stimulus) << i;
        ASSERT_EQ(a.level, b.level) << i;
        ASSERT_EQ(a.question, b.question) << i;
        ASSERT_EQ(a.rating, b.rating) << i;
        ASSERT_EQ(a.source_line, b.source_line) << i;
    }
    EXPECT_EQ(from_file.rows[0].participant, "p0");  // trimmed, after the BOM
    EXPECT_EQ(from_file.rows[1].stimulus, "s1");
    EXPECT_FALSE(from_file.rows[0].rating.has_value());  // i = 0 is NA
    EXPECT_DOUBLE_EQ(from_file.origin + *from_file.rows.back().rating, 2.5);
    EXPECT_THROW(read_long_csv(path, RatingScale{}), InputError);  // gone: one line
}

// Over 4 MiB without quotes the reader parses two halves at once: every row, its
// rating and its line number are those written (blank lines and a leading NA run
// included), and of two bad lines the earlier is the one named.
TEST(LongTable, LargeFilesParsedInTwoHalvesKeepEveryRowAndLine) {
    struct Written {
        std::string participant, level;
        std::optional<int> rating;
        std::size_t line;
    };
    std::vector<Written> written;
    std::ostringstream csv;
    csv << "participant,stimulus,factor,level,question,rating\n";
    std::size_t line = 1;
    std::mt19937 random(9);
    for (int i = 0; i < 180000; ++i) {
        if (i % 5000 == 17) {
            csv << "\n";  // a blank line: skipped, but counted
            ++line;
        }
        Written w{
            "participant" + std::to_string(i % 311), std::to_string(i % 7), {}, ++line};
        if (i >= 3 && i % 1013 != 0) w.rating = 1 + static_cast<int>(random() % 7);
        csv << w.participant << ",stimulus" << i % 97 << ",thickness," << w.level
            << ",translucent," << (w.rating ? std::to_string(*w.rating) : "NA") << "\n";
        written.push_back(w);
    }
    const std::string text = csv.str();
    ASSERT_GT(text.size(), std::size_t{4} << 20);
    const LongTable table = read(text);
    ASSERT_EQ(table.rows.size(), written.size());
    const double origin = *written[3].rating;  // the first rating (rows 0-2 are NA)
    EXPECT_EQ(table.origin, origin);
    for (std::size_t i = 0; i < written.size(); ++i) {
        const RatingRow& row = table.rows[i];
        ASSERT_EQ(row.participant, written[i].participant) << i;
        ASSERT_EQ(row.level, written[i].level) << i;
        ASSERT_EQ(row.source_line, written[i].line) << i;
        ASSERT_EQ(row.rating.has_value(), written[i].rating.has_value()) << i;
        if (row.rating) ASSERT_EQ(table.origin + *row.rating, *written[i].rating) << i;
    }
    // A bad rating near the end (second half), then another near the start as well.
    std::string bad = text;
    const std::size_t late = bad.rfind(",translucent,") + 13;
    bad.replace(late, 1, "x");
    const std::string late_line = std::to_string(written.back().line);
    EXPECT_EQ(error_of(bad),
              "ratings.csv:" + late_line +
                  ": column 6 (rating): rating 'x' is not a finite number");
    const std::size_t early = bad.find(",translucent,", bad.find("participant10,")) + 13;
    bad.replace(early, 1, "y");
    EXPECT_EQ(error_of(bad).rfind("ratings.csv:12: column 6 (rating): rating 'y'", 0), 0u)
        << error_of(bad);
}

TEST(Label, EqualTextsAreOneLabelAndOrderByText) {
    const Label a("thickness"), b(std::string("thick") + "ness"), c("backlight"), empty;
    EXPECT_EQ(a, b);
    EXPECT_EQ(a.identity(), b.identity());
    EXPECT_NE(a, c);
    EXPECT_LT(c, a);  // "backlight" < "thickness"
    EXPECT_EQ(a, "thickness");
    EXPECT_EQ(a, std::string("thickness"));
    EXPECT_TRUE(empty.empty());
    EXPECT_EQ(Label(""), empty);
    EXPECT_EQ(a.str().size(), 9u);
    EXPECT_EQ(std::hash<Label>{}(a), std::hash<Label>{}(b));
    EXPECT_EQ("level " + a, "level thickness");
}

// Issue 26 item 10: ratings of +-1e308 with --scale any ended `analyze` with "lucent:
// stod" (the exact difference of 1e308 and -1e308 is 2e308, beyond a double, and
// std::stod threw an out_of_range that named nothing). Now one line names the file, the
// line and the column.
TEST(LongTable, RatingsOfPlusAndMinus1e308AreRefusedNamingFileLineAndColumnNotStod) {
    const std::string csv =
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,1e308\n"
        "p2,b,f,2,q,-1e308\n";
    std::string message;
    try {
        read(csv, RatingScale{true});
        ADD_FAILURE() << "not refused";
    } catch (const InputError& e) {
        message = e.what();
    }  // any other exception (std::out_of_range "stod") fails the test
    EXPECT_EQ(message.rfind("ratings.csv:3: column 6 (rating): rating '-1e308'", 0), 0u)
        << message;
    EXPECT_NE(message.find("(line 2)"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.find("stod"), std::string::npos) << message;
    // The column is the rating's wherever the header puts it.
    const std::string first = error_of(
        "rating,participant,stimulus,factor,level,question\n"
        "-1e308,p1,a,f,1,q\n1e308,p2,b,f,2,q\n",
        RatingScale{true});
    EXPECT_EQ(first.rfind("ratings.csv:3: column 1 (rating):", 0), 0u) << first;
}

// The overflow case: a rating text beyond the double range (1e400) is not a number the
// analysis takes; the line says so, where, and why.
TEST(LongTable, RatingsBeyondTheDoubleRangeAreRefusedNamingFileLineAndColumn) {
    const std::string first =
        error_of("participant,stimulus,factor,level,question,rating\np1,a,f,1,q,1e400\n",
                 RatingScale{true});
    EXPECT_EQ(first,
              "ratings.csv:2: column 6 (rating): rating '1e400' is beyond the range of "
              "a double (magnitudes up to about 1.8e308): rescale the ratings");
    const std::string later = error_of(
        "participant,stimulus,factor,level,question,rating\np1,a,f,1,q,3\np1,b,f,2,q,-"
        "1e400\n",
        RatingScale{true});
    EXPECT_EQ(
        later.rfind("ratings.csv:3: column 6 (rating): rating '-1e400' is beyond", 0), 0u)
        << later;
    // A word stays "not a finite number".
    EXPECT_NE(
        error_of("participant,stimulus,factor,level,question,rating\np,s,f,1,q,abc\n")
            .find(
                "ratings.csv:2: column 6 (rating): rating 'abc' is not a finite number"),
        std::string::npos);
}

// Finite ratings whose spread would overflow the sums of squares (0 and 1e200: one
// squared deviation is already 1e400) are refused too, naming the later of the two rows.
TEST(LongTable, RatingsSpreadBeyondFiniteSumsOfSquaresAreRefusedNamingTheRow) {
    const std::string message = error_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,0\np2,a,f,1,q,1\np3,b,f,2,q,1e200\n",
        RatingScale{true});
    EXPECT_EQ(message.rfind("ratings.csv:4: column 6 (rating): the ratings span 1e+200 "
                            "(this rating and line 2)",
                            0),
              0u)
        << message;
    // sqrt(DBL_MAX / 3) / 4 for three ratings.
    char limit[32];
    std::snprintf(limit, sizeof limit, "%.3g",
                  std::sqrt(std::numeric_limits<double>::max() / 3.0) / 4.0);
    EXPECT_NE(message.find(std::string("up to a span of ") + limit), std::string::npos)
        << message;
}

}  // namespace
}  // namespace lucent::analysis
