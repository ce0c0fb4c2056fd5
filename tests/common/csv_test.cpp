// CSV fields against RFC 4180: quoted only when a comma, a quote or a line break needs
// it, inner quotes doubled, and quoted fields (commas, quotes, line breaks) read back.
#include "common/csv.h"

#include <gtest/gtest.h>

namespace lucent::common {
namespace {

using Fields = std::vector<std::string>;

TEST(Csv, FieldIsQuotedOnlyWhenNeeded) {
    EXPECT_EQ(csv_field("plain"), "plain");
    EXPECT_EQ(csv_field(""), "");
    EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
    EXPECT_EQ(csv_field("0.8,0.5,0.3"), "\"0.8,0.5,0.3\"");
    EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
    EXPECT_EQ(csv_field("cr\rhere"), "\"cr\rhere\"");
    EXPECT_EQ(csv_field("semi;colon tab\t"), "semi;colon tab\t");
}

TEST(Csv, QuotedAlwaysQuotes) {
    EXPECT_EQ(csv_quoted("plain"), "\"plain\"");
    EXPECT_EQ(csv_quoted(""), "\"\"");
    EXPECT_EQ(csv_quoted("a\"b"), "\"a\"\"b\"");
}

TEST(Csv, SplitsAndUnquotesRfc4180Fields) {
    EXPECT_EQ(split_csv_line("a,b,c"), (Fields{"a", "b", "c"}));
    EXPECT_EQ(split_csv_line(""), (Fields{""}));
    EXPECT_EQ(split_csv_line(",,"), (Fields{"", "", ""}));
    EXPECT_EQ(split_csv_line("\"a,b\",c"), (Fields{"a,b", "c"}));
    EXPECT_EQ(split_csv_line("\"say \"\"hi\"\"\",x"), (Fields{"say \"hi\"", "x"}));
    EXPECT_EQ(split_csv_line("\"\",\"\"\"\""), (Fields{"", "\""}));
    EXPECT_EQ(split_csv_line("a,\"two\nlines\""), (Fields{"a", "two\nlines"}));
    // A line read by std::getline from a CRLF file ends in CR: it is not data.
    EXPECT_EQ(split_csv_line("a,b\r"), (Fields{"a", "b"}));
}

TEST(Csv, WrittenFieldsReadBack) {
    for (std::string text : {"plain", "0.8,0.5,0.3", "say \"hi\"", "", "a,\"b\",c",
                             "two\nlines", "\"", ",", "x,\"y\"\nz"}) {
        const Fields fields = split_csv_line(csv_field(text) + "," + csv_field("next"));
        ASSERT_EQ(fields.size(), 2u) << text;
        EXPECT_EQ(fields[0], text);
        EXPECT_EQ(fields[1], "next");
        EXPECT_EQ(split_csv_line(csv_quoted(text)), (Fields{text}));
    }
}

TEST(Csv, RecordsOpenAtTheEndOfALineGoOnOnTheNext) {
    Fields fields;
    EXPECT_FALSE(decode_csv_record("a,\"first", fields));
    EXPECT_TRUE(decode_csv_record("a,\"first\nsecond\",b", fields));
    EXPECT_EQ(fields, (Fields{"a", "first\nsecond", "b"}));
    // A quoted CRLF is data either way; a bare CR is kept or dropped as asked.
    EXPECT_TRUE(decode_csv_record("\"x\r\ny\",a\rb", fields, BareCarriageReturn::keep));
    EXPECT_EQ(fields, (Fields{"x\r\ny", "a\rb"}));
    EXPECT_TRUE(decode_csv_record("\"x\r\ny\",a\rb", fields, BareCarriageReturn::drop));
    EXPECT_EQ(fields, (Fields{"x\r\ny", "ab"}));
}

}  // namespace
}  // namespace lucent::common
