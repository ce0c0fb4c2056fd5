// Issue 51 item 3: a rating model that exists only in this test, registered here (one
// RatingModelSpec and one RatingModelRegistration: what a model of analysis/models/ is
// plus its registry line), is run, reported and checked by every layer that asks the
// registry, with no other edit: `lucent analyze --model` and `--primary-model`, the
// report's summary, sections and mixed_tests.csv, a protocol's [analysis] plan, and
// `lucent power`, which says the model has no power simulation.
#include <gtest/gtest.h>

#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/models/rating_model.h"
#include "analysis/report/mixed_sections.h"
#include "app/analysis_plan.h"
#include "app/cli_main.h"
#include "app/commands.h"
#include "common/csv.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::analysis {
namespace {

namespace fs = std::filesystem;

// rating ~ level with no random effect, tested by the F of the level: a fixed-effects
// model, enough to show a model's whole way through.
RatingModelFit fit_fixed_effects(const PairFrame& pair,
                                 const RandomStructure& structure) {
    RatingModelFit fit = empty_fit("test_ols", pair, structure);
    fit.formula = "rating ~ level";
    std::map<std::string, std::pair<double, double>> sum_and_count;
    const std::vector<std::string>& level = pair.frame.text("level");
    double grand = 0.0;
    for (std::size_t i = 0; i < pair.ratings.size(); ++i) {
        sum_and_count[level[i]].first += pair.ratings[i];
        sum_and_count[level[i]].second += 1.0;
        grand += pair.ratings[i] / double(pair.ratings.size());
    }
    double between = 0.0, within = 0.0;
    for (const auto& [l, sc] : sum_and_count)
        between += sc.second * std::pow(sc.first / sc.second - grand, 2);
    for (std::size_t i = 0; i < pair.ratings.size(); ++i) {
        const auto& sc = sum_and_count[level[i]];
        within += std::pow(pair.ratings[i] - sc.first / sc.second, 2);
    }
    const double df1 = double(sum_and_count.size()) - 1.0,
                 df2 = double(pair.ratings.size()) - double(sum_and_count.size());
    if (df1 < 1.0 || df2 < 1.0 || within <= 0.0) {
        fit.notes.push_back("No residual variance: F is undefined.");
        return fit;
    }
    fit.fitted = true;
    fit.statistic = (between / df1) / (within / df2);
    fit.df = df1;
    fit.den_df = df2;
    fit.p = boost::math::cdf(
        boost::math::complement(boost::math::fisher_f(df1, df2), *fit.statistic));
    return fit;
}

const RatingModelSpec kFixedEffects{
    .name = "test_ols",
    .ran = "fixed-effects linear model (test_ols) likewise; ",
    .title = "fixed-effects linear model (test_ols)",
    .test = "F (fixed effects)",
    .help = "test_ols (a test's fixed-effects model)",
    .fit = [](const PairFrame& pair, const RandomStructure& structure,
              const ModelChoice&) { return fit_fixed_effects(pair, structure); },
    .blocks =
        [](const OneWayAnalysis& pair, const RatingModelFit& fit) {
            return std::vector<Block>{
                {Block::kHeading, "Fixed-effects linear model (test_ols)", {}, {}, 3},
                {Block::kParagraph,
                 "F test of " + pair.factor + ": " + fit_counts_text(fit) + "."}};
        }};

// Two levels, three participants: the F by hand below.
constexpr const char* kRatings =
    "participant,stimulus,factor,level,question,rating\n"
    "p1,a,thickness,18,translucent,2\np1,b,thickness,25,translucent,5\n"
    "p2,a,thickness,18,translucent,3\np2,b,thickness,25,translucent,6\n"
    "p3,a,thickness,18,translucent,4\np3,b,thickness,25,translucent,4\n";

int run(std::vector<std::string> args) {
    args.insert(args.begin(), "lucent");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    return app::run_cli(static_cast<int>(argv.size()), argv.data(),
                        {app::register_analyze, app::register_power});
}

std::string read(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

class RegisteredModel : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = lucent::test::scratch_dir("registered_model");
        csv_ = (dir_ / "ratings.csv").string();
        std::ofstream(csv_) << kRatings;
    }
    fs::path dir_;
    std::string csv_;
};

