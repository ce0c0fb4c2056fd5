// The psychometric function against an independent fit of the same likelihood in R
// (nlminb, checked by optim; values from data/make_reference.R, see data/SOURCE.md), a
// probit GLM in the closed-form case, the hard cases in words, and a simulated observer.
#include "analysis/psychometric/psychometric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "analysis/data/long_table.h"
#include "analysis/report/format.h"

namespace lucent::analysis {
namespace {

std::vector<PsychometricBin> read_bins(const std::string& name) {
    std::ifstream in(std::string(LUCENT_SOURCE_DIR) +
                     "/tests/analysis/psychometric/data/" + name);
    std::vector<PsychometricBin> bins;
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "x,n_correct,n_trials");
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::istringstream fields(line);
        PsychometricBin b;
        char comma = 0;
        fields >> b.x >> comma >> b.n_correct >> comma >> b.n_trials;
        bins.push_back(b);
    }
    return bins;
}

void expect_rel(double actual, double expected, double tolerance = 1e-6) {
    EXPECT_NEAR(actual, expected, tolerance * std::max(std::abs(expected), 1e-3))
        << "expected " << expected;
}

struct Reference {
    double alpha, beta, lapse, log_likelihood, deviance;
    int df;
    double p_deviance, threshold, slope;
    std::optional<double> threshold_p, slope_p;
};

void expect_equal_to_r(const PsychometricFit& fit, const Reference& r) {
    ASSERT_TRUE(fit.fitted);
    EXPECT_TRUE(fit.converged);
    expect_rel(*fit.alpha, r.alpha);
    expect_rel(*fit.beta, r.beta);
    EXPECT_NEAR(*fit.lapse, r.lapse, 1e-7);
    expect_rel(*fit.log_likelihood, r.log_likelihood, 1e-9);
    expect_rel(*fit.deviance, r.deviance, 1e-7);
    EXPECT_EQ(fit.deviance_df, r.df);
    expect_rel(*fit.deviance_p, r.p_deviance);
    ASSERT_EQ(fit.threshold.status, ThresholdStatus::estimated) << fit.threshold.text;
    expect_rel(*fit.threshold.value, r.threshold);
    expect_rel(*fit.threshold.slope, r.slope);
    if (r.threshold_p) {
        ASSERT_TRUE(fit.threshold_p);
        ASSERT_EQ(fit.threshold_p->status, ThresholdStatus::estimated);
        expect_rel(*fit.threshold_p->value, *r.threshold_p);
        expect_rel(*fit.threshold_p->slope, *r.slope_p);
    }
}

PsychometricOptions options(PsychometricFamily family, double guess,
                            std::optional<double> fixed_lapse,
                            std::optional<double> p_level = std::nullopt) {
    PsychometricOptions o;
    o.family = family;
    o.guess = guess;
    o.free_lapse = !fixed_lapse;
    o.lapse = fixed_lapse.value_or(0.0);
    o.p_correct_level = p_level;
    return o;
}

constexpr auto kGauss = PsychometricFamily::cumulative_gaussian;
constexpr auto kWeibull = PsychometricFamily::weibull;

TEST(Psychometric, GaussianTwoAfcEqualsR) {
    const auto bins = read_bins("gauss_2afc.csv");
    ASSERT_EQ(bins.size(), 8u);
    // Lapse free: its maximum is on the lower bound 0 (R's nlminb agrees).
    const PsychometricFit free = fit_psychometric(bins, options(kGauss, 0.5, {}, 0.75));
    expect_equal_to_r(free, {0.461035404548, 0.171250190493, 0.0, -16.3579523796,
                             6.79047519705, 5, 0.236695096561, 0.461035404548,
                             1.16479368359, 0.461035404548, 1.16479368359});
    EXPECT_EQ(free.parameters, 3);
    const PsychometricFit fixed = fit_psychometric(bins, options(kGauss, 0.5, 0.0, 0.75));
    expect_equal_to_r(fixed, {0.461035402396, 0.171250192777, 0.0, -16.3579523796,
                              6.79047519705, 6, 0.34065944426, 0.461035402396,
                              1.16479366806, 0.461035402396, 1.16479366806});
    EXPECT_EQ(fixed.parameters, 2);
    EXPECT_TRUE(fixed.notes.empty()) << fixed.notes.front();
}

