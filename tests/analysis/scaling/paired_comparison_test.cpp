// Bradley-Terry and Thurstone Case V against R's BradleyTerry2::BTm (values from
// data/make_reference.R, see data/SOURCE.md), and the hard cases the issue names.
#include "analysis/scaling/paired_comparison.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "analysis/data/long_table.h"
#include "scaling_test_data.h"

namespace lucent::analysis {
namespace {

using testing::read_small_csv;

void expect_rel(double actual, double expected, double tolerance = 1e-6) {
    EXPECT_NEAR(actual, expected, tolerance * std::abs(expected))
        << "expected " << expected;
}

// citations.csv: row = cited journal, column = citing journal; a citation of i by j is
// a win of i over j (countsToBinomial), one row per unordered pair.
PairedData citations() {
    const auto csv = read_small_csv("citations.csv");
    PairedData data;
    for (std::size_t c = 1; c < csv[0].size(); ++c) data.stimuli.push_back(csv[0][c]);
    const std::size_t n = data.stimuli.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            data.counts.push_back(
                {i, j, std::stod(csv[i + 1][j + 1]), std::stod(csv[j + 1][i + 1])});
    return data;
}

// baseball.csv: home team shown first; teams in BTm's (alphabetical) factor order.
PairedData baseball() {
    const auto csv = read_small_csv("baseball.csv");
    PairedData data;
    data.stimuli = {"Baltimore", "Boston",   "Cleveland", "Detroit",
                    "Milwaukee", "New York", "Toronto"};
    auto index = [&](const std::string& team) {
        return static_cast<std::size_t>(
            std::find(data.stimuli.begin(), data.stimuli.end(), team) -
            data.stimuli.begin());
    };
    for (std::size_t r = 1; r < csv.size(); ++r)
        data.counts.push_back({index(csv[r][0]), index(csv[r][1]), std::stod(csv[r][2]),
                               std::stod(csv[r][3])});
    return data;
}

void expect_abilities(const PairedFit& fit, const std::vector<double>& coef,
                      const std::vector<double>& se) {
    ASSERT_EQ(fit.abilities.size(), coef.size() + 1);
    EXPECT_TRUE(fit.abilities[0].reference);
    EXPECT_EQ(*fit.abilities[0].ability, 0.0);
    for (std::size_t i = 0; i < coef.size(); ++i) {
        ASSERT_TRUE(fit.abilities[i + 1].ability && fit.abilities[i + 1].se);
        expect_rel(*fit.abilities[i + 1].ability, coef[i]);
        expect_rel(*fit.abilities[i + 1].se, se[i]);
    }
}

TEST(PairedComparison, CitationsBradleyTerryEqualsBTm) {
    const PairedFit fit = fit_paired_comparison(citations());
    EXPECT_EQ(fit.model, "Bradley-Terry (logit)");
    // The values: Comm Statist -2.9490725 (0.10254534), JASA -0.4795698
    // (0.06058873), JRSS-B 0.2689541 (0.07082997).
    expect_abilities(fit, {-2.94907249684, -0.479569769752, 0.268954055819},
                     {0.102545335511, 0.0605887292482, 0.0708299651111});
    expect_rel(*fit.deviance, 4.29338396989);
    EXPECT_EQ(fit.df_residual, 3);
    expect_rel(*fit.aic, 46.3938806545);
    expect_rel(*fit.null_deviance, 1925.23285021);
    EXPECT_TRUE(fit.converged);
    EXPECT_EQ(fit.groups, 1);
}

TEST(PairedComparison, CitationsThurstoneEqualsBTmProbit) {
    const PairedFit fit = fit_paired_comparison(citations(), {BinomialLink::probit});
    EXPECT_EQ(fit.model, "Thurstone Case V (probit)");
    expect_abilities(fit, {-1.67469367729, -0.289913263757, 0.159117067426},
                     {0.0506666261683, 0.0363652511274, 0.0431543115094});
    expect_rel(*fit.deviance, 6.41197463551);
    expect_rel(*fit.aic, 48.5124713201);
}

TEST(PairedComparison, ReferenceByName) {
    PairedOptions options;
    options.reference = "JASA";
    const PairedFit fit = fit_paired_comparison(citations(), options);
    EXPECT_TRUE(fit.abilities[2].reference);
    expect_rel(*fit.abilities[0].ability, 0.479569769752);
    expect_rel(*fit.abilities[1].ability, -2.94907249684 + 0.479569769752);
    expect_rel(*fit.deviance, 4.29338396989);
    options.reference = "Nature";
    EXPECT_THROW(fit_paired_comparison(citations(), options), InputError);
}

TEST(PairedComparison, BaseballEqualsBTm) {
    PairedOptions options;
    options.screen_order_rows = true;  // BTm's 42 rows: each pair at both teams' homes
    const PairedFit fit = fit_paired_comparison(baseball(), options);
    expect_abilities(fit,
                     {1.10769770538, 0.683852769159, 1.43640843181, 1.58135587666,
                      1.24761784514, 1.29448512391},
                     {0.333878206989, 0.331876672711, 0.339568506378, 0.343255981594,
                      0.335860922525, 0.336669401422});
    expect_rel(*fit.deviance, 44.0534612286);  // the issue: 44.053 on 36 df, AIC 140.52
    EXPECT_EQ(fit.df_residual, 36);
    expect_rel(*fit.aic, 140.518600991);
    expect_rel(*fit.null_deviance, 78.0154698249);
    ASSERT_TRUE(fit.fit_p);
    EXPECT_GT(*fit.fit_p, 0.05);  // chi-square(36) at 44.05: p = 0.17
}

TEST(PairedComparison, BaseballHomeAdvantageEqualsBTm) {
    PairedOptions options;
    options.order_effect = true;
    const PairedFit fit = fit_paired_comparison(baseball(), options);
    expect_abilities(fit,
                     {1.14380265331, 0.704694456907, 1.47535721359, 1.61955499359,
                      1.28134040328, 1.32711039808},
                     {0.337842535245, 0.335001717499, 0.344552212895, 0.347365683422,
                      0.3404037212, 0.340322567525});
    // The issue: home advantage 0.3023 (SE 0.1309), deviance 38.643.
    expect_rel(*fit.order_effect, 0.302260655529);
    expect_rel(*fit.order_effect_se, 0.130943707456);
    expect_rel(*fit.deviance, 38.642852144);
    EXPECT_EQ(fit.df_residual, 35);
    expect_rel(*fit.aic, 137.107991906);
}

TEST(PairedComparison, BaseballThurstoneEqualsBTmProbit) {
    PairedOptions options{BinomialLink::probit, "", false, true};
    const PairedFit fit = fit_paired_comparison(baseball(), options);
    expect_abilities(fit,
                     {0.681263279494, 0.415464981318, 0.876906358611, 0.970430458289,
                      0.763584663054, 0.797270081621},
                     {0.199156723527, 0.198425570954, 0.201444181411, 0.203073561874,
                      0.199938377172, 0.20033353738});
    expect_rel(*fit.deviance, 43.9949475817);
    expect_rel(*fit.aic, 140.460087344);
    options.order_effect = true;
    const PairedFit home = fit_paired_comparison(baseball(), options);
    expect_abilities(home,
                     {0.698087164947, 0.422424887495, 0.893011106017, 0.990235148069,
                      0.780157560914, 0.812692326719},
                     {0.200797289472, 0.199796092031, 0.203428625494, 0.204756217239,
                      0.201806105909, 0.201837599899});
    expect_rel(*home.order_effect, 0.184085678202);
    expect_rel(*home.order_effect_se, 0.0795615238433);
    expect_rel(*home.deviance, 38.6033086348);
    expect_rel(*home.aic, 137.068448397);
}

// ---- Hard cases ----------------------------------------------------------------------

void expect_all_finite(const PairedFit& fit) {
    for (const auto& a : fit.abilities) {
        EXPECT_TRUE(!a.ability || std::isfinite(*a.ability));
        EXPECT_TRUE(!a.se || std::isfinite(*a.se));
    }
    for (const auto* v : {&fit.deviance, &fit.null_deviance, &fit.aic, &fit.fit_p,
                          &fit.lr_chi2, &fit.lr_p, &fit.order_effect})
        EXPECT_TRUE(!*v || std::isfinite(**v));
}

std::string joined(const std::vector<std::string>& notes) {
    std::string all;
    for (const auto& n : notes) all += n + "\n";
    return all;
}

TEST(PairedComparison, StimulusThatAlwaysWinsIsReportedUnbounded) {
    PairedData data{{"a", "b", "c", "d"}, {}};
    data.counts = {{0, 1, 5, 0}, {0, 2, 5, 0}, {0, 3, 5, 0},  // a wins all 15
                   {1, 2, 3, 2}, {1, 3, 4, 1}, {2, 3, 3, 2}};
    const PairedFit fit = fit_paired_comparison(data);
    expect_all_finite(fit);
    EXPECT_FALSE(fit.abilities[0].ability);
    EXPECT_EQ(fit.abilities[0].unbounded, 1);
    EXPECT_TRUE(fit.abilities[1].reference);  // a cannot be the reference: b is
    EXPECT_TRUE(fit.abilities[2].ability && fit.abilities[3].ability);
    EXPECT_TRUE(fit.converged);
    EXPECT_NE(joined(fit.notes).find("a won every comparison (15 of 15): its ability is "
                                     "unbounded (reported as > "),
              std::string::npos)
        << joined(fit.notes);
    // b, c and d alone are close to equal, but a's 15 wins are no chance: the report
    // does not call the choices chance.
    EXPECT_EQ(joined(fit.notes).find("consistent with chance"), std::string::npos)
        << joined(fit.notes);
    // Losing every comparison: unbounded below.
    for (auto& c : data.counts)
        if (c.first == 0) std::swap(c.first_wins, c.second_wins);
    const PairedFit lost = fit_paired_comparison(data);
    EXPECT_EQ(lost.abilities[0].unbounded, -1);
    EXPECT_NE(joined(lost.notes).find("a lost every comparison"), std::string::npos);
}

TEST(PairedComparison, PerfectOrderHasNoFiniteScale) {
    PairedData data{{"a", "b", "c"}, {{0, 1, 3, 0}, {1, 2, 3, 0}, {0, 2, 3, 0}}};
    const PairedFit fit = fit_paired_comparison(data);
    expect_all_finite(fit);
    for (const auto& a : fit.abilities) EXPECT_FALSE(a.ability);
    EXPECT_NE(joined(fit.notes).find("no finite scale exists"), std::string::npos)
        << joined(fit.notes);
}

TEST(PairedComparison, GraphInPartsIsScaledWithinEachGroup) {
    PairedData data{{"a", "b", "c", "d", "e"},
                    {{0, 1, 3, 2}, {2, 3, 1, 4}, {3, 4, 2, 2}, {2, 4, 3, 3}}};
    const PairedFit fit = fit_paired_comparison(data);
    expect_all_finite(fit);
    EXPECT_EQ(fit.groups, 2);
    EXPECT_NE(joined(fit.notes).find("The comparisons fall into 2 unconnected groups: "
                                     "{c, d, e} and {a, b}; there is no common scale"),
              std::string::npos)
        << joined(fit.notes);
    EXPECT_TRUE(fit.abilities[0].reference);
    EXPECT_TRUE(fit.abilities[2].reference);
    EXPECT_EQ(fit.abilities[0].group, 1u);
    EXPECT_EQ(fit.abilities[2].group, 0u);
    // Each group's abilities are those of the group alone.
    const PairedFit ab = fit_paired_comparison({{"a", "b"}, {{0, 1, 3, 2}}});
    EXPECT_NEAR(*fit.abilities[1].ability, *ab.abilities[1].ability, 1e-9);
    EXPECT_NEAR(*ab.abilities[1].ability, std::log(2.0 / 3.0), 1e-9);
}

TEST(PairedComparison, AlwaysPressingLeftIsAPositionBias) {
    // Each pair shown 4 times, twice in each order; the first shown always chosen.
    PairedData data{{"a", "b", "c"}, {}};
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = i + 1; j < 3; ++j) {
            data.counts.push_back({i, j, 2, 0});
            data.counts.push_back({j, i, 2, 0});
        }
    const PairedFit fit = fit_paired_comparison(data);
    expect_all_finite(fit);
    EXPECT_EQ(*fit.position.share, 1.0);
    EXPECT_NEAR(*fit.position.p, 2.0 * std::pow(0.5, 12), 1e-15);  // binom.test(12, 12)
    EXPECT_NE(joined(fit.notes).find("The first-shown stimulus was chosen in 12 of 12 "
                                     "comparisons (100%"),
              std::string::npos)
        << joined(fit.notes);
    // The abilities are equal; the order effect takes the bias.
    for (const auto& a : fit.abilities) EXPECT_NEAR(*a.ability, 0.0, 1e-9);
}

TEST(PairedComparison, ChanceChoicesDoNotDifferFromZero) {
    PairedData data{{"a", "b", "c", "d"}, {}};
    for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t j = i + 1; j < 4; ++j) data.counts.push_back({i, j, 5, 5});
    const PairedFit fit = fit_paired_comparison(data);
    expect_all_finite(fit);
    for (const auto& a : fit.abilities) EXPECT_NEAR(*a.ability, 0.0, 1e-12);
    EXPECT_NEAR(*fit.lr_chi2, 0.0, 1e-9);
    EXPECT_NEAR(*fit.lr_p, 1.0, 1e-9);
    EXPECT_NE(joined(fit.notes).find("The abilities do not differ from 0"),
              std::string::npos);
}

