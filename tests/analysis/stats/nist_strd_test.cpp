// NIST StRD one-way ANOVA datasets: every certified value, through the real CSV reader
// (exact decimal origin) and the library's ANOVA. Reports the log relative error (LRE).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "analysis/data/grouping.h"
#include "analysis/data/long_table.h"
#include "analysis/stats/anova.h"
#include "tests/support/test_paths.h"

namespace lucent::analysis {
namespace {

struct NistDataset {
    double df_between = 0, df_within = 0, ss_between = 0, ms_between = 0, f = 0;
    double ss_within = 0, ms_within = 0, r_squared = 0, residual_sd = 0;
    std::string long_csv;  // the data as the long CSV `lucent analyze` reads
};

std::vector<std::string> tokens(const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> out;
    for (std::string t; in >> t;) out.push_back(t);
    return out;
}

// Certified values are found by their labels (AtmWtAg's stated line numbers are off by
// one); data rows follow the "Data:" line. Lines may end in CRLF.
NistDataset read_nist(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    NistDataset d;
    std::ostringstream csv;
    csv << "participant,stimulus,factor,level,question,rating\n";
    bool in_data = false;
    int row = 0;
    for (std::string line; std::getline(in, line);) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const auto t = tokens(line);
        if (t.empty()) continue;
        if (in_data) {
            if (t.size() == 2)
                csv << ++row << ",,"
                    << "treatment," << t[0] << ",response," << t[1] << "\n";
            continue;
        }
        const std::size_t n = t.size();
        if (t[0] == "Data:" && d.residual_sd > 0)
            in_data = true;  // not the header's "Data: 1 Factor"
        else if (t[0] == "Between" && n >= 5) {
            d.df_between = std::stod(t[n - 4]);
            d.ss_between = std::stod(t[n - 3]);
            d.ms_between = std::stod(t[n - 2]);
            d.f = std::stod(t[n - 1]);
        } else if (t[0] == "Within" && n >= 4) {
            d.df_within = std::stod(t[n - 3]);
            d.ss_within = std::stod(t[n - 2]);
            d.ms_within = std::stod(t[n - 1]);
        } else if (line.find("Certified R-Squared") != std::string::npos) {
            d.r_squared = std::stod(t[n - 1]);
        } else if (t[0] == "Standard" && n >= 3 && t[1] == "Deviation") {
            d.residual_sd = std::stod(t[n - 1]);
        }
    }
    d.long_csv = csv.str();
    return d;
}

// Log relative error, capped at 15 as NIST does.
double lre(double value, double certified) {
    if (value == certified) return 15.0;
    return std::min(15.0,
                    -std::log10(std::fabs(value - certified) / std::fabs(certified)));
}

struct Case {
    const char* name;
    double min_lre;  // 9 for lower and average difficulty, 7 for higher
};

class NistAnova : public ::testing::TestWithParam<Case> {};

TEST_P(NistAnova, MatchesEveryCertifiedValue) {
    const Case c = GetParam();
    const std::string rel = std::string("data/nist-strd-anova/") + c.name + ".dat";
    LUCENT_REQUIRE_SHARED(rel);
    const NistDataset nist = read_nist(test::shared_dir() / rel);
    ASSERT_GT(nist.f, 0.0) << "certified block not found in " << rel;
    ASSERT_GT(nist.residual_sd, 0.0);

    std::istringstream csv(nist.long_csv);
    const LongTable table = read_long_csv(csv, rel, RatingScale{true});
    const auto pairs = split_by_question_and_factor(table);
    ASSERT_EQ(pairs.size(), 1u);
    const AnovaResult r = one_way_anova(pairs[0].data);
    ASSERT_TRUE(r.f && r.ms_within && r.eta_sq);

    EXPECT_EQ(r.df_between, nist.df_between);
    EXPECT_EQ(r.df_within, nist.df_within);
    const std::pair<const char*, std::pair<double, double>> checks[] = {
        {"SS between", {r.ss_between, nist.ss_between}},
        {"MS between", {*r.ms_between, nist.ms_between}},
        {"F", {*r.f, nist.f}},
        {"SS within", {r.ss_within, nist.ss_within}},
        {"MS within", {*r.ms_within, nist.ms_within}},
        {"R squared", {*r.eta_sq, nist.r_squared}},
        {"residual SD", {std::sqrt(*r.ms_within), nist.residual_sd}}};
    double worst = 15.0;
    for (const auto& [label, values] : checks) {
        const double digits = lre(values.first, values.second);
        worst = std::min(worst, digits);
        EXPECT_GE(digits, c.min_lre) << c.name << " " << label << ": " << values.first
                                     << " vs certified " << values.second;
    }
    std::printf("[ LRE      ] %-8s F %.1f, worst certified value %.1f\n", c.name,
                lre(*r.f, nist.f), worst);
    RecordProperty("worst_lre", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(StRD, NistAnova,
                         ::testing::Values(Case{"SiRstv", 9}, Case{"SmLs01", 9},
                                           Case{"SmLs02", 9}, Case{"SmLs03", 9},
                                           Case{"AtmWtAg", 9}, Case{"SmLs04", 9},
                                           Case{"SmLs05", 9}, Case{"SmLs06", 9},
                                           Case{"SmLs07", 7}, Case{"SmLs08", 7},
                                           Case{"SmLs09", 7}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lucent::analysis