TEST(Psychometric, WeibullOnTwoAfcEqualsR) {
    expect_equal_to_r(
        fit_psychometric(read_bins("gauss_2afc.csv"), options(kWeibull, 0.5, {}, 0.75)),
        {0.516813705526, 2.9896563957, 0.0, -16.2153507272, 6.50527189216, 5,
         0.260108303009, 0.457185314916, 1.13316845156, 0.457185314916, 1.13316845156});
}

TEST(Psychometric, WeibullOddOneOutEqualsR) {
    const auto bins = read_bins("weibull_oddity.csv");
    // Lapse free, inside its bounds.
    expect_equal_to_r(
        fit_psychometric(bins, options(kWeibull, kGuessOddOneOutOfThree, {}, 2.0 / 3.0)),
        {2.04573404856, 2.54027033469, 0.0362235585652, -14.3889484495, 3.94547348915, 5,
         0.557292901012, 1.77087823871, 0.313424254978, 1.82891803271, 0.310460216166});
    expect_equal_to_r(
        fit_psychometric(bins,
                         options(kWeibull, kGuessOddOneOutOfThree, 0.01, 2.0 / 3.0)),
        {2.1446640907, 2.15493335079, 0.01, -15.0960953378, 5.35976726592, 6,
         0.498565059268, 1.80923133383, 0.271069202933, 1.82770965803, 0.270092500757});
    expect_equal_to_r(
        fit_psychometric(bins, options(kGauss, kGuessOddOneOutOfThree, 0.01, 2.0 / 3.0)),
        {1.86012635722, 0.955132194845, 0.01, -15.2592774046, 5.68613139946, 6,
         0.459251573495, 1.86012635722, 0.274278365736, 1.8783571192, 0.274228407778});
}

// gamma = 0, lambda = 0, cumulative Gaussian: the probit GLM, alpha = -b0/b1,
// beta = 1/b1, with R's glm at epsilon 1e-14.
TEST(Psychometric, YesNoEqualsProbitGlm) {
    const PsychometricFit fit = fit_psychometric(read_bins("probit_yesno.csv"),
                                                 options(kGauss, kGuessYesNo, 0.0));
    const double b0 = -0.197056271988, b1 = 1.27175019809;
    ASSERT_TRUE(fit.fitted);
    expect_rel(*fit.alpha, -b0 / b1);
    expect_rel(*fit.beta, 1.0 / b1);
    expect_rel(*fit.log_likelihood, -9.93982537758, 1e-9);
    expect_rel(*fit.deviance, 2.95082116743, 1e-7);
    EXPECT_EQ(fit.deviance_df, 7);
    expect_rel(*fit.threshold.value, -b0 / b1);
}

TEST(Psychometric, TrialsAreBinnedByIntensity) {
    std::vector<PsychometricTrial> trials{{0.3, true}, {0.1, false}, {0.3, false},
                                          {0.2, true}, {0.1, true},  {0.3, true}};
    const auto bins = bin_trials(trials);
    ASSERT_EQ(bins.size(), 3u);
    EXPECT_EQ(bins[0].x, 0.1);
    EXPECT_EQ(bins[0].n_correct, 1);
    EXPECT_EQ(bins[0].n_trials, 2);
    EXPECT_EQ(bins[2].n_correct, 2);
    EXPECT_EQ(bins[2].n_trials, 3);
}

TEST(Psychometric, BadInputIsRefusedInOneLine) {
    PsychometricOptions weibull = options(kWeibull, 0.5, {});
    try {
        fit_psychometric(std::vector<PsychometricTrial>{{0.5, true}, {-0.25, false}},
                         weibull);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("trial 2"), std::string::npos) << what;
        EXPECT_NE(what.find("-0.25"), std::string::npos) << what;
        EXPECT_NE(what.find("Weibull"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos);
    }
    EXPECT_THROW(fit_psychometric(std::vector<PsychometricBin>{{0.0, 1, 2}}, weibull),
                 InputError);
    EXPECT_THROW(fit_psychometric(std::vector<PsychometricBin>{{1.0, 3, 2}}), InputError);
    EXPECT_THROW(fit_psychometric(std::vector<PsychometricBin>{{NAN, 1, 2}}), InputError);
    EXPECT_THROW(
        fit_psychometric_participants({{"p1", 1.0, true}, {"p2", 0.0, true}}, weibull),
        InputError);
    PsychometricOptions bad;
    bad.guess = 1.0;
    EXPECT_THROW(fit_psychometric(std::vector<PsychometricBin>{}, bad), InputError);
    bad = {};
    bad.p_correct_level = 0.4;  // below the 2AFC guess rate
    EXPECT_THROW(fit_psychometric(std::vector<PsychometricBin>{}, bad), InputError);
}