TEST(PairedComparison, BlocksFromChoicesPooledAndPerParticipant) {
    std::istringstream csv(
        "participant,session,trial,block,task,question,practice,catch,expected,"
        "shown_1,shown_2,shown_3,shown_4,value_1,value_2,value_3,value_4,choice,rt_ms\n"
        "P1,s,1,pc,pair,q,0,0,,hi,lo,,,2,1,,,1,500\n"
        "P1,s,2,pc,pair,q,0,0,,lo,hi,,,1,2,,,1,500\n"
        "P1,s,3,pc,pair,q,0,0,,lo,hi,,,1,2,,,2,500\n"
        "P1,s,4,pc,pair,q,1,0,,lo,hi,,,1,2,,,2,500\n"
        "P1,s,5,pc,pair,q,0,1,2,lo,hi,,,1,2,,,1,500\n"
        "P2,s2,1,pc,pair,q,0,0,,lo,hi,,,1,2,,,2,500\n"
        "P2,s2,2,pc,pair,q,0,0,,hi,lo,,,2,1,,,2,500\n");
    const ChoiceTable table = read_choice_csv(csv, "t.csv");
    const auto blocks = fit_paired_blocks(table);
    ASSERT_EQ(blocks.size(), 1u);
    EXPECT_EQ(blocks[0].stimuli, (std::vector<std::string>{"lo", "hi"}));  // by value
    EXPECT_EQ(*blocks[0].values[1], 2.0);
    EXPECT_EQ(blocks[0].catch_trials, 1u);
    EXPECT_EQ(blocks[0].catch_failed, 1u);
    ASSERT_EQ(blocks[0].participants.size(), 2u);
    // Pooled: hi won 3 of 5 against lo: log(3/2).
    EXPECT_NEAR(*blocks[0].pooled.abilities[1].ability, std::log(1.5), 1e-9);
    EXPECT_NEAR(*blocks[0].participants[0].second.abilities[1].ability, std::log(2.0),
                1e-9);
    // P2 chose the right-hand one twice, hi once and lo once.
    EXPECT_NEAR(*blocks[0].participants[1].second.abilities[1].ability, 0.0, 1e-9);
}

}  // namespace
}  // namespace lucent::analysis