TEST_F(RegisteredModel, LucentAnalyzeFitsReportsAndLetsItLead) {
    const RatingModelRegistration registration(kFixedEffects);
    const std::string out = (dir_ / "report").string();
    ASSERT_EQ(run({"analyze", csv_, "--out", out, "--model", "anova,test_ols",
                   "--primary-model", "test_ols"}),
              app::kExitOk);
    const std::string report = read(fs::path(out) / "report.md");
    EXPECT_NE(report.find("Fixed-effects linear model (test_ols)"), std::string::npos);
    EXPECT_NE(report.find("fixed-effects linear model (test_ols) likewise"),
              std::string::npos);
    EXPECT_NE(report.find("Primary analysis: the fixed-effects linear model (test_ols)"),
              std::string::npos);
    EXPECT_NE(report.find("test_ols (primary)"), std::string::npos);

    // By hand: means 3 and 5, grand 4; SS between 6 * 1 = 6, SS within 2 + 2 = 4;
    // F = (6 / 1) / (4 / 4) = 6 on 1 and 4 df.
    std::ifstream tests(fs::path(out) / "mixed_tests.csv");
    std::string line;
    std::getline(tests, line);
    const std::vector<std::string> header = common::split_csv_line(line);
    ASSERT_TRUE(std::getline(tests, line));
    const std::vector<std::string> row = common::split_csv_line(line);
    std::map<std::string, std::string> cell;
    for (std::size_t c = 0; c < header.size() && c < row.size(); ++c)
        cell[header[c]] = row[c];
    EXPECT_EQ(cell["model"], "test_ols");
    EXPECT_EQ(cell["formula"], "rating ~ level");
    EXPECT_NEAR(std::stod(cell["statistic"]), 6.0, 1e-12);
    EXPECT_EQ(cell["df"], "1");
    EXPECT_EQ(cell["den_df"], "4");
    // F(1, 4) is T^2 with T on 4 df, whose tail is closed: P(|T| > t) = 1 - x (3 - x^2)
    // / 2 with x = t / sqrt(t^2 + 4); t = sqrt(6).
    const double x = std::sqrt(6.0) / std::sqrt(10.0);
    EXPECT_NEAR(std::stod(cell["p"]), 1.0 - x * (3.0 - x * x) / 2.0, 1e-12);
}

TEST_F(RegisteredModel, UnregisteredItIsRefusedByNameEverywhere) {
    const std::string out = (dir_ / "refused").string();
    testing::internal::CaptureStderr();
    EXPECT_EQ(run({"analyze", csv_, "--out", out, "--model", "anova,test_ols"}),
              app::kExitUsage);
    EXPECT_NE(testing::internal::GetCapturedStderr().find(
                  "--model: 'test_ols' is not one of anova, clmm, lmm"),
              std::string::npos);
    const std::string text = std::string(lucent::test::kSmallProtocol) +
                             "\n[analysis]\nprimary_model = \"test_ols\"\n";
    const study::Protocol planned = study::parse_protocol(text, "plan.toml");
    try {
        app::check_analysis_plan(planned);
        FAIL() << "an unregistered model passed the plan's check";
    } catch (const study::ProtocolError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("plan.toml:", 0), 0u) << message;
        EXPECT_NE(message.find("analysis.primary_model"), std::string::npos) << message;
        EXPECT_NE(message.find("'test_ols'"), std::string::npos) << message;
    }
    const RatingModelRegistration registration(kFixedEffects);
    EXPECT_NO_THROW(app::check_analysis_plan(planned));
    // Registered, it has no power simulation, and `lucent power` says so.
    testing::internal::CaptureStderr();
    EXPECT_EQ(run({"power", "--model", "test_ols", "--means", "4,5"}), app::kExitUsage);
    EXPECT_NE(testing::internal::GetCapturedStderr().find(
                  "--model must be clmm or lmm for a crossed design ('test_ols' has no "
                  "power simulation)"),
              std::string::npos);
}

TEST(RatingModelRegistry, ANameIsRegisteredOnce) {
    RatingModelSpec clmm_again = kFixedEffects;
    clmm_again.name = "clmm";
    EXPECT_THROW(RatingModelRegistration{clmm_again}, std::logic_error);
    RatingModelSpec anova = kFixedEffects;
    anova.name = "anova";
    EXPECT_THROW(RatingModelRegistration{anova}, std::logic_error);
}

}  // namespace
}  // namespace lucent::analysis