// No value of a fit is NaN or infinite.
void expect_finite(const PsychometricFit& fit) {
    for (const auto& v :
         {fit.alpha, fit.beta, fit.lapse, fit.log_likelihood, fit.deviance,
          fit.deviance_p, fit.deviance_p_bootstrap, fit.constant_chi2, fit.constant_p}) {
        if (v) {
            EXPECT_TRUE(std::isfinite(*v));
        }
    }
    for (const Threshold* t :
         {&fit.threshold, fit.threshold_p ? &*fit.threshold_p : nullptr}) {
        if (t == nullptr) continue;
        for (const auto& v : {t->value, t->bound, t->slope, t->ci_low, t->ci_high,
                              t->slope_ci_low, t->slope_ci_high}) {
            if (v) {
                EXPECT_TRUE(std::isfinite(*v));
            }
        }
    }
    EXPECT_FALSE(fit.threshold.text.empty());
}

bool has_note(const PsychometricFit& fit, const std::string& text) {
    for (const std::string& n : fit.notes)
        if (n.find(text) != std::string::npos) return true;
    return false;
}

std::string all_notes(const PsychometricFit& fit) {
    std::string s;
    for (const std::string& n : fit.notes) s += n + " | ";
    return s;
}

const std::vector<double> kLevels{0.1, 0.2, 0.3, 0.4, 0.5, 0.6};

std::vector<PsychometricBin> bins_of(const std::vector<int>& correct, int n) {
    std::vector<PsychometricBin> bins;
    for (std::size_t i = 0; i < correct.size(); ++i)
        bins.push_back({kLevels[i], correct[i], n});
    return bins;
}

TEST(PsychometricHardCases, AtChanceHasNoThreshold) {
    PsychometricOptions o = options(kGauss, 0.5, {}, 0.75);
    o.bootstrap = 20;
    const PsychometricFit fit =
        fit_psychometric(bins_of({21, 19, 20, 22, 18, 21}, 40), o);
    expect_finite(fit);
    EXPECT_TRUE(fit.fitted);
    EXPECT_EQ(fit.threshold.status, ThresholdStatus::not_identified);
    EXPECT_FALSE(fit.threshold.value);
    EXPECT_EQ(fit.threshold.text, "not identified");
    EXPECT_EQ(fit.threshold_p->status, ThresholdStatus::not_identified);
    ASSERT_TRUE(fit.constant_p);
    EXPECT_GT(*fit.constant_p, 0.05);
    EXPECT_EQ(fit.constant_df, 2);
    EXPECT_TRUE(has_note(fit, "No threshold")) << all_notes(fit);
    EXPECT_TRUE(has_note(fit, "at chance")) << all_notes(fit);
    EXPECT_TRUE(has_note(fit, "likelihood-ratio test against a constant"))
        << all_notes(fit);
}

TEST(PsychometricHardCases, AboveChanceWithoutASignificantRiseKeepsTheFitsThreshold) {
    // An adaptive track's trials: most near the threshold, 80% correct, a weak rise.
    PsychometricOptions o = options(kGauss, 0.5, {}, 0.75);
    o.bootstrap = 20;
    const PsychometricFit fit = fit_psychometric(
        std::vector<PsychometricBin>{
            {1.0, 3, 5}, {2.0, 11, 15}, {3.0, 17, 20}, {4.0, 9, 10}, {5.0, 4, 5}},
        o);
    expect_finite(fit);
    ASSERT_TRUE(fit.constant_p);
    EXPECT_GT(*fit.constant_p, 0.05);  // the rise alone would not be significant
    ASSERT_EQ(fit.threshold.status, ThresholdStatus::estimated) << all_notes(fit);
    // psi at the threshold is halfway between the guess rate and the ceiling 1 - lapse.
    EXPECT_NEAR(psychometric_psi(fit, *fit.threshold.value),
                0.5 + (0.5 - fit.lapse.value_or(0.0)) / 2, 1e-9);
    EXPECT_TRUE(has_note(fit, "The rise with intensity is not significant"))
        << all_notes(fit);
    EXPECT_TRUE(has_note(fit, "above chance")) << all_notes(fit);
}

