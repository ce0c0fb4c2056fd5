#pragma once
// Maximum Likelihood Difference Scaling (Maloney and Yang 2003) by the generalized linear
// model of Knoblauch and Maloney (2008), as MLDS::mlds(method = "glm") fits it: a probit
// GLM without intercept whose coefficients are the scale values psi_2..psi_p (psi_1 = 0)
// in units of the decision noise (sigma = 1); reported as well in MLDS's normalisation
// psi_1 = 0, psi_p = 1 with sigma estimated, and checked by a direct maximum-likelihood
// fit in that normalisation. The six-point test and the bootstrap intervals are MLDS's
// (simu.6pt, boot.mlds), seeded.
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/choice_table.h"

namespace lucent::analysis {

// One judgement in the series' order (indices into MldsData::stimuli): the pairs
// (q[0], q[1]) and (q[2], q[3]), each low to high, the first pair before the second
// (by low, then high end); a triad a<b<c is (a, b, b, c). second_larger: the second pair
// was judged to differ more (the GLM's response 1).
struct MldsTrial {
    std::array<std::size_t, 4> q{};
    bool second_larger = false;
};

struct MldsData {
    std::vector<std::string> stimuli;  // the series, low to high
    std::vector<MldsTrial> trials;
};

struct MldsOptions {
    int bootstrap = 0;  // parametric bootstrap samples for the intervals (0: none)
    std::uint64_t seed = 1;
    double level = 0.95;            // of the percentile intervals
    int six_point_simulations = 0;  // simulated data sets of the six-point test (0: none)
    bool direct = true;             // also fit by direct maximum likelihood
};

struct MldsDirectFit {
    std::vector<double> scale;  // psi_1 = 0, psi_p = 1
    double sigma = 0, log_likelihood = 0;
    bool converged = false;
};

// Maloney and Yang's six-point condition: (a,b) < (a',b') and (b,c) < (b',c') imply
// (a,c) < (a',c'). The test (MLDS's simu.6pt): the log-likelihood of the judgements of
// every six-point set found in the data, under the fitted scale, against its
// distribution over data simulated from the fitted scale and refitted; p = the share of
// simulated values at or below the observed one (small: the data violate the model's
// assumptions more than chance).
struct SixPointTest {
    int sets = 0;        // six-point sets whose three quadruples were all shown
    int violations = 0;  // sets whose majority judgements break the condition
    std::optional<double> log_likelihood, p;
    int simulations = 0;
};

struct MldsFit {
    std::vector<std::string> stimuli;
    int trials = 0;
    // The GLM's scale (sigma = 1), psi_1 = 0, and its standard errors.
    std::vector<std::optional<double>> glm_scale, glm_se;
    // Normalised psi_1 = 0, psi_p = 1 (MLDS's plots), SEs by the delta method;
    // sigma = 1 / psi_p of the GLM.
    std::vector<std::optional<double>> scale, se;
    std::optional<double> sigma, sigma_se;
    // Bootstrap percentile intervals of the normalised scale and sigma.
    std::vector<std::optional<double>> ci_low, ci_high;
    std::optional<double> sigma_ci_low, sigma_ci_high;
    int bootstrap_samples = 0;  // used (a sample whose psi_p is not positive is not)
    std::optional<double> deviance, null_deviance, aic, log_likelihood;
    // Proportion of deviance accounted for: (null deviance - deviance) / null
    // deviance, the null model every judgement at chance (psi all 0).
    std::optional<double> daf;
    int df_residual = 0;
    std::optional<MldsDirectFit> direct;
    SixPointTest six_point;
    bool converged = false;
    std::vector<std::string> notes;  // hard cases in words
};

MldsFit fit_mlds(const MldsData& data, const MldsOptions& options = {});

// The triad and quadruple rows (catch trials left out) in the series' order: the screen
// order may show the pairs swapped or a triad reversed; the response follows.
MldsData mlds_data(const std::vector<const ChoiceRow*>& rows,
                   const std::vector<std::string>& stimuli);

struct MldsBlockFits {
    std::string block, question;
    std::vector<std::string> stimuli;           // series order
    std::vector<std::optional<double>> values;  // physical value per stimulus
    MldsFit pooled;
    std::vector<std::pair<std::string, MldsFit>> participants;
    std::size_t catch_trials = 0, catch_failed = 0;
};

// Every triad or quadruple block (block, question), pooled and per participant; the
// series order from `orders` (block -> stimuli), else the value columns (see
// series_order in paired_comparison.h).
std::vector<MldsBlockFits> fit_mlds_blocks(
    const ChoiceTable& table, const MldsOptions& options = {},
    const std::map<std::string, std::vector<std::string>>& orders = {});

}  // namespace lucent::analysis
