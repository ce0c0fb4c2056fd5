// Within-subject tests against R 4.2.2 (Debian's r-base-core): the values below were
// printed by R with options(digits = 15) for the data sets written out here:
//   aov(y ~ level + Error(id/level)), mauchly.test(lm(Y ~ 1), X = ~1),
//   anova(lm(Y ~ 1), X = ~1, test = "Spherical"), stats:::sphericity (the epsilons),
//   friedman.test(Y), pairwise.t.test(y, level, paired = TRUE, p.adjust.method = "holm"),
//   p.adjust(p, "holm").
// `reacttime` is the data set of R's ?SSD example (Baron & Li, after Maxwell & Delaney).
#include "analysis/stats/repeated_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace lucent::analysis {
namespace {

SubjectByLevel matrix(std::size_t columns, std::vector<double> values) {
    SubjectByLevel m;
    for (std::size_t j = 0; j < columns; ++j)
        m.levels.push_back("L" + std::to_string(j + 1));
    for (std::size_t i = 0; i < values.size() / columns; ++i)
        m.participants.push_back("P" + std::to_string(i + 1));
    m.values = std::move(values);
    return m;
}

const SubjectByLevel& reacttime() {
    static const SubjectByLevel m = matrix(
        6, {420, 420, 480, 480, 600, 780, 420, 480, 480, 360, 480, 600, 480, 480, 540,
            660, 780, 780, 420, 540, 540, 480, 780, 900, 540, 660, 540, 480, 660, 720,
            360, 420, 360, 360, 480, 540, 480, 480, 600, 540, 720, 840, 480, 600, 660,
            540, 720, 900, 540, 600, 540, 480, 720, 780, 480, 420, 540, 540, 660, 780});
    return m;
}

// 7 participants x 4 levels of Likert ratings, with ties within participants.
const SubjectByLevel& likert() {
    static const SubjectByLevel m = matrix(4, {3, 4, 4, 6, 2, 2, 5, 5, 4, 4, 4, 4, 1, 3,
                                               2, 6, 5, 6, 6, 7, 3, 3, 5, 4, 2, 4, 4, 5});
    return m;
}

void expect_relative(const Statistic& value, double expected, double tolerance,
                     const char* what) {
    ASSERT_TRUE(value) << what << " is undefined";
    EXPECT_NEAR(*value, expected, tolerance * std::fabs(expected)) << what;
}

TEST(RepeatedMeasuresAnova, MatchesRAovAndAnovaMlmOnReacttime) {
    const RepeatedMeasuresAnova r = repeated_measures_anova(reacttime());
    EXPECT_EQ(r.participants, 10);
    EXPECT_EQ(r.df_effect, 5);
    EXPECT_EQ(r.df_error, 45);
    EXPECT_NEAR(r.ss_effect, 680700, 1e-7);
    EXPECT_NEAR(r.ss_participants, 292140, 1e-7);
    EXPECT_NEAR(r.ss_error, 161100, 1e-7);
    // F = (680700 / 5) / (161100 / 45) exactly; R's anova.mlm (38.0279329622523) gets it
    // through the SSD matrix and is off by 4e-11 relative, as are its epsilons (~2e-12).
    expect_relative(r.f, (680700.0 / 5) / (161100.0 / 45), 1e-14, "F");
    expect_relative(r.f, 38.0279329622523, 1e-10, "F (R's anova.mlm)");
    expect_relative(r.p, 4.47106426528521e-15, 1e-9, "p");
    expect_relative(r.mauchly_w, 0.03108445938269, 1e-10, "Mauchly W");
    expect_relative(r.mauchly_p, 0.0476518670321, 1e-9, "Mauchly p");
    expect_relative(r.gg_epsilon, 0.485491764776298, 1e-10, "G-G epsilon");
    expect_relative(r.hf_epsilon, 0.677807491560499, 1e-10, "H-F epsilon");
    expect_relative(r.p_gg, 2.53199188582932e-08, 1e-9, "G-G p");
    expect_relative(r.p_hf, 7.39301356449841e-11, 1e-9, "H-F p");
    // Effect sizes from R's printed sums of squares (closed forms).
    expect_relative(r.partial_eta_sq, 680700.0 / (680700 + 161100), 1e-13,
                    "partial eta^2");
    expect_relative(r.generalized_eta_sq, 680700.0 / (680700 + 292140 + 161100), 1e-13,
                    "generalized eta^2");
    EXPECT_TRUE(r.note.empty()) << r.note;
}

TEST(RepeatedMeasuresAnova, MatchesROnTiedLikertRatingsWithHuynhFeldtBelowOne) {
    const RepeatedMeasuresAnova r = repeated_measures_anova(likert());
    expect_relative(r.f, (21.8214285714285714 / 3) / (15.4285714285714286 / 18), 1e-13,
                    "F");
    expect_relative(r.f, 8.48611111111112, 1e-12, "F (R)");
    expect_relative(r.p, 0.00100080725247128, 1e-9, "p");
    EXPECT_NEAR(r.ss_effect, 21.8214285714, 1e-9);
    EXPECT_NEAR(r.ss_error, 15.4285714286, 1e-9);
    expect_relative(r.mauchly_w, 0.2557334533608, 1e-10, "Mauchly W");
    expect_relative(r.mauchly_p, 0.274851618824, 1e-9, "Mauchly p");
    expect_relative(r.gg_epsilon, 0.650929181315922, 1e-10, "G-G epsilon");
    expect_relative(r.hf_epsilon, 0.961115247786879, 1e-10, "H-F epsilon");
    expect_relative(r.p_gg, 0.00545569075741597, 1e-9, "G-G p");
    expect_relative(r.p_hf, 0.00120645875886723, 1e-9, "H-F p");
}

TEST(RepeatedMeasuresAnova, HuynhFeldtAboveOneIsReportedButItsPUsesOne) {
    // Compound symmetry up to noise: a participant offset plus small, equal-variance
    // errors, so the H-F estimate passes 1 and its p equals the uncorrected p.
    const SubjectByLevel m = matrix(3, {1,   2, 3.1, 2, 3.1, 4, 3.2, 4, 5, 4, 5,   6.2, 5,
                                        6.1, 7, 6.1, 7, 8,   7, 8.2, 9, 8, 9, 10.1});
    const RepeatedMeasuresAnova r = repeated_measures_anova(m);
    ASSERT_TRUE(r.hf_epsilon && r.p_hf && r.p);
    ASSERT_GT(*r.hf_epsilon, 1.0);
    EXPECT_DOUBLE_EQ(*r.p_hf, *r.p);
}

TEST(RepeatedMeasuresAnova, IsInvariantToTheOrderOfLevels) {
    // Sphericity statistics depend on the contrast space, not on the Helmert basis used.
    SubjectByLevel permuted = reacttime();
    const std::vector<std::size_t> order{3, 0, 5, 1, 4, 2};
    for (std::size_t i = 0; i < permuted.rows(); ++i)
        for (std::size_t j = 0; j < 6; ++j)
            permuted.values[i * 6 + j] = reacttime().value(i, order[j]);
    const RepeatedMeasuresAnova a = repeated_measures_anova(reacttime());
    const RepeatedMeasuresAnova b = repeated_measures_anova(permuted);
    EXPECT_NEAR(*a.f, *b.f, 1e-11 * *a.f);
    EXPECT_NEAR(*a.mauchly_w, *b.mauchly_w, 1e-11);
    EXPECT_NEAR(*a.gg_epsilon, *b.gg_epsilon, 1e-12);
}

bool finite_or_empty(const Statistic& s) { return !s || !std::isnan(*s); }

void expect_no_nan(const RepeatedMeasuresAnova& r) {
    for (const Statistic* s :
         {&r.f, &r.p, &r.mauchly_w, &r.mauchly_p, &r.gg_epsilon, &r.p_gg, &r.hf_epsilon,
          &r.p_hf, &r.partial_eta_sq, &r.generalized_eta_sq})
        EXPECT_TRUE(finite_or_empty(*s));
    EXPECT_TRUE(std::isfinite(r.ss_effect) && std::isfinite(r.ss_error));
}

TEST(RepeatedMeasuresAnova, DegenerateCasesAreUndefinedWithAReasonNeverNaN) {
    // Two participants, three levels: F is defined, Mauchly's test needs 3 participants.
    const RepeatedMeasuresAnova two =
        repeated_measures_anova(matrix(3, {1, 2, 4, 2, 4, 5}));
    expect_no_nan(two);
    EXPECT_TRUE(two.f.has_value());
    EXPECT_FALSE(two.mauchly_w.has_value());
    EXPECT_NE(two.note.find("Mauchly"), std::string::npos) << two.note;

    // Every participant shifts the levels alike: zero residual, F infinite, p 0.
    const RepeatedMeasuresAnova additive =
        repeated_measures_anova(matrix(3, {1, 2, 4, 2, 3, 5, 4, 5, 7}));
    expect_no_nan(additive);
    ASSERT_TRUE(additive.f && additive.p);
    EXPECT_TRUE(std::isinf(*additive.f));
    EXPECT_EQ(*additive.p, 0.0);
    EXPECT_FALSE(additive.gg_epsilon.has_value());
    EXPECT_FALSE(additive.note.empty());

    // Constant data: nothing to test.
    const RepeatedMeasuresAnova constant =
        repeated_measures_anova(matrix(3, std::vector<double>(9, 4)));
    expect_no_nan(constant);
    EXPECT_FALSE(constant.f.has_value());
    EXPECT_FALSE(constant.note.empty());

    // One level, one participant.
    EXPECT_FALSE(repeated_measures_anova(matrix(1, {1, 2, 3})).f.has_value());
    EXPECT_FALSE(repeated_measures_anova(matrix(3, {1, 2, 3})).f.has_value());

    // Two levels: sphericity holds by construction, both corrections are 1.
    const RepeatedMeasuresAnova pair =
        repeated_measures_anova(matrix(2, {1, 2, 2, 4, 3, 3, 1, 5}));
    expect_no_nan(pair);
    EXPECT_EQ(*pair.mauchly_w, 1.0);
    EXPECT_FALSE(pair.mauchly_p.has_value());
    EXPECT_NEAR(*pair.gg_epsilon, 1.0, 1e-15);
    EXPECT_NEAR(*pair.p_gg, *pair.p, 1e-15);
}

TEST(RepeatedMeasuresAnova, TwoLevelsEqualThePairedTSquared) {
    // With two levels the RM F is the square of the paired t (an independent path).
    const SubjectByLevel m = matrix(2, {1, 2, 2, 4, 3, 3, 1, 5, 2, 2.5});
    const RepeatedMeasuresAnova r = repeated_measures_anova(m);
    const std::vector<PairedComparison> t = paired_t_tests_holm(m);
    ASSERT_EQ(t.size(), 1u);
    EXPECT_NEAR(*r.f, *t[0].t * *t[0].t, 1e-12 * *r.f);
    EXPECT_NEAR(*r.p, *t[0].p, 1e-12);
}

TEST(Friedman, MatchesRFriedmanTestOnReacttime) {
    const FriedmanResult f = friedman_test(reacttime());
    expect_relative(f.chi_sq, 39.00602409639, 1e-11, "chi squared");
    EXPECT_EQ(*f.df, 5);
    expect_relative(f.p, 2.36821542356e-07, 1e-9, "p");
    expect_relative(f.kendall_w, 39.00602409639 / (10 * 5), 1e-11, "Kendall's W");
}

TEST(Friedman, TieCorrectionMatchesR) {
    const FriedmanResult f = friedman_test(likert());
    expect_relative(f.chi_sq, 14.05555555556, 1e-11, "chi squared");
    expect_relative(f.p, 0.00283049919081, 1e-9, "p");
}

TEST(Friedman, AllTiedIsUndefined) {
    const FriedmanResult f = friedman_test(matrix(3, {2, 2, 2, 5, 5, 5}));
    EXPECT_FALSE(f.chi_sq.has_value());
    EXPECT_FALSE(f.note.empty());
    // Perfect agreement: W = 1.
    const FriedmanResult agree = friedman_test(matrix(3, {1, 2, 3, 2, 3, 4, 1, 5, 7}));
    EXPECT_NEAR(*agree.kendall_w, 1.0, 1e-15);
}

TEST(PairedT, MatchesRPairwiseTTestHolmOnReacttime) {
    // R's lower-triangular p-value matrix, [row b][column a], levels 1..6.
    const double holm[6][6] = {
        {},
        {0.183937489398930454},
        {0.040468660435347178, 0.992203111049041242},
        {0.732999431602437745, 0.992203111049041242, 5.61811883513177e-01},
        {0.000708973832545030, 0.011321546436239002, 2.76319796670867e-03,
         1.52182184641622e-04},
        {0.000114670471970932, 0.000907871300488304, 2.06387027134522e-05,
         5.33152156487638e-05, 0.00276319796670867}};
    const double raw_2_1 = 3.67874978797861e-02;
    const std::vector<PairedComparison> pairs = paired_t_tests_holm(reacttime());
    ASSERT_EQ(pairs.size(), 15u);
    for (const PairedComparison& c : pairs) {
        const int a = c.level_a[1] - '1', b = c.level_b[1] - '1';
        expect_relative(c.p_holm, holm[b][a], 1e-9,
                        (c.level_a + " vs " + c.level_b).c_str());
    }
    // Levels 1 and 2: R's t.test(paired = TRUE): t = 2.449489742783, mean difference 48.
    expect_relative(pairs[0].t, 2.449489742783, 1e-11, "t");
    expect_relative(pairs[0].p, raw_2_1, 1e-10, "p");
    EXPECT_DOUBLE_EQ(*pairs[0].diff, 48.0);
    EXPECT_EQ(*pairs[0].df, 9);
}

TEST(PairedT, MatchesROnTiedLikertRatings) {
    const std::vector<PairedComparison> pairs = paired_t_tests_holm(likert());
    ASSERT_EQ(pairs.size(), 6u);  // (1,2) (1,3) (1,4) (2,3) (2,4) (3,4)
    const double expected[] = {0.135768796043418, 0.044184355345268, 0.044184355345268,
                               0.320808096502349, 0.044184355345268, 0.312639232313033};
    for (std::size_t i = 0; i < pairs.size(); ++i)
        expect_relative(pairs[i].p_holm, expected[i], 1e-9, "Holm p");
}

TEST(PairedT, ZeroVarianceOfDifferencesIsUndefinedAndLeftOutOfHolm) {
    // Levels 1 and 2 differ by exactly 1 for everyone; 1 vs 3 and 2 vs 3 vary.
    const std::vector<PairedComparison> pairs =
        paired_t_tests_holm(matrix(3, {1, 2, 5, 2, 3, 3, 4, 5, 9}));
    EXPECT_FALSE(pairs[0].t.has_value());
    EXPECT_FALSE(pairs[0].p_holm.has_value());
    EXPECT_NE(pairs[0].note.find("zero variance"), std::string::npos);
    // Holm over the two defined p-values only: the smaller is doubled.
    const double p1 = *pairs[1].p, p2 = *pairs[2].p;
    EXPECT_DOUBLE_EQ(*pairs[1].p_holm,
                     std::min(1.0, p1 <= p2 ? 2 * p1 : std::max(2 * p2, p1)));
}

TEST(Holm, MatchesRPAdjustWithMissingValues) {
    // p.adjust(c(0.01, 0.04, 0.03, NA, 0.2), "holm") = 0.04 0.09 0.09 NA 0.20
    const std::vector<Statistic> adjusted =
        holm_adjust({0.01, 0.04, 0.03, std::nullopt, 0.2});
    EXPECT_DOUBLE_EQ(*adjusted[0], 0.04);
    EXPECT_DOUBLE_EQ(*adjusted[1], 0.09);
    EXPECT_DOUBLE_EQ(*adjusted[2], 0.09);
    EXPECT_FALSE(adjusted[3].has_value());
    EXPECT_DOUBLE_EQ(*adjusted[4], 0.2);
}

}  // namespace
}  // namespace lucent::analysis