TEST(PsychometricHardCases, AlwaysCorrectIsBelowTheSmallestIntensity) {
    const PsychometricFit fit = fit_psychometric(bins_of({40, 40, 40, 40, 40, 40}, 40),
                                                 options(kGauss, 0.5, {}, 0.75));
    expect_finite(fit);
    EXPECT_EQ(fit.threshold.status, ThresholdStatus::below_range);
    EXPECT_FALSE(fit.threshold.value);
    EXPECT_EQ(*fit.threshold.bound, 0.1);
    EXPECT_EQ(fit.threshold.text, "< 0.1");
    EXPECT_EQ(fit.threshold_p->text, "< 0.1");
    EXPECT_TRUE(has_note(fit, "below the smallest intensity tested")) << all_notes(fit);
}

TEST(PsychometricHardCases, AlwaysWrongIsBelowChance) {
    const PsychometricFit fit =
        fit_psychometric(bins_of({0, 1, 0, 2, 0, 1}, 20), options(kGauss, 0.5, {}));
    expect_finite(fit);
    EXPECT_FALSE(fit.fitted);
    EXPECT_EQ(fit.threshold.status, ThresholdStatus::not_identified);
    EXPECT_TRUE(has_note(fit, "Below chance")) << all_notes(fit);
    // In yes/no (no guessing) never "yes" is a threshold above the range.
    const PsychometricFit yes_no =
        fit_psychometric(bins_of({0, 0, 0}, 10), options(kGauss, kGuessYesNo, 0.0));
    EXPECT_EQ(yes_no.threshold.text, "> 0.3");
}

TEST(PsychometricHardCases, SingleIntensityAndNoTrials) {
    const PsychometricFit one = fit_psychometric(
        std::vector<PsychometricBin>{{0.3, 14, 20}, {0.3, 15, 20}, {0.5, 0, 0}});
    expect_finite(one);
    EXPECT_FALSE(one.fitted);
    EXPECT_EQ(one.trials, 40);
    EXPECT_EQ(one.threshold.status, ThresholdStatus::not_identified);
    EXPECT_TRUE(has_note(one, "One intensity only")) << all_notes(one);

    const PsychometricFit none = fit_psychometric(std::vector<PsychometricTrial>{});
    expect_finite(none);
    EXPECT_EQ(none.trials, 0);
    EXPECT_TRUE(has_note(none, "No trials")) << all_notes(none);
    const PsychometricFit empty_bins =
        fit_psychometric(std::vector<PsychometricBin>{{0.1, 0, 0}, {0.2, 0, 0}});
    EXPECT_TRUE(has_note(empty_bins, "No trials"));
}

TEST(PsychometricHardCases, LapseAtItsUpperBound) {
    // Errors at the top intensities: 80% correct where the function has long saturated.
    PsychometricOptions o = options(kGauss, 0.5, {});
    o.bootstrap = 20;
    const PsychometricFit fit =
        fit_psychometric(std::vector<PsychometricBin>{{0.1, 20, 40},
                                                      {0.2, 22, 40},
                                                      {0.3, 32, 40},
                                                      {0.4, 32, 40},
                                                      {0.6, 32, 40},
                                                      {0.8, 32, 40}},
                         o);
    expect_finite(fit);
    ASSERT_TRUE(fit.fitted);
    EXPECT_DOUBLE_EQ(*fit.lapse, 0.06);
    EXPECT_TRUE(has_note(fit, "lapse rate is at its upper bound 0.06")) << all_notes(fit);
}

