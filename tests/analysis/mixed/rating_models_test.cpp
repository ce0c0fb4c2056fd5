// The report's mixed models of one (question, factor) pair, from the long rating table,
// against R (ordinal 2022.11-16, lme4 1.1-31 + lmerTest 3.1-3): the wine tasting as a
// rating study (judges are participants, bottles are stimuli, temperature the factor),
// and the hard cases issue 29 names, each said in words and never NaN.
#include "analysis/mixed/rating_models.h"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/mixed/model_frame.h"
#include "tests/support/test_paths.h"

namespace lucent::analysis {
namespace {

// wine as a long table; `recode` may change each row's (judge, bottle, temp, rating).
template <typename Recode>
LongTable wine_table(Recode recode) {
    const auto frame = mixed::DataFrame::read_csv(test::source_dir() /
                                                  "tests/analysis/mixed/data/wine.csv");
    LongTable table;
    const auto ratings = frame.numeric("rating");
    for (std::size_t i = 0; i < frame.rows(); ++i) {
        std::string judge = "J" + frame.text("judge")[i],
                    bottle = "b" + frame.text("bottle")[i], temp = frame.text("temp")[i];
        double rating = ratings[i];
        if (!recode(judge, bottle, temp, rating)) continue;
        RatingRow row;
        row.participant = judge;
        row.stimulus = bottle;
        row.factor = "temp";
        row.level = temp;
        row.question = "bitterness";
        row.rating = rating;
        table.rows.push_back(row);
    }
    return table;
}

LongTable wine_table() {
    return wine_table([](auto&...) { return true; });
}

ModelChoice both() {
    ModelChoice choice;
    choice.mixed = {"clmm", "lmm"};
    return choice;
}

PairModels fit(const LongTable& table,
               std::vector<std::string> levels = {"cold", "warm"}) {
    return fit_pair_models(table, "bitterness", "temp", levels, both());
}

void expect_close(const Statistic& actual, double expected, double relative = 1e-6) {
    ASSERT_TRUE(actual.has_value()) << "expected " << expected;
    EXPECT_NEAR(*actual, expected, relative * std::max(1.0, std::abs(expected)));
}

bool has_note(const RatingModelFit& fit, const std::string& words) {
    for (const auto& note : fit.notes)
        if (note.find(words) != std::string::npos) return true;
    return false;
}

void expect_all_finite(const RatingModelFit& fit) {
    for (const auto* s : {&fit.statistic, &fit.df, &fit.den_df, &fit.p,
                          &fit.lr_chi_square, &fit.lr_df, &fit.lr_p, &fit.log_likelihood})
        if (*s) EXPECT_TRUE(std::isfinite(**s));
    for (const auto& e : fit.effects) {
        EXPECT_TRUE(std::isfinite(e.estimate) && std::isfinite(e.standard_error));
        if (e.low) EXPECT_TRUE(std::isfinite(*e.low) && std::isfinite(*e.high));
    }
    for (const auto& row : fit.predicted)
        for (double v : row) EXPECT_TRUE(std::isfinite(v) && v >= 0.0 && v <= 1.0);
}

// m <- clmm(rating ~ temp + (1|judge) + (1|bottle), wine); anova(update(m, ~ . - temp),
// m) lmer(as.numeric(rating) ~ temp + (1|judge) + (1|bottle), wine, control = tight);
// anova()
TEST(RatingModels, WineAsARatingStudyEqualsR) {
    const PairModels models = fit(wine_table());
    ASSERT_TRUE(models.of("clmm") && models.of("clmm")->fitted);
    const RatingModelFit& clmm = *models.of("clmm");
    EXPECT_EQ(clmm.formula, "rating ~ level + (1 | participant) + (1 | stimulus)");
    expect_close(clmm.log_likelihood, -87.3979638147415);
    expect_close(clmm.statistic, 9.42770228736111, 1e-5);
    EXPECT_EQ(clmm.df, 1.0);
    ASSERT_EQ(clmm.effects.size(), 1u);
    EXPECT_EQ(clmm.effects[0].level, "warm");
    EXPECT_NEAR(clmm.effects[0].estimate, 2.92807280966732, 1e-5);
    EXPECT_NEAR(clmm.effects[0].standard_error, 0.783680378152074, 1e-4);
    EXPECT_EQ(clmm.participants, 9);
    EXPECT_EQ(clmm.stimuli, 8);
    // The probabilities per level sum to 1; the observed proportions are the data's.
    ASSERT_EQ(clmm.categories, (std::vector<std::string>{"1", "2", "3", "4", "5"}));
    for (const auto& row : clmm.predicted) {
        double sum = 0.0;
        for (double v : row) sum += v;
        EXPECT_NEAR(sum, 1.0, 1e-12);
    }
    // table(wine$rating, wine$temp)[, "cold"] / 36: 5 16 13 2 0
    EXPECT_NEAR(clmm.observed[0][0], 5.0 / 36, 1e-15);
    EXPECT_NEAR(clmm.observed[0][1], 16.0 / 36, 1e-15);
    EXPECT_EQ(clmm.observed[0][4], 0.0);

    ASSERT_TRUE(models.of("lmm") && models.of("lmm")->fitted);
    const RatingModelFit& lmm = *models.of("lmm");
    expect_close(lmm.statistic, 15.9397583938132);
    expect_close(lmm.den_df, 5.99999970439998);
    expect_close(lmm.p, 0.00718039403222973);
    EXPECT_NEAR(lmm.effects[0].estimate, 7.0 / 6.0,
                1e-9);  // balanced: the mean difference
    expect_all_finite(clmm);
    expect_all_finite(lmm);
}

// Every judge rated four wines at each temperature: random slopes are identified.
// lmer(rating ~ temp + (temp|judge) + (1|bottle), wine, control = tight); anova(m);
// anova(update(m, ~ . - temp), m)
TEST(RatingModels, RandomSlopesWhereIdentifiedEqualR) {
    ModelChoice choice = both();
    choice.random_slopes = true;
    const PairModels models =
        fit_pair_models(wine_table(), "bitterness", "temp", {"cold", "warm"}, choice);
    ASSERT_TRUE(models.of("lmm") && models.of("lmm")->fitted);
    const RatingModelFit& lmm = *models.of("lmm");
    EXPECT_EQ(lmm.formula, "rating ~ level + (1 + level | participant) + (1 | stimulus)");
    expect_close(lmm.log_likelihood, -179.974252736021 / 2);
    expect_close(lmm.statistic, 14.4294475145931);
    expect_close(lmm.den_df, 6.28625777728131);
    expect_close(lmm.lr_chi_square, 9.57277480750213);
    ASSERT_EQ(lmm.random_sds.size(), 4u);
    EXPECT_EQ(lmm.random_sds[1].first, "participant levelwarm");
    EXPECT_NEAR(lmm.random_sds[1].second, std::sqrt(0.0804398157834378), 1e-6);
    // One judge: not identified, said, and intercepts only.
    const LongTable one =
        wine_table([](std::string& judge, std::string&, std::string&, double&) {
            return judge == "J1" || judge == "J2";
        });
    const PairModels few =
        fit_pair_models(one, "bitterness", "temp", {"cold", "warm"}, choice);
    ASSERT_TRUE(few.of("lmm"));
    EXPECT_TRUE(has_note(*few.of("lmm"),
                         "not identified (2 participants for a 2 x 2 covariance"));
    EXPECT_EQ(few.of("lmm")->formula,
              "rating ~ level + (1 | participant) + (1 | stimulus)");
}

// One bottle per temperature: stimulus and level confounded; clmm(rating ~ temp +
// (1|judge), wine) is what remains.
TEST(RatingModels, OneStimulusPerLevelDropsTheStimulusTermAndSaysSo) {
    const LongTable table =
        wine_table([](std::string&, std::string& bottle, std::string& temp, double&) {
            bottle = "bottle_" + temp;
            return true;
        });
    const PairModels models = fit(table);
    ASSERT_TRUE(models.of("clmm") && models.of("clmm")->fitted);
    EXPECT_EQ(models.of("clmm")->formula, "rating ~ level + (1 | participant)");
    EXPECT_TRUE(has_note(*models.of("clmm"), "stimulus and level are confounded"));
    expect_close(models.of("clmm")->log_likelihood, -88.7388151628385);
    expect_close(models.of("clmm")->statistic, 28.4983639483682, 1e-5);
    EXPECT_NEAR(models.of("clmm")->effects[0].estimate, 2.66752203377235, 1e-5);
    EXPECT_TRUE(has_note(*models.of("lmm"), "stimulus and level are confounded"));
}

// Judge 1 rates every wine 3: w4$rating[w4$judge == "1"] <- "3"; clmm as above.
TEST(RatingModels, AParticipantWhoGivesOneRatingToEverythingEqualsR) {
    const LongTable table =
        wine_table([](std::string& judge, std::string&, std::string&, double& rating) {
            if (judge == "J1") rating = 3;
            return true;
        });
    const PairModels models = fit(table);
    ASSERT_TRUE(models.of("clmm") && models.of("clmm")->fitted);
    expect_close(models.of("clmm")->log_likelihood, -85.2847251060079);
    expect_close(models.of("clmm")->statistic, 9.58349761998187, 1e-5);
    // R's clmm stops at a gradient of 1e-6, which leaves the estimate 5e-6 from the
    // optimum here.
    EXPECT_NEAR(models.of("clmm")->effects[0].estimate, 2.48273607198091, 2.5e-5);
    expect_all_finite(*models.of("clmm"));
}

// Ratings of 4 recoded to 5, so nobody used 4: R's factor() drops the level; Lucent
// drops the category, says so, and predicts it with probability 0.
TEST(RatingModels, ARatingCategoryNobodyUsedIsDroppedAndSaid) {
    const LongTable table =
        wine_table([](std::string&, std::string&, std::string&, double& rating) {
            if (rating == 4) rating = 5;
            return true;
        });
    const PairModels models = fit(table);
    ASSERT_TRUE(models.of("clmm") && models.of("clmm")->fitted);
    expect_close(models.of("clmm")->log_likelihood, -75.3413952327874);
    expect_close(models.of("clmm")->statistic, 9.17420362748371, 1e-5);
    EXPECT_NEAR(models.of("clmm")->effects[0].estimate, 2.94760415691191, 1e-5);
    ASSERT_EQ(models.of("clmm")->categories.size(), 5u);
    for (const auto& row : models.of("clmm")->predicted) EXPECT_EQ(row[3], 0.0);
    EXPECT_TRUE(has_note(*models.of("clmm"), "4"));
    expect_all_finite(*models.of("clmm"));
}

// Every participant gives the same ratings and every stimulus gets the same ones (a
// Latin square), so both variances are zero and the model is clm(rating ~ level):
// logLik -47.3326237369776, levelB 2.92044288292418 (R's clm; its clmm reports both
// variances as 0 and the same estimates). Without the level, the stimulus variance takes
// up the level's differences, so the likelihood ratio is anova(m0, m) of the mixed
// models: 14.5178016124659.
TEST(RatingModels, VariancesAtZeroAreABoundaryFitEqualToClm) {
    LongTable table;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (const char* level : {"A", "B"}) {
                RatingRow row;
                row.participant = "p" + std::to_string(i);
                row.stimulus = std::string(level == std::string("A") ? "a" : "b") +
                               std::to_string(j);
                row.factor = "temp";
                row.level = level;
                row.question = "bitterness";
                row.rating = (level == std::string("A") ? 1 : 3) + (i + j) % 4;
                table.rows.push_back(row);
            }
    const PairModels models = fit(table, {"A", "B"});
    ASSERT_TRUE(models.of("clmm") && models.of("clmm")->fitted);
    expect_close(models.of("clmm")->log_likelihood, -47.3326237369776, 1e-5);
    EXPECT_NEAR(models.of("clmm")->effects[0].estimate, 2.92044288292418, 1e-4);
    expect_close(models.of("clmm")->statistic, 14.5178016124659, 1e-5);
    EXPECT_TRUE(has_note(*models.of("clmm"), "singular"));
    EXPECT_TRUE(has_note(*models.of("lmm"), "singular"));
    expect_all_finite(*models.of("clmm"));
    expect_all_finite(*models.of("lmm"));
}

// Warm wines rated 4-5 and cold ones 1-3: the effect runs to infinity. It is reported as
// not estimable, with finite numbers everywhere.
TEST(RatingModels, CompleteSeparationIsReportedNotNaN) {
    const LongTable table =
        wine_table([](std::string&, std::string&, std::string& temp, double& rating) {
            if (temp == "warm") rating = rating >= 3 ? 5 : 4;
            if (temp == "cold") rating = std::min(rating, 3.0);
            return true;
        });
    const PairModels models = fit(table);
    ASSERT_TRUE(models.of("clmm"));
    ASSERT_EQ(models.of("clmm")->effects.size(), 1u);
    EXPECT_FALSE(models.of("clmm")->effects[0].estimable);
    EXPECT_TRUE(has_note(*models.of("clmm"), "separation"));
    expect_all_finite(*models.of("clmm"));
    expect_all_finite(*models.of("lmm"));
}

// Judge 3 alone: no participant variance to estimate.
TEST(RatingModels, ASingleParticipantDropsTheParticipantTerm) {
    const LongTable table = wine_table([](std::string& judge, std::string&, std::string&,
                                          double&) { return judge == "J3"; });
    const PairModels models = fit(table);
    ASSERT_TRUE(models.of("clmm") && models.of("lmm"));
    EXPECT_EQ(models.of("clmm")->formula, "rating ~ level + (1 | stimulus)");
    EXPECT_TRUE(has_note(*models.of("clmm"), "One participant"));
    EXPECT_EQ(models.of("clmm")->participants, 1);
    expect_all_finite(*models.of("clmm"));
    expect_all_finite(*models.of("lmm"));
}

// One participant rating one stimulus per level (scripts/run-default's first study): a
// parameter per level fits the three ratings exactly, so a likelihood-ratio test would
// report a "significant" 6.6 on 2 df from three numbers. Nothing is fitted, and why.
TEST(RatingModels, OneRatingPerLevelFitsNothingAndSaysWhy) {
    LongTable table;
    const double ratings[3] = {5, 4, 6};
    for (int level = 0; level < 3; ++level) {
        RatingRow row;
        row.participant = "p1";
        row.stimulus = "s" + std::to_string(level);
        row.factor = "temp";
        row.level = std::to_string(level + 1);
        row.question = "bitterness";
        row.rating = ratings[level];
        table.rows.push_back(row);
    }
    const PairModels models = fit(table, {"1", "2", "3"});
    ASSERT_TRUE(models.of("clmm") && models.of("lmm"));
    EXPECT_FALSE(models.of("clmm")->fitted);
    EXPECT_FALSE(models.of("clmm")->p.has_value());
    EXPECT_TRUE(has_note(*models.of("clmm"), "Needs at least 2 ratings in some level"));
    EXPECT_FALSE(models.of("lmm")->fitted);
}

TEST(RatingModels, OneLevelFitsNothingAndSaysWhy) {
    const PairModels models = fit(wine_table(), {"cold"});
    ASSERT_TRUE(models.of("clmm"));
    EXPECT_FALSE(models.of("clmm")->fitted);
    EXPECT_TRUE(has_note(*models.of("clmm"), "nothing to compare"));
}

TEST(RatingModels, ModelListsParseAndNameBadEntries) {
    const ModelChoice choice = parse_model_list("lmm,clmm", "anova");
    EXPECT_FALSE(choice.anova);
    // In registry order, whatever the list's.
    EXPECT_EQ(choice.mixed, (std::vector<std::string>{"clmm", "lmm"}));
    EXPECT_EQ(choice.primary, "lmm");  // anova does not run: the first listed
    EXPECT_EQ(parse_model_list("anova,clmm", "clmm").primary, "clmm");
    try {
        parse_model_list("anova,glmm", "anova");
        FAIL() << "accepted glmm";
    } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "--model: 'glmm' is not one of anova, clmm, lmm");
    }
    EXPECT_THROW(parse_model_list("", "anova"), InputError);
}

}  // namespace
}  // namespace lucent::analysis
