#pragma once
// Within-subject tests for one factor: every participant contributes one value per level
// (the mean of their ratings of that level's stimuli). In R's conventions:
//   - repeated-measures ANOVA: aov(y ~ level + Error(participant/level)), with Mauchly's
//     test (mauchly.test(mlm, X = ~1), including R's second-order term) and the
//     Greenhouse-Geisser and Huynh-Feldt corrections (anova.mlm(..., test = "Spherical");
//     the H-F p-value uses min(1, epsilon)), partial and generalized eta squared
//     (Olejnik & Algina 2003: SS_level / (SS_level + SS_participants + SS_error));
//   - Friedman's rank test, tie-corrected (friedman.test), with Kendall's W;
//   - paired t-tests of every pair of levels with Holm's correction
//     (pairwise.t.test(paired = TRUE, p.adjust.method = "holm")).
// Undefined results (too few participants, zero variance) are empty with a reason in
// `note`; nothing is ever NaN.
#include <string>
#include <vector>

#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

// Participants x levels, row-major: value(i, j) is participant i's value at level j.
// Only complete rows: a participant missing a level is left out by the builder.
struct SubjectByLevel {
    std::vector<std::string> participants;
    std::vector<std::string> levels;
    std::vector<double> values;

    std::size_t rows() const { return participants.size(); }
    std::size_t columns() const { return levels.size(); }
    double value(std::size_t participant, std::size_t level) const {
        return values[participant * levels.size() + level];
    }
};

struct RepeatedMeasuresAnova {
    int participants = 0, levels = 0;
    double df_effect = 0, df_error = 0;
    double ss_effect = 0, ss_participants = 0, ss_error = 0;
    Statistic f, p;                  // +inf F (zero error variance, different means): p 0
    Statistic mauchly_w, mauchly_p;  // need at least `levels` participants
    Statistic gg_epsilon, p_gg, hf_epsilon, p_hf;  // hf_epsilon as computed (may pass 1)
    Statistic partial_eta_sq, generalized_eta_sq;
    std::string note;  // why something is undefined; "" when all is defined
};

struct FriedmanResult {
    int participants = 0;
    Statistic chi_sq, df, p, kendall_w;
    std::string note;
};

struct PairedComparison {
    std::string level_a, level_b;
    Statistic diff;  // mean of (b - a) over participants
    Statistic t, df, p, p_holm;
    std::string note;
};

RepeatedMeasuresAnova repeated_measures_anova(const SubjectByLevel& data);
FriedmanResult friedman_test(const SubjectByLevel& data);
// Pairs (a, b) with a before b in level order; Holm over the pairs with a defined p.
std::vector<PairedComparison> paired_t_tests_holm(const SubjectByLevel& data);

// Holm's step-down adjustment (R's p.adjust(p, "holm")); undefined entries stay
// undefined and do not count in the number of tests.
std::vector<Statistic> holm_adjust(const std::vector<Statistic>& p);

}  // namespace lucent::analysis
