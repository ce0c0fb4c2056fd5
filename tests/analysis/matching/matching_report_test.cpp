// The report's Matching and Thresholds sections: present only with such trials, their
// tables, plots (identity line, tracks, fits) and CSV files, and no NaN or infinity
// anywhere, degenerate conditions included.
#include "analysis/matching/matching_report.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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

TEST(MatchingReport, NoSectionsWithoutSuchTrials) {
    const MatchingSection section = matching_section({}, {});
    EXPECT_TRUE(section.blocks.empty());
    EXPECT_TRUE(section.files.empty());
}

}  // namespace
}  // namespace lucent::analysis
