// The report's Matching and Thresholds sections: present only with such trials, their
// tables, plots (identity line, tracks, fits) and CSV files, and no NaN or infinity
// anywhere, degenerate conditions included.
#include "analysis/matching/matching_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "analysis/report/report.h"
#include "tests/analysis/matching/matching_fixtures.h"

namespace lucent::analysis {
namespace {

std::string read(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// No "nan" or "inf" as a number anywhere (words such as "information" are fine).
void expect_finite_text(const std::string& text, const std::string& what) {
    static const std::regex bad(
        R"((^|[^A-Za-z])-?(nan|NaN|NAN|inf|Inf|INF)([^A-Za-z]|$))");
    std::smatch m;
    EXPECT_FALSE(std::regex_search(text, m, bad))
        << what << ": '" << m.str() << "' at " << m.position();
}

TEST(MatchingReport, SectionsPlotsAndFilesWithoutNaN) {
    const study::Protocol p = testing::protocol();
    using testing::match_row;
    const std::vector<MatchRow> matches = {
        match_row("A", "front", 1.5), match_row("B", "front", 2.5),
        match_row("A", "front", 2.0), match_row("A", "two_factors", 10),
        match_row("B", "picture", 4),  // n = 1
    };
    std::mt19937_64 rng(2);
    auto rows = testing::simulate_staircases(p, "A", {1.0, 0.4, 0.0}, rng);
    // B always correct: below the smallest delta; C at chance.
    for (int i = 0; i < 20; ++i) {
        StaircaseRow r = rows[i];
        r.participant = std::string("B");
        r.session = std::string("B-s");
        r.correct = true;
        r.choice = r.expected;
        rows.push_back(r);
        r.participant = std::string("C");
        r.session = std::string("C-s");
        r.correct = i % 2 == 0;
        rows.push_back(r);
    }
    ThresholdOptions options;
    options.bootstrap = 50;
    const MatchingSection section = matching_section(
        analyse_matches(matches, &p), analyse_thresholds(rows, &p, options));
    const auto dir = std::filesystem::path(::testing::TempDir()) / "matching_report";
    std::filesystem::remove_all(dir);
    ReportOptions report;
    report.source = "test";
    report.extra_blocks = section.blocks;
    report.extra_files = section.files;
    const auto written = write_report({}, dir, report);
    const std::string html = read(dir / "report.html");
    EXPECT_NE(html.find("Matching"), std::string::npos);
    EXPECT_NE(html.find("Thresholds"), std::string::npos);
    EXPECT_NE(html.find("match = target"), std::string::npos);  // the identity line
    EXPECT_NE(html.find("fitted psi"), std::string::npos);
    EXPECT_NE(html.find("no constancy index: the target is a picture"),
              std::string::npos);
    EXPECT_NE(html.find("below the smallest delta shown"), std::string::npos);
    EXPECT_NE(html.find("at chance"), std::string::npos);
    EXPECT_NE(html.find("One match only"), std::string::npos);
    EXPECT_NE(html.find("Every match is at the range"), std::string::npos);
    // Wrong answers drawn open, reversals ringed.
    EXPECT_NE(html.find("fill=\"white\""), std::string::npos);
    EXPECT_NE(html.find("r=\"6.5\""), std::string::npos);
    for (const auto& f : written) {
        const std::string name = f.filename().string();
        expect_finite_text(read(f), name);
    }
    EXPECT_TRUE(std::filesystem::exists(dir / "matching.csv"));
    EXPECT_TRUE(std::filesystem::exists(dir / "thresholds.csv"));
    EXPECT_TRUE(std::filesystem::exists(dir / plot_file_name("matching", "m")));
    EXPECT_TRUE(std::filesystem::exists(dir / plot_file_name("staircase_A", "j")));
}

StaircaseRow staircase_row(const std::string& participant, double delta, bool correct,
                           int position) {
    StaircaseRow r;
    r.participant = participant;
    r.session = participant + "-s";
    r.trial = position;
    r.block = std::string("j");
    r.standard = std::string("std1");
    r.staircase = std::string("std1/up");
    r.intensity = delta;
    r.expected = 2;
    r.choice = correct ? 2 : 1;
    r.correct = correct;
    return r;
}

std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> fields;
    std::string field;
    bool quoted = false;
    for (char c : line) {
        if (c == '"') {
            quoted = !quoted;
        } else if (c == ',' && !quoted) {
            fields.push_back(field);
            field.clear();
        } else {
            field += c;
        }
    }
    fields.push_back(field);
    return fields;
}

// Issue 44, items 3 and 4 in the report and thresholds.csv: a JND between two deltas, an
// interval's end withheld below the deltas shown (no negative Weber fraction anywhere),
// and a participant right on every non-zero delta flagged in words and in a column.
TEST(MatchingReport, ThresholdsSayBetweenWithheldEndsAndFlags) {
    const study::Protocol p = testing::protocol();
    std::vector<StaircaseRow> rows;
    int position = 0;
    // L: at chance at 0.5 and 1, right from 1.5 up: between 1 and 1.5.
    for (int rep = 0; rep < 10; ++rep)
        for (double delta : {0.5, 1.0, 1.5, 2.0, 2.5})
            rows.push_back(
                staircase_row("L", delta, delta > 1.2 || rep % 2 == 0, position++));
    // W: 2 of 3 at 0.05, 4 of 5 at 0.1, 6 of 6 at 0.2: the lower end below 0.05.
    for (int i = 0; i < 3; ++i)
        rows.push_back(staircase_row("W", 0.05, i < 2, position++));
    for (int i = 0; i < 5; ++i)
        rows.push_back(staircase_row("W", 0.1, i < 4, position++));
    for (int i = 0; i < 6; ++i) rows.push_back(staircase_row("W", 0.2, true, position++));
    // S: right on all 30 non-zero deltas, half of the 10 at delta 0.
    for (int i = 0; i < 30; ++i)
        rows.push_back(staircase_row("S", 0.1 * (1 + i % 3), true, position++));
    for (int i = 0; i < 10; ++i)
        rows.push_back(staircase_row("S", 0.0, i % 2 == 0, position++));
    ThresholdOptions options;
    options.bootstrap = 1000;
    options.seed = 3;
    const MatchingSection section =
        matching_section({}, analyse_thresholds(rows, &p, options));
    const auto dir = std::filesystem::path(::testing::TempDir()) / "thresholds_report";
    std::filesystem::remove_all(dir);
    ReportOptions report;
    report.source = "test";
    report.extra_blocks = section.blocks;
    report.extra_files = section.files;
    const auto written = write_report({}, dir, report);
    for (const auto& f : written) expect_finite_text(read(f), f.filename().string());
    const std::string html = read(dir / "report.html");
    EXPECT_NE(html.find("between 1 and 1.5"), std::string::npos);
    EXPECT_NE(html.find("between 0.5 and 0.75"), std::string::npos);  // Weber, std 2
    EXPECT_NE(html.find("&lt; 0.05 .. "), std::string::npos);
    EXPECT_NE(html.find("&lt; 0.025 .. "), std::string::npos);
    EXPECT_NE(html.find("right on all 30 non-zero deltas"), std::string::npos);
    EXPECT_NE(html.find("Flagged: right on every one of the 30 trials"),
              std::string::npos);
    EXPECT_NE(html.find("20 or more of them"), std::string::npos);  // the rule stated

    std::istringstream csv(read(dir / "thresholds.csv"));
    std::string line;
    std::getline(csv, line);
    const std::vector<std::string> header = split(line);
    const auto column = [&](const std::string& name) {
        const auto it = std::find(header.begin(), header.end(), name);
        EXPECT_NE(it, header.end()) << name;
        return static_cast<std::size_t>(it - header.begin());
    };
    std::map<std::string, std::vector<std::string>> by;
    while (std::getline(csv, line)) {
        const auto fields = split(line);
        ASSERT_EQ(fields.size(), header.size()) << line;
        by[fields[0]] = fields;
    }
    ASSERT_EQ(by.size(), 3u);
    EXPECT_EQ(by["L"][column("jnd")], "");
    EXPECT_EQ(by["L"][column("jnd_text")], "between 1 and 1.5");
    EXPECT_EQ(by["L"][column("jnd_between_low")], "1");
    EXPECT_EQ(by["L"][column("jnd_between_high")], "1.5");
    EXPECT_EQ(by["L"][column("jnd_ci_low")], "");
    EXPECT_EQ(by["W"][column("jnd_ci_low")], "");
    EXPECT_EQ(by["W"][column("weber_ci_low")], "");
    EXPECT_EQ(by["W"][column("jnd_ci_text")].rfind("< 0.05 .. ", 0), 0u);
    EXPECT_GT(std::stoi(by["W"][column("bootstrap_below")]), 0.025 * 999);
    for (const auto& [id, fields] : by) {
        EXPECT_EQ(fields[column("all_nonzero_correct")], id == "S" ? "yes" : "no") << id;
        for (const char* name : {"weber", "weber_ci_low", "weber_ci_high"})
            EXPECT_TRUE(fields[column(name)].empty() ||
                        std::stod(fields[column(name)]) > 0)
                << id << " " << name;
    }
    EXPECT_EQ(by["S"][column("nonzero_delta_trials")], "30");
    EXPECT_EQ(by["S"][column("nonzero_delta_correct")], "30");
}

TEST(MatchingReport, NoSectionsWithoutSuchTrials) {
    const MatchingSection section = matching_section({}, {});
    EXPECT_TRUE(section.blocks.empty());
    EXPECT_TRUE(section.files.empty());
}

}  // namespace
}  // namespace lucent::analysis
