// The built-in `scaling` study end to end without a display: simulated observers with a
// known perceptual scale answer every planned trial through the store, as the autopilot
// does; the analysis reads the database back and its MLDS and Thurstone scales recover
// the observers' scale (issue 30, section 3). The truth is the observer model's closed
// form psi(v) = ((v - 1) / 63)^0.5, never a fitted value.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "analysis/data/choice_table.h"
#include "analysis/scaling/mlds.h"
#include "analysis/scaling/paired_comparison.h"
#include "study/export.h"
#include "study/observations.h"
#include "study/simulated_observer.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// Runs `participants` simulated observers through the scaling study into `db`.
void run_observers(const std::string& db, const ObserverModel& observer,
                   int participants) {
    const Protocol p = builtin_protocol("scaling");
    Store store(db);
    const int64_t study = store.ensure_study(p);
    std::mt19937_64 rng(2024);
    for (int n = 1; n <= participants; ++n) {
        int number = 0;
        const int64_t pid =
            store.ensure_participant(study, "S" + std::to_string(n), &number);
        const uint64_t seed = 100 + n;
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p, seed, number), seed, {});
        for (const TrialRow& t : store.trials(s.id)) {
            ASSERT_NE(t.task, Task::rating);  // the study rates nothing
            TrialOutcome o;
            Response r;
            r.question = p.find_block(t.block)->question_id;
            r.rating =
                simulated_choice(observer, choice_stimuli(p, t.block, t.shown), rng);
            r.rt_ms = 800;
            o.responses.push_back(r);
            store.record_trial(s.id, t.id, o);
        }
    }
}

TEST(ScalingRecovery, MldsAndThurstoneRecoverTheObserversScale) {
    const auto dir = lucent::test::scratch_dir("scaling_recovery");
    const std::string db = (dir / "scaling.db").string();
    const ObserverModel observer = ObserverModel::parse("0.5,0.2");
    run_observers(db, observer, 10);

    std::stringstream csv;
    const ChoiceExport exported = export_choices(db, csv, {.analysis = true});
    // 10 sessions x (126 quadruples + 1 catch + 36 pairs + 2 identical + 1 obvious).
    ASSERT_EQ(exported.rows, 10 * 166);
    EXPECT_TRUE(exported.excluded_participants.empty());  // obvious catches are obvious
    const analysis::ChoiceTable table = analysis::read_choice_csv(csv, db);
    const std::map<std::string, std::vector<std::string>> orders =
        read_observations(db).choice_orders;

    const std::vector<double> r = {1, 4, 7, 10, 14, 19, 25, 36, 64};
    auto psi = [&](double v) { return observer.scale(v, 1, 64); };

    // The six-point test on data that obey the model: no evidence against it.
    analysis::MldsOptions six_point;
    six_point.six_point_simulations = 100;
    six_point.seed = 9;
    const std::vector<analysis::MldsBlockFits> mlds =
        analysis::fit_mlds_blocks(table, six_point, orders);
    ASSERT_EQ(mlds.size(), 1u);
    const analysis::MldsFit& fit = mlds[0].pooled;
    ASSERT_EQ(fit.scale.size(), r.size());
    // 1260 quadruples: each scale value within 4 standard errors and 0.08 of the truth.
    for (size_t i = 0; i < r.size(); ++i) {
        ASSERT_TRUE(fit.scale[i].has_value()) << "r = " << r[i];
        EXPECT_NEAR(*fit.scale[i], psi(r[i]), 0.08) << "r = " << r[i];
        if (i > 0 && i + 1 < r.size()) {  // the ends are fixed at 0 and 1
            ASSERT_TRUE(fit.se[i].has_value());
            EXPECT_LT(std::abs(*fit.scale[i] - psi(r[i])), 4 * *fit.se[i])
                << "r = " << r[i];
        }
    }
    EXPECT_GT(fit.six_point.sets, 0);
    ASSERT_TRUE(fit.six_point.p.has_value());
    EXPECT_GT(*fit.six_point.p, 0.01);
    ASSERT_TRUE(fit.sigma.has_value());
    EXPECT_NEAR(*fit.sigma, observer.sigma, 0.04);

    // Pairs ("which looks more translucent?", a lower r looks more translucent: the
    // block's obvious catch says so): Thurstone Case V abilities are -psi / (sigma
    // sqrt 2) from r_1's.
    analysis::PairedOptions probit;
    probit.link = analysis::BinomialLink::probit;
    const std::vector<analysis::PairedBlockFits> pairs =
        analysis::fit_paired_blocks(table, probit, orders);
    ASSERT_EQ(pairs.size(), 1u);
    const analysis::PairedFit& thurstone = pairs[0].pooled;
    ASSERT_EQ(thurstone.abilities.size(), r.size());
    const double unit = observer.sigma * std::sqrt(2.0);
    for (size_t i = 0; i < r.size(); ++i) {
        const analysis::StimulusAbility& a = thurstone.abilities[i];
        ASSERT_TRUE(a.ability.has_value()) << a.stimulus;
        // Within 4 standard errors (r_1 is the reference, 0 by definition).
        const double truth = -(psi(r[i]) - psi(r[0]));
        if (i == 0) {
            EXPECT_EQ(*a.ability, 0.0);
            continue;
        }
        ASSERT_TRUE(a.se.has_value()) << a.stimulus;
        EXPECT_LT(std::abs(*a.ability * unit - truth), 4 * *a.se * unit) << a.stimulus;
        EXPECT_NEAR(*a.ability * unit, truth, 0.12) << a.stimulus;
    }
}

}  // namespace
}  // namespace lucent::study
