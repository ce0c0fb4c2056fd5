#include "analysis/mixed/clmm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tests/support/test_paths.h"

// Expected values are R 4.2.2 / ordinal 2022.11-16, printed with options(digits = 15),
// the R call beside each. On tolerances: R's nlminb stops about 1e-6 (relative) short of
// the maximum of its own objective (WineJudgeRObjective shows that our maximum is higher
// on R's function), and R's standard errors come from a central-difference Hessian with
// step 1e-4, whose rounding noise is a few 1e-6; the tolerances below are the measured
// agreement rounded up, and 1e-6 or tighter wherever R's own precision allows it.

namespace lucent::analysis::mixed {
namespace {

DataFrame wine() {
    return DataFrame::read_csv(lucent::test::source_dir() /
                               "tests/analysis/mixed/data/wine.csv");
}

ClmmSpec wine_spec(const DataFrame& frame, const std::vector<std::string>& terms,
                   const std::vector<std::string>& groupings, Link link = Link::Logit) {
    ClmmSpec spec;
    spec.response = frame.factor("rating");
    std::vector<FixedTerm> fixed;
    for (const auto& t : terms) fixed.push_back({t, true, {}});
    spec.fixed = fixed_design(frame, fixed, false);
    for (const auto& g : groupings) spec.random_intercepts.push_back(frame.factor(g));
    spec.link = link;
    return spec;
}

void expect_rel(double actual, double expected, double tolerance,
                const std::string& what) {
    EXPECT_NEAR(actual, expected, tolerance * std::abs(expected)) << what;
}

// Thresholds then coefficients, as R's coef() prints them.
std::vector<ClmmEstimate> all_estimates(const ClmmFit& fit) {
    std::vector<ClmmEstimate> all = fit.thresholds;
    all.insert(all.end(), fit.coefficients.begin(), fit.coefficients.end());
    return all;
}

void expect_estimates(const ClmmFit& fit, const std::vector<double>& estimates,
                      const std::vector<double>& std_errors, double tol_estimate,
                      double tol_se) {
    const auto all = all_estimates(fit);
    ASSERT_EQ(all.size(), estimates.size());
    for (std::size_t j = 0; j < all.size(); ++j) {
        expect_rel(all[j].estimate, estimates[j], tol_estimate, all[j].name);
        if (!std_errors.empty())
            expect_rel(all[j].std_error, std_errors[j], tol_se, all[j].name + " se");
    }
}

bool has_note(const ClmmFit& fit, const std::string& text) {
    return std::any_of(fit.notes.begin(), fit.notes.end(), [&](const std::string& note) {
        return note.find(text) != std::string::npos;
    });
}

void expect_all_finite(const ClmmFit& fit) {
    EXPECT_TRUE(std::isfinite(fit.log_likelihood));
    for (const auto& e : all_estimates(fit)) {
        EXPECT_TRUE(std::isfinite(e.estimate)) << e.name;
        EXPECT_TRUE(std::isfinite(e.std_error)) << e.name;
    }
    for (const auto& g : fit.groupings) {
        EXPECT_TRUE(std::isfinite(g.variance)) << g.name;
        EXPECT_TRUE(std::isfinite(g.sd)) << g.name;
    }
}

// clmm(rating ~ temp + contact + (1|judge), data = wine)
const std::vector<double> kJudgeEstimates = {-1.62366692406869, 1.51336518291881,
                                             4.22852668849532,  6.08877255848077,
                                             3.06299662584431,  1.83488492228405};
const std::vector<double> kJudgeStdErrors = {0.682441031959170, 0.603753330430831,
                                             0.808966050324495, 0.972453654184804,
                                             0.595376183131184, 0.512529332005404};
constexpr double kJudgeLogLik = -81.5654092921275;
constexpr double kJudgeVariance = 1.27946090925484;  // sd 1.13113257810693

TEST(Clmm, WineJudgeLogitEqualsR) {
    const ClmmFit fit = fit_clmm(wine_spec(wine(), {"temp", "contact"}, {"judge"}));
    EXPECT_TRUE(fit.converged);
    EXPECT_TRUE(fit.notes.empty());
    expect_rel(fit.log_likelihood, kJudgeLogLik, 1e-12, "logLik");
    EXPECT_EQ(fit.parameters, 7);
    EXPECT_EQ(fit.thresholds[0].name, "1|2");
    EXPECT_EQ(fit.thresholds[3].name, "4|5");
    EXPECT_EQ(fit.coefficients[0].name, "tempwarm");
    EXPECT_EQ(fit.coefficients[1].name, "contactyes");
    // Measured: estimates 1.6e-6 (1|2; the rest <= 9e-7), standard errors <= 6.4e-6.
    expect_estimates(fit, kJudgeEstimates, kJudgeStdErrors, 2e-6, 1e-5);
    ASSERT_EQ(fit.groupings.size(), 1u);
    EXPECT_EQ(fit.groupings[0].levels, 9);
    expect_rel(fit.groupings[0].variance, kJudgeVariance, 5e-6, "judge variance");
    expect_rel(fit.groupings[0].sd, std::sqrt(kJudgeVariance), 3e-6, "judge sd");
}

// Our objective is R's: at R's estimates it gives R's log-likelihood to rounding, and our
// maximum is at least as high, so the differences above are R's optimiser stopping short.
TEST(Clmm, WineJudgeRObjective) {
    const ClmmSpec spec = wine_spec(wine(), {"temp", "contact"}, {"judge"});
    const std::vector<double> thresholds(kJudgeEstimates.begin(),
                                         kJudgeEstimates.begin() + 4);
    const std::vector<double> effects(kJudgeEstimates.begin() + 4, kJudgeEstimates.end());
    const double at_r =
        clmm_log_likelihood_at(spec, thresholds, effects, {std::sqrt(kJudgeVariance)});
    expect_rel(at_r, kJudgeLogLik, 1e-13, "R's objective at R's estimates");
    EXPECT_GE(fit_clmm(spec).log_likelihood, at_r - 1e-13);
}

TEST(Clmm, WineJudgeProbitEqualsR) {
    const ClmmFit fit =
        fit_clmm(wine_spec(wine(), {"temp", "contact"}, {"judge"}, Link::Probit));
    // clmm(rating ~ temp + contact + (1|judge), data = wine, link = "probit")
    expect_rel(fit.log_likelihood, -80.9306071535645, 1e-11,
               "logLik");  // ours 1e-10 higher
    expect_rel(fit.coefficients[0].estimate, 1.800014411244547, 1e-6, "tempwarm");
    expect_estimates(fit,
                     {-0.926479680282878, 0.889437776051073, 2.467592735987285,
                      3.536662180626951, 1.800014411244547, 1.048205467119597},
                     {0.388151355351634, 0.348476506506062, 0.446872253520068,
                      0.525615926869757, 0.326939982085039, 0.285545228506720},
                     4e-6, 5e-6);
    expect_rel(fit.groupings[0].variance, 0.439772152814162, 1e-5, "judge variance");
}

TEST(Clmm, WineClmEqualsR) {
    const ClmmFit fit = fit_clmm(wine_spec(wine(), {"temp", "contact"}, {}));
    // clm(rating ~ temp + contact, data = wine): exact Newton, so tight agreement.
    EXPECT_TRUE(fit.converged);
    EXPECT_EQ(fit.parameters, 6);
    expect_rel(fit.log_likelihood, -86.4919233656491, 1e-13, "logLik");
    expect_estimates(fit,
                     {-1.34438341126472, 1.25080879841654, 3.46688692647397,
                      5.00640420426996, 2.50310200789893, 1.52779765809506},
                     {0.517102045324273, 0.437880202961600, 0.597760424608409,
                      0.730906343666974, 0.528680100824846, 0.476622629648298},
                     1e-9, 1e-9);
}

TEST(Clmm, WineClmProbitEqualsR) {
    const ClmmFit fit =
        fit_clmm(wine_spec(wine(), {"temp", "contact"}, {}, Link::Probit));
    // clm(rating ~ temp + contact, data = wine, link = "probit")
    expect_rel(fit.log_likelihood, -85.761148364776574, 1e-13, "logLik");
    expect_estimates(fit,
                     {-0.773262728758367, 0.736021489839440, 2.044680463850121,
                      2.941344982257154, 1.499374578398644, 0.867743538882857},
                     {0.282862357058857, 0.249938818301151, 0.321821013936779,
                      0.387259280359505, 0.291790391089871, 0.266907009281740},
                     1e-9, 1e-9);
}

TEST(Clmm, WineCrossedEqualsR) {
    const ClmmFit fit = fit_clmm(wine_spec(wine(), {"contact"}, {"judge", "bottle"}));
    // clmm(rating ~ contact + (1|judge) + (1|bottle), data = wine)
    EXPECT_TRUE(fit.converged);
    EXPECT_EQ(fit.parameters, 7);
    expect_rel(fit.log_likelihood, -90.9566388388736, 1e-13, "logLik");
    expect_estimates(fit,
                     {-2.9865810446248693, 0.0225479356407957, 2.5594999820155739,
                      4.3388666629025634, 1.7805162457810584},
                     {0.998569339712349, 0.870573864022776, 0.944677865450673,
                      1.057127195958413, 1.112762766625204},
                     5e-6, 4e-6);  // measured 2.9e-6 (2|3, near 0), 3.2e-6
    expect_rel(fit.groupings[0].variance, 1.19387592597787, 1e-7, "judge variance");
    expect_rel(fit.groupings[1].variance, 1.94990364094953, 1e-7, "bottle variance");
}

TEST(Clmm, WineCrossedBottleAtBoundary) {
    const ClmmFit fit =
        fit_clmm(wine_spec(wine(), {"temp", "contact"}, {"judge", "bottle"}));
    // clmm(rating ~ temp + contact + (1|judge) + (1|bottle), data = wine): R's bottle
    // variance is 1.6e-11 (its search parameter stops near 0), ours is the boundary.
    ASSERT_EQ(fit.groupings.size(), 2u);
    EXPECT_TRUE(fit.groupings[1].at_boundary);
    EXPECT_EQ(fit.groupings[1].variance, 0.0);
    EXPECT_TRUE(has_note(fit, "boundary (singular) fit"));
    EXPECT_EQ(fit.parameters, 8);
    expect_rel(fit.log_likelihood, -81.5654127769674, 1e-11, "logLik");
    expect_estimates(fit,
                     {-1.62366542798494, 1.51336020717642, 4.22852710366230,
                      6.08877643882278, 3.06300324035050, 1.83490270352768},
                     {0.682437215449920, 0.603736820399324, 0.808958124296320,
                      0.972458643891623, 0.595391635794609, 0.512558713421359},
                     3e-6, 1e-5);
    expect_rel(fit.groupings[0].variance, 1.27948827069151, 3e-5, "judge variance");
}

TEST(Clmm, LikelihoodRatioTestOfContactEqualsR) {
    const ClmmSpec spec = wine_spec(wine(), {"temp", "contact"}, {"judge"});
    const ClmmFit full = fit_clmm(spec);
    const ClmmLikelihoodRatioTest test =
        clmm_likelihood_ratio_test(spec, full, "contact");
    // anova(clmm(rating ~ temp + (1|judge), data = wine),
    //       clmm(rating ~ temp + contact + (1|judge), data = wine))
    expect_rel(test.log_likelihood_reduced, -88.7388151628385, 1e-11, "reduced logLik");
    EXPECT_EQ(test.parameters_reduced, 6);
    EXPECT_EQ(test.df, 1);
    expect_rel(test.chi_square, 14.346811741422, 1e-9, "LR.stat");
    expect_rel(test.p, 0.000152036938964081, 1e-8, "Pr(>Chisq)");
    EXPECT_THROW(clmm_likelihood_ratio_test(spec, full, "nothing"), std::exception);
}

TEST(Clmm, ExactModesAgreeWithRModesClosely) {
    ClmmSpec spec = wine_spec(wine(), {"temp", "contact"}, {"judge"});
    spec.modes = ClmmModes::Exact;
    const ClmmFit exact = fit_clmm(spec);
    // The fully converged Laplace approximation (R's clmm with tight inner tolerance
    // gives -81.5654127767727).
    expect_rel(exact.log_likelihood, -81.5654127767727, 1e-11, "logLik");
    expect_estimates(exact, kJudgeEstimates, kJudgeStdErrors, 1e-5, 1e-4);
}

// ---------------------------------------------------------------------------------------
// Hard cases (issue 29, section 3).

TEST(ClmmHardCases, ParticipantWithOneRatingForEverything) {
    auto frame = wine();
    auto rating = frame.text("rating");
    const auto& judge = frame.text("judge");
    for (std::size_t i = 0; i < rating.size(); ++i)
        if (judge[i] == "9") rating[i] = "5";
    frame.set("rating", rating);
    const ClmmFit fit = fit_clmm(wine_spec(frame, {"temp", "contact"}, {"judge"}));
    expect_all_finite(fit);
    EXPECT_TRUE(has_note(fit, "judge '9' gave the same rating ('5') to all 8"));
    // w2 <- wine; w2$rating[w2$judge == 9] <- "5"
    // clmm(rating ~ temp + contact + (1|judge), data = w2)
    expect_rel(fit.log_likelihood, -80.193762498973953, 1e-11, "logLik");
    expect_estimates(fit,
                     {-2.832084641554576, 0.454652071521320, 3.246534253747579,
                      4.820524951248046, 2.908079596223248, 1.558239718043011},
                     {1.071287410003435, 0.943047443968002, 1.054085114176580,
                      1.139890208146777, 0.617858996015293, 0.523067377056485},
                     1e-5, 1e-5);
    expect_rel(fit.groupings[0].variance, 6.153807432980020, 1e-5, "judge variance");
}

TEST(ClmmHardCases, UnusedRatingCategoryIsDropped) {
    const auto frame = wine();
    ClmmSpec spec = wine_spec(frame, {"temp", "contact"}, {"judge"});
    const ClmmFit reference = fit_clmm(spec);
    spec.response = frame.factor("rating", {"1", "2", "2.5", "3", "4", "5", "6"});
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_TRUE(has_note(fit, "rating category '2.5'"));
    EXPECT_TRUE(has_note(fit, "rating category '6'"));
    EXPECT_EQ(fit.response_levels, reference.response_levels);
    EXPECT_EQ(fit.thresholds[1].name, "2|3");
    EXPECT_EQ(fit.log_likelihood, reference.log_likelihood);
    expect_estimates(fit, kJudgeEstimates, kJudgeStdErrors, 2e-6, 1e-5);
}

// x = 1 is always rated 5, x = 0 uses every category 4 times: the effect of x runs to
// infinity, and the thresholds are those of x = 0 alone, logit(j / 5) (R's clm gives
// the same thresholds with x = 22.04 and "Hessian is numerically singular").
DataFrame separated_frame(int groups) {
    DataFrame frame;
    std::vector<std::string> y, x, g;
    for (int group = 0; group < groups; ++group) {
        for (int k = 1; k <= 5; ++k)
            for (int r = 0; r < 4; ++r) {
                y.push_back(std::to_string(k));
                x.push_back("0");
                g.push_back("g" + std::to_string((r + k + group) % groups));
            }
        for (int r = 0; r < 6; ++r) {
            y.push_back("5");
            x.push_back("1");
            g.push_back("g" + std::to_string(r % groups));
        }
    }
    frame.set("y", y);
    frame.set("x", x);
    frame.set("g", g);
    return frame;
}

TEST(ClmmHardCases, CompleteSeparationIsReportedNotNaN) {
    const DataFrame frame = separated_frame(1);
    ClmmSpec spec;
    spec.response = frame.factor("y");
    spec.fixed = fixed_design(frame, {{"x", false, {}}}, false);
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_TRUE(
        has_note(fit, "complete separation: x is not estimable (runs to infinity)"));
    EXPECT_FALSE(fit.coefficients[0].estimable);
    EXPECT_GT(fit.coefficients[0].estimate, 10);
    for (int j = 0; j < 4; ++j) {
        EXPECT_TRUE(fit.thresholds[std::size_t(j)].estimable);
        EXPECT_NEAR(fit.thresholds[std::size_t(j)].estimate,
                    std::log((j + 1.0) / (4 - j)), 1e-6);
    }
    // The log-likelihood tends to that of x = 0 alone: 20 log(1/5).
    EXPECT_NEAR(fit.log_likelihood, 20 * std::log(0.2), 1e-6);
}

// Three ratings, one per level, all different: a parameter per level fits them exactly,
// so every threshold and effect runs off together and the whole information matrix is
// tiny (no direction stands out against a better one). Before the absolute test this
// reported effects of +-65 with standard errors of 2e7 as estimable.
TEST(ClmmHardCases, SaturatedModelIsNotEstimable) {
    DataFrame frame;
    frame.set("y", {"5", "4", "6"});
    frame.set("level", {"a", "b", "c"});
    ClmmSpec spec;
    spec.response = frame.factor("y");
    spec.fixed = fixed_design(frame, {{"level", true, {}}}, false);
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    ASSERT_EQ(fit.coefficients.size(), 2u);
    EXPECT_FALSE(fit.coefficients[0].estimable);
    EXPECT_FALSE(fit.coefficients[1].estimable);
    EXPECT_TRUE(has_note(fit, "complete separation"));
}

TEST(ClmmHardCases, CompleteSeparationWithRandomIntercepts) {
    const DataFrame frame = separated_frame(3);
    ClmmSpec spec;
    spec.response = frame.factor("y");
    spec.fixed = fixed_design(frame, {{"x", false, {}}}, false);
    spec.random_intercepts = {frame.factor("g")};
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_TRUE(
        has_note(fit, "complete separation: x is not estimable (runs to infinity)"));
    EXPECT_FALSE(fit.coefficients[0].estimable);
}

TEST(ClmmHardCases, VarianceAtZeroGivesTheClmFit) {
    // Four groups with identical data: no spread between them.
    DataFrame frame;
    const std::vector<std::string> x0 = {"0", "0", "0", "0", "0",
                                         "1", "1", "1", "1", "1"};
    const std::vector<std::string> y0 = {"1", "2", "2", "3", "4",
                                         "2", "3", "4", "4", "5"};
    std::vector<std::string> x, y, g;
    for (int group = 1; group <= 4; ++group)
        for (std::size_t i = 0; i < x0.size(); ++i) {
            x.push_back(x0[i]);
            y.push_back(y0[i]);
            g.push_back(std::to_string(group));
        }
    frame.set("x", x);
    frame.set("y", y);
    frame.set("g", g);
    ClmmSpec spec;
    spec.response = frame.factor("y");
    spec.fixed = fixed_design(frame, {{"x", false, {}}}, false);
    spec.random_intercepts = {frame.factor("g")};
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_TRUE(fit.groupings[0].at_boundary);
    EXPECT_EQ(fit.groupings[0].variance, 0.0);
    EXPECT_TRUE(has_note(fit, "boundary (singular) fit: the variance of 'g'"));
    EXPECT_EQ(fit.parameters, 6);  // R counts the variance
    // clm(y ~ x, data = dd) (R's clmm here: "Hessian is not positive definite")
    expect_rel(fit.log_likelihood, -54.821115406784642, 1e-12, "logLik");
    expect_estimates(fit,
                     {-1.544349209526757, 0.504451546479517, 1.483437065507630,
                      3.532237821513903, 1.987888611987147},
                     {0.564653007648768, 0.451276897355698, 0.503007043538897,
                      0.718329718846295, 0.639375730876304},
                     1e-9, 1e-9);
}

TEST(ClmmHardCases, SingleParticipantIsNotIdentifiable) {
    auto frame = wine();
    frame.set("one", std::vector<std::string>(frame.rows(), "P001"));
    const ClmmFit fit = fit_clmm(wine_spec(frame, {"temp", "contact"}, {"one"}));
    const ClmmFit clm = fit_clmm(wine_spec(frame, {"temp", "contact"}, {}));
    expect_all_finite(fit);
    EXPECT_FALSE(fit.groupings[0].identifiable);
    EXPECT_TRUE(has_note(fit, "grouping 'one' has a single level"));
    EXPECT_EQ(fit.parameters, 6);
    EXPECT_EQ(fit.log_likelihood, clm.log_likelihood);
}

TEST(ClmmHardCases, OneStimulusPerLevelIsConfounded) {
    // The grouping "temp" as a random effect beside the fixed temp: one group per level.
    const ClmmFit fit =
        fit_clmm(wine_spec(wine(), {"temp", "contact"}, {"judge", "temp"}));
    expect_all_finite(fit);
    EXPECT_FALSE(fit.groupings[1].identifiable);
    EXPECT_TRUE(has_note(fit, "grouping 'temp' is confounded with the fixed effects"));
    expect_rel(fit.coefficients[0].estimate, kJudgeEstimates[4], 1e-4, "tempwarm");
}

TEST(ClmmHardCases, ZeroAndCollinearColumnsAreDropped) {
    const auto frame = wine();
    ClmmSpec spec = wine_spec(frame, {"temp", "contact"}, {});
    const auto n = spec.fixed.x.rows();
    Eigen::MatrixXd x(n, 5);
    x << spec.fixed.x.col(0), Eigen::VectorXd::Zero(n), spec.fixed.x.col(1),
        2 * spec.fixed.x.col(0), Eigen::VectorXd::Ones(n);
    spec.fixed.x = x;
    spec.fixed.names = {"tempwarm", "zero", "contactyes", "twice", "one"};
    spec.fixed.term_of_column = spec.fixed.names;
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_EQ(fit.dropped_columns, (std::vector<std::string>{"zero", "twice", "one"}));
    EXPECT_TRUE(has_note(fit, "'zero' is all zero"));
    EXPECT_TRUE(has_note(fit, "'twice' is collinear"));
    EXPECT_TRUE(has_note(fit, "'one' is constant"));
    ASSERT_EQ(fit.coefficients.size(), 2u);
    expect_rel(fit.log_likelihood, -86.4919233656491, 1e-13, "logLik");
    expect_rel(fit.coefficients[1].estimate, 1.52779765809506, 1e-9, "contactyes");
}

TEST(ClmmHardCases, OneCategoryOnly) {
    DataFrame frame;
    frame.set("y", {"3", "3", "3", "3"});
    frame.set("x", {"0", "1", "0", "1"});
    ClmmSpec spec;
    spec.response = frame.factor("y", {"1", "2", "3"});
    spec.fixed = fixed_design(frame, {{"x", false, {}}}, false);
    const ClmmFit fit = fit_clmm(spec);
    expect_all_finite(fit);
    EXPECT_FALSE(fit.converged);
    EXPECT_TRUE(has_note(fit, "only one rating category was used"));
}

}  // namespace
}  // namespace lucent::analysis::mixed