TEST(PsychometricHardCases, ThresholdAboveTheRangeAndStepResponses) {
    // Hardly above chance until the top level: the staircase hit the knob's range.
    const PsychometricFit high = fit_psychometric(bins_of({20, 21, 20, 22, 21, 30}, 40),
                                                  options(kGauss, 0.5, 0.0));
    expect_finite(high);
    EXPECT_EQ(high.threshold.status, ThresholdStatus::above_range) << all_notes(high);
    EXPECT_EQ(high.threshold.text, "> 0.6");
    // A jump from chance to perfect between two levels: the slope is not identified, and
    // the likelihood is as high for a step anywhere between 0.3 and 0.4, so the
    // threshold is only "between 0.3 and 0.4".
    const PsychometricFit step =
        fit_psychometric(bins_of({20, 20, 20, 40, 40, 40}, 40), options(kGauss, 0.5, {}));
    expect_finite(step);
    ASSERT_EQ(step.threshold.status, ThresholdStatus::between) << all_notes(step);
    EXPECT_EQ(*step.threshold.between_low, 0.3);
    EXPECT_EQ(*step.threshold.between_high, 0.4);
    EXPECT_EQ(step.threshold.text, "between 0.3 and 0.4");
    EXPECT_FALSE(step.threshold.value);
    EXPECT_FALSE(step.threshold.slope);
    EXPECT_TRUE(has_note(step, "slope is steeper")) << all_notes(step);
}

// Issue 44, item 3: a sharp observer on a coarse ladder got "JND 0.1475, 95% interval
// 0.1475 .. 0.1475": the slope runs off to infinity, every resample puts the step in
// the same gap, and the interval collapsed onto an arbitrary point of it.
TEST(PsychometricBootstrap, ASharpObserverOnACoarseLadderIsBetweenTwoIntensities) {
    // At chance (5 of 10) at 0.05 and 0.1, right on 27 of 28 from 0.15 up: the best
    // function is a step between 0.1 and 0.15 with psi = 1/2 below and 1 - 1/28 above
    // (a lapse rate of 0.036, within its bound 0.06); any step in that gap is as likely.
    const std::vector<PsychometricBin> ladder{
        {0.05, 3, 6}, {0.1, 2, 4}, {0.15, 10, 10}, {0.2, 11, 12}, {0.25, 6, 6}};
    for (const PsychometricFamily family : {kGauss, kWeibull}) {
        PsychometricOptions o = options(family, 0.5, {}, 0.75);
        o.bootstrap = 200;
        const PsychometricFit fit = fit_psychometric(ladder, o);
        expect_finite(fit);
        ASSERT_TRUE(fit.fitted);
        EXPECT_NEAR(*fit.lapse, 1.0 / 28.0, 1e-3);
        for (const Threshold* t : {&fit.threshold, &*fit.threshold_p}) {
            ASSERT_EQ(t->status, ThresholdStatus::between) << all_notes(fit);
            EXPECT_EQ(*t->between_low, 0.1);
            EXPECT_EQ(*t->between_high, 0.15);
            EXPECT_EQ(t->text, "between 0.1 and 0.15");
            EXPECT_FALSE(t->value);
            EXPECT_FALSE(t->slope);
            // No interval at all, not a collapsed one.
            EXPECT_FALSE(t->ci_low);
            EXPECT_FALSE(t->ci_high);
            EXPECT_EQ(t->ci_low_status, ThresholdStatus::not_identified);
            EXPECT_EQ(t->ci_text, "");
            EXPECT_FALSE(t->slope_ci_low || t->slope_ci_high);
        }
        EXPECT_TRUE(has_note(fit, "between two neighbouring intensities, 0.1 and 0.15"))
            << all_notes(fit);
        EXPECT_TRUE(has_note(fit, "no value and no interval")) << all_notes(fit);
    }
}

