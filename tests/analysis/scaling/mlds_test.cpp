// MLDS against R's glm(resp ~ . - 1, binomial("probit")) on the same design (values from
// data/make_reference.R, see data/SOURCE.md): the data are read from the choices CSV in
// screen order (pairs swapped, triads reversed at random), so the conversion to the
// series' order is checked too. Then the direct fit, the six-point test, the bootstrap
// and the hard cases.
#include "analysis/scaling/mlds.h"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/scaling/paired_comparison.h"
#include "scaling_test_data.h"

namespace lucent::analysis {
namespace {

void expect_rel(double actual, double expected, double tolerance = 1e-6) {
    EXPECT_NEAR(actual, expected, tolerance * std::abs(expected))
        << "expected " << expected;
}

MldsData read_data(const std::string& name) {
    static std::vector<ChoiceTable> keep;  // rows outlive the pointers
    keep.push_back(read_choice_csv(testing::scaling_data_path(name)));
    std::vector<const ChoiceRow*> rows;
    for (const ChoiceRow& r : keep.back().rows) rows.push_back(&r);
    return mlds_data(rows, series_order(rows));
}

struct Reference {
    std::vector<double> coef, se, normalised;
    double deviance, null_deviance, aic, log_likelihood, sigma, daf;
    int df;
};

void expect_equal_to_r(const MldsFit& fit, const Reference& r) {
    ASSERT_EQ(fit.glm_scale.size(), r.coef.size() + 1);
    EXPECT_EQ(*fit.glm_scale[0], 0.0);
    for (std::size_t j = 0; j < r.coef.size(); ++j) {
        expect_rel(*fit.glm_scale[j + 1], r.coef[j]);
        expect_rel(*fit.glm_se[j + 1], r.se[j]);
    }
    for (std::size_t j = 1; j < r.normalised.size(); ++j)
        expect_rel(*fit.scale[j], r.normalised[j]);
    expect_rel(*fit.deviance, r.deviance);
    expect_rel(*fit.null_deviance, r.null_deviance);
    expect_rel(*fit.aic, r.aic);
    expect_rel(*fit.log_likelihood, r.log_likelihood);
    expect_rel(*fit.sigma, r.sigma);
    expect_rel(*fit.daf, r.daf);
    EXPECT_EQ(fit.df_residual, r.df);
    EXPECT_TRUE(fit.converged);
    // The direct maximum likelihood (psi_p = 1, sigma free) reaches the same maximum.
    ASSERT_TRUE(fit.direct);
    EXPECT_TRUE(fit.direct->converged);
    expect_rel(fit.direct->log_likelihood, r.log_likelihood, 1e-9);
    expect_rel(fit.direct->sigma, r.sigma, 1e-5);
    for (std::size_t j = 1; j + 1 < r.normalised.size(); ++j)
        EXPECT_NEAR(fit.direct->scale[j], r.normalised[j], 1e-5);
}

TEST(Mlds, QuadruplesEqualRGlm) {
    const MldsData data = read_data("mlds_quadruple.csv");
    ASSERT_EQ(data.trials.size(), 210u);
    EXPECT_EQ(data.stimuli.front(), "s1");
    EXPECT_EQ(data.stimuli.back(), "s8");
    expect_equal_to_r(fit_mlds(data),
                      {{0.603248245903, 1.17058313107, 1.9453888246, 2.91255121302,
                        4.21700048333, 5.86973157668, 7.80626161998},
                       {0.262847079745, 0.327835964623, 0.418784353409, 0.535082733348,
                        0.706837343445, 0.925243679237, 1.20017029903},
                       {0, 0.0772774825224, 0.149954381246, 0.249208765899,
                        0.373104483914, 0.540207424325, 0.751926064284, 1},
                       135.29663614,
                       291.121815835,
                       149.29663614,
                       -67.6483180702,
                       0.128102291299,
                       0.53525765236,
                       203});
}

TEST(Mlds, TriadsEqualRGlm) {
    const MldsData data = read_data("mlds_triad.csv");
    ASSERT_EQ(data.trials.size(), 168u);
    expect_equal_to_r(fit_mlds(data),
                      {{0.0947762343646, 0.554015929717, 1.33784929506, 1.82131497054,
                        2.90931664611, 4.33623706359, 5.84026200703},
                       {0.27089185401, 0.299629254073, 0.361826629314, 0.434280640458,
                        0.563451305711, 0.759769420412, 1.02778546447},
                       {0, 0.0162280791941, 0.0948614855035, 0.229073506197,
                        0.311855010673, 0.498148309547, 0.742473036033, 1},
                       109.228119539,
                       232.897452668,
                       123.228119539,
                       -54.6140597695,
                       0.171225194828,
                       0.531003373856,
                       161});
}

TEST(Mlds, SixPointTestAndBootstrapAreSeeded) {
    const MldsData data = read_data("mlds_quadruple.csv");
    MldsOptions options;
    options.bootstrap = 200;
    options.six_point_simulations = 100;
    options.seed = 7;
    options.direct = false;
    const MldsFit a = fit_mlds(data, options), b = fit_mlds(data, options);
    // Six-point sets (a1<a2<a3, b1<b2<b3, a1<b1) whose three quadruples were shown in
    // that order of pairs (Get6pts's rule): some, and the same both times.
    EXPECT_GT(a.six_point.sets, 0);
    EXPECT_EQ(a.six_point.sets, b.six_point.sets);
    ASSERT_TRUE(a.six_point.p && a.six_point.log_likelihood);
    EXPECT_EQ(*a.six_point.p, *b.six_point.p);
    EXPECT_GE(*a.six_point.p, 0.05);  // simulated from the model: no violation expected
    EXPECT_EQ(a.six_point.simulations, 100);
    EXPECT_EQ(a.bootstrap_samples, 200);
    for (std::size_t j = 1; j + 1 < a.stimuli.size(); ++j) {
        ASSERT_TRUE(a.ci_low[j] && a.ci_high[j]);
        EXPECT_EQ(*a.ci_low[j], *b.ci_low[j]);
        EXPECT_LT(*a.ci_low[j], *a.scale[j]);
        EXPECT_GT(*a.ci_high[j], *a.scale[j]);
    }
    EXPECT_LT(*a.sigma_ci_low, *a.sigma);
    EXPECT_GT(*a.sigma_ci_high, *a.sigma);
    options.seed = 8;
    EXPECT_NE(*fit_mlds(data, options).ci_low[3], *a.ci_low[3]);
}

// Quadruples of a 5-stimulus series, each judged by `judge(a, b, c, d)` (true: second
// pair more different).
template <class Judge>
MldsData quadruples(int repeats, Judge judge) {
    MldsData data{{"a", "b", "c", "d", "e"}, {}};
    for (int r = 0; r < repeats; ++r)
        for (std::size_t a = 0; a < 5; ++a)
            for (std::size_t b = a + 1; b < 5; ++b)
                for (std::size_t c = b + 1; c < 5; ++c)
                    for (std::size_t d = c + 1; d < 5; ++d)
                        data.trials.push_back({{a, b, c, d}, judge(a, b, c, d, r)});
    return data;
}

void expect_no_nan(const MldsFit& fit) {
    for (const auto* v : {&fit.glm_scale, &fit.glm_se, &fit.scale, &fit.se})
        for (const auto& x : *v) EXPECT_TRUE(!x || std::isfinite(*x));
    for (const auto* x : {&fit.sigma, &fit.deviance, &fit.aic, &fit.daf})
        EXPECT_TRUE(!*x || std::isfinite(**x));
}

TEST(Mlds, NoiselessObserverIsReportedInWords) {
    // psi = x^2 judged without noise: every judgement agrees with the scale.
    const MldsData data = quadruples(2, [](auto a, auto b, auto c, auto d, int) {
        auto psi = [](std::size_t i) { return double(i * i); };
        return psi(d) - psi(c) > psi(b) - psi(a);
    });
    const MldsFit fit = fit_mlds(data);
    expect_no_nan(fit);
    EXPECT_FALSE(fit.sigma);
    ASSERT_FALSE(fit.notes.empty());
    EXPECT_NE(fit.notes[0].find("sigma is 0"), std::string::npos) << fit.notes[0];
}

TEST(Mlds, ChanceObserverIsReportedInWords) {
    // Alternating answers: every quadruple judged both ways equally often.
    const MldsData data =
        quadruples(4, [](auto, auto, auto, auto, int r) { return r % 2 == 0; });
    MldsOptions options;
    options.bootstrap = 50;
    const MldsFit fit = fit_mlds(data, options);
    expect_no_nan(fit);
    EXPECT_NEAR(*fit.daf, 0.0, 1e-9);
    std::string all;
    for (const auto& n : fit.notes) all += n + "\n";
    EXPECT_NE(all.find("no growth along the series"), std::string::npos) << all;
}

TEST(Mlds, CounterbalancedScreenOrderIsUndone) {
    ChoiceRow row;
    row.task = ChoiceTask::quadruple;
    row.shown = {"d", "c", "b", "a"};  // pair (c,d) shown first, each pair reversed
    row.choice = 1;                    // the first shown (c,d) differs more
    ChoiceRow triad;
    triad.task = ChoiceTask::triad;
    triad.shown = {"c", "b", "a", ""};  // reversed triad
    triad.choice = 2;                   // (b,a) differs more
    const MldsData data = mlds_data({&row, &triad}, {"a", "b", "c", "d"});
    ASSERT_EQ(data.trials.size(), 2u);
    EXPECT_EQ(data.trials[0].q, (std::array<std::size_t, 4>{0, 1, 2, 3}));
    EXPECT_TRUE(data.trials[0].second_larger);
    EXPECT_EQ(data.trials[1].q, (std::array<std::size_t, 4>{0, 1, 1, 2}));
    EXPECT_FALSE(data.trials[1].second_larger);
}

}  // namespace
}  // namespace lucent::analysis