// Issue 44, item 3: an interval of "-11.72 .. 0.25" on deltas from 0.05: resamples
// where every answer is right put the threshold below every delta shown, where the
// search stops at its bound, and the percentile took that bound as a number.
TEST(PsychometricBootstrap, ResamplesBelowTheTestedRangeWithholdTheLowerEnd) {
    const std::vector<PsychometricBin> bins{{0.05, 2, 3}, {0.1, 4, 5}, {0.2, 6, 6}};
    PsychometricOptions o = options(kGauss, 0.5, {}, 0.75);
    o.bootstrap = 1000;
    o.seed = 3;
    const PsychometricFit fit = fit_psychometric(bins, o);
    expect_finite(fit);
    const Threshold& t = fit.threshold;
    ASSERT_EQ(t.status, ThresholdStatus::estimated) << all_notes(fit);
    EXPECT_GE(*t.value, 0.05);
    EXPECT_LE(*t.value, 0.2);
    // A resample with all 14 answers right has its threshold below 0.05 (the point
    // estimate's rule for every response correct); under the fitted psi that happens
    // with probability prod psi(x)^n, well above the 2.5% the interval leaves out below.
    double all_correct = 1.0;
    for (const PsychometricBin& b : bins)
        all_correct *= std::pow(psychometric_psi(fit, b.x), b.n_trials);
    ASSERT_GT(all_correct, 0.06);
    ASSERT_EQ(fit.bootstrap_samples, 1000);
    // At least those resamples (binomial, 1000 draws: more than 4.5 SDs below its mean
    // would be needed to fall under 0.6 of it).
    EXPECT_GE(t.bootstrap_below, 0.6 * 1000 * all_correct);
    EXPECT_GT(t.bootstrap_below, 0.025 * 999);
    // So the lower end is withheld, said in words, never a number below the range.
    EXPECT_EQ(t.ci_low_status, ThresholdStatus::below_range);
    EXPECT_FALSE(t.ci_low);
    ASSERT_EQ(t.ci_high_status, ThresholdStatus::estimated);
    ASSERT_TRUE(t.ci_high);
    EXPECT_GE(*t.ci_high, *t.value);
    EXPECT_LE(*t.ci_high, 0.2);
    EXPECT_EQ(t.ci_text.rfind("< 0.05 .. ", 0), 0u) << t.ci_text;
    EXPECT_TRUE(has_note(fit,
                         "put the threshold below the smallest intensity tested, "
                         "0.05"))
        << all_notes(fit);
    EXPECT_TRUE(has_note(fit, "lower end is only said to be below 0.05"))
        << all_notes(fit);
    // The same at 75% correct.
    ASSERT_EQ(fit.threshold_p->status, ThresholdStatus::estimated);
    EXPECT_FALSE(fit.threshold_p->ci_low);
    EXPECT_EQ(fit.threshold_p->ci_text.rfind("< 0.05 .. ", 0), 0u);
}

// The rule, on either side: an end is withheld exactly when more than (n - 1) x 2.5% of
// the n resamples lie beyond the range on its side (R's type-7 percentile reaches them).
TEST(PsychometricBootstrap, AnEndIsWithheldWhenMoreThanAlphaHalfOfResamplesAreBeyond) {
    PsychometricOptions o = options(kGauss, 0.5, {}, 0.75);
    o.bootstrap = 400;
    // Flat until 0.3, then up at 0.4, the top delta: many resamples rise past it.
    const PsychometricFit high = fit_psychometric(
        std::vector<PsychometricBin>{
            {0.1, 10, 20}, {0.2, 10, 20}, {0.3, 11, 20}, {0.4, 17, 20}},
        o);
    // A clean rise in the middle of the range: none beyond it.
    const PsychometricFit clean =
        fit_psychometric(bins_of({21, 24, 30, 36, 39, 40}, 40), o);
    for (const PsychometricFit* fit : {&high, &clean}) {
        expect_finite(*fit);
        for (const Threshold* t : {&fit->threshold, &*fit->threshold_p}) {
            ASSERT_EQ(t->status, ThresholdStatus::estimated) << all_notes(*fit);
            const double cut = 0.025 * (fit->bootstrap_samples - 1);
            EXPECT_EQ(t->ci_low_status == ThresholdStatus::below_range,
                      t->bootstrap_below > cut);
            EXPECT_EQ(t->ci_high_status == ThresholdStatus::above_range,
                      t->bootstrap_above > cut);
            EXPECT_EQ(t->ci_low.has_value(),
                      t->ci_low_status == ThresholdStatus::estimated);
            EXPECT_EQ(t->ci_high.has_value(),
                      t->ci_high_status == ThresholdStatus::estimated);
            const double x_min = fit->bins.front().x, x_max = fit->bins.back().x;
            if (t->ci_low) {
                EXPECT_GE(*t->ci_low, x_min);
            }
            if (t->ci_high) {
                EXPECT_LE(*t->ci_high, x_max);
            }
        }
    }
    const Threshold& h = high.threshold;
    EXPECT_GT(h.bootstrap_above, 0.025 * 399) << all_notes(high);
    EXPECT_EQ(h.ci_high_status, ThresholdStatus::above_range);
    ASSERT_TRUE(h.ci_low);
    EXPECT_EQ(h.ci_text, format_short(*h.ci_low) + " .. > 0.4");
    EXPECT_TRUE(has_note(high, "upper end is only said to be above 0.4"))
        << all_notes(high);
    const Threshold& c = clean.threshold;
    EXPECT_EQ(c.bootstrap_below + c.bootstrap_above, 0);
    ASSERT_TRUE(c.ci_low && c.ci_high);
    EXPECT_EQ(c.ci_text, format_short(*c.ci_low) + " .. " + format_short(*c.ci_high));
}

TEST(PsychometricHardCases, ProportionAboveTheCeilingHasNoThreshold) {
    // With a lapse rate of 0.05 the function never reaches 97% correct.
    const PsychometricFit fit =
        fit_psychometric(read_bins("gauss_2afc.csv"), options(kGauss, 0.5, 0.05, 0.97));
    expect_finite(fit);
    ASSERT_EQ(fit.threshold.status, ThresholdStatus::estimated);
    EXPECT_EQ(fit.threshold_p->status, ThresholdStatus::not_identified);
    EXPECT_TRUE(has_note(fit, "never reaches 97% correct")) << all_notes(fit);
    // psi at the threshold is halfway between the guess rate and the ceiling.
    EXPECT_NEAR(psychometric_psi(fit, *fit.threshold.value), 0.5 + 0.45 / 2, 1e-12);
}

// A simulated 2AFC observer (cumulative Gaussian, mean 0.4, sd 0.1, lapse 0.02) at seven
// levels, 60 trials each, per participant: the fits recover the threshold and slope.
TEST(PsychometricRecovery, SimulatedObserverIsRecovered) {
    const double mean = 0.4, sd = 0.1, lapse = 0.02;
    const double true_slope = (1.0 - 0.5 - lapse) / (sd * std::sqrt(2.0 * M_PI));
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<ParticipantTrial> trials;
    for (const std::string id : {"p1", "p2", "p3"})
        for (int rep = 0; rep < 60; ++rep)
            for (double x : {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7}) {
                const double psi = 0.5 + (1.0 - 0.5 - lapse) * 0.5 *
                                             std::erfc(-(x - mean) / (sd * M_SQRT2));
                trials.push_back({id, x, u(rng) < psi});
            }
    PsychometricOptions o = options(kGauss, 0.5, {}, 0.75);
    o.bootstrap = 200;
    o.seed = 7;
    const ParticipantFits fits = fit_psychometric_participants(trials, o);
    ASSERT_EQ(fits.participants.size(), 3u);
    EXPECT_EQ(fits.participants[0].first, "p1");
    EXPECT_EQ(fits.pooled.trials, 3 * 420);
    for (const auto& [id, fit] : fits.participants) {
        expect_finite(fit);
        const Threshold& t = fit.threshold;
        ASSERT_EQ(t.status, ThresholdStatus::estimated) << id << ": " << all_notes(fit);
        ASSERT_TRUE(t.ci_low && t.ci_high && t.slope_ci_low && t.slope_ci_high);
        EXPECT_EQ(fit.bootstrap_samples, 200);
        EXPECT_LE(*t.ci_low, mean) << id;
        EXPECT_GE(*t.ci_high, mean) << id;
        EXPECT_LE(*t.slope_ci_low, true_slope) << id;
        EXPECT_GE(*t.slope_ci_high, true_slope) << id;
        EXPECT_LE(*t.ci_low, *t.value);
        EXPECT_GE(*t.ci_high, *t.value);
    }
    // Pooled: 1260 trials, within 0.03 of the threshold and 25% of the slope.
    const Threshold& pooled = fits.pooled.threshold;
    ASSERT_EQ(pooled.status, ThresholdStatus::estimated);
    EXPECT_NEAR(*pooled.value, mean, 0.03);
    EXPECT_NEAR(*pooled.slope, true_slope, 0.25 * true_slope);
    EXPECT_NEAR(*fits.pooled.threshold_p->value, mean, 0.03);  // 75% = F 1/2 at lapse 0
    // Seeded: the same intervals again.
    const ParticipantFits again = fit_psychometric_participants(trials, o);
    EXPECT_EQ(*again.pooled.threshold.ci_low, *pooled.ci_low);
    EXPECT_EQ(*again.pooled.threshold.slope_ci_high, *pooled.slope_ci_high);
}

}  // namespace
}  // namespace lucent::analysis
