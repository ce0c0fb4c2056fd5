#include "analysis/simulate/crossed_power.h"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/non_central_f.hpp>
#include <cmath>
#include <string>

#include "analysis/mixed/clmm.h"
#include "analysis/mixed/lmm.h"
#include "analysis/simulate/normal_source.h"
#include "analysis/stats/repeated_measures.h"

namespace lucent::analysis {
namespace {

// One simulated study in model form: responses, level of each, participant and stimulus
// codes.
struct SimulatedStudy {
    std::vector<double> y;
    mixed::FactorColumn level, participant, stimulus;
};

SimulatedStudy layout(const CrossedPowerSpec& spec) {
    SimulatedStudy study;
    const int k = int(spec.level_means.size()), m = spec.stimuli_per_level,
              n = spec.participants;
    study.level = {"level", {}, {}};
    study.participant = {"participant", {}, {}};
    study.stimulus = {"stimulus", {}, {}};
    for (int j = 0; j < k; ++j) study.level.levels.push_back(std::to_string(j + 1));
    for (int i = 0; i < n; ++i)
        study.participant.levels.push_back("p" + std::to_string(i));
    for (int s = 0; s < k * m; ++s)
        study.stimulus.levels.push_back("s" + std::to_string(s));
    for (int i = 0; i < n; ++i)
        for (int s = 0; s < k * m; ++s) {
            study.level.codes.push_back(s / m);
            study.participant.codes.push_back(i);
            study.stimulus.codes.push_back(s);
        }
    study.y.resize(study.level.codes.size());
    return study;
}

void draw(const CrossedPowerSpec& spec, NormalSource& normal, SimulatedStudy& study) {
    const int k = int(spec.level_means.size()), m = spec.stimuli_per_level,
              n = spec.participants;
    std::vector<double> participant(static_cast<std::size_t>(n));
    std::vector<double> stimulus(static_cast<std::size_t>(k * m));
    for (double& p : participant) p = spec.participant_sd * normal.next();
    for (double& s : stimulus) s = spec.stimulus_sd * normal.next();
    const bool rounded = spec.likert || spec.model == RatingModel::clmm;
    for (std::size_t r = 0; r < study.y.size(); ++r) {
        const double latent = spec.level_means[std::size_t(study.level.codes[r])] +
                              participant[std::size_t(study.participant.codes[r])] +
                              stimulus[std::size_t(study.stimulus.codes[r])] +
                              spec.residual_sd * normal.next();
        study.y[r] = rounded ? std::clamp(std::round(latent), 1.0, 7.0) : latent;
    }
}

mixed::FixedDesign level_design(const SimulatedStudy& study, bool intercept) {
    mixed::FixedDesign design;
    const auto rows = Eigen::Index(study.y.size());
    const auto k = study.level.levels.size();
    design.x = Eigen::MatrixXd::Zero(rows, Eigen::Index(k - 1 + (intercept ? 1 : 0)));
    if (intercept) {
        design.x.col(0).setOnes();
        design.names.push_back("(Intercept)");
        design.term_of_column.push_back("(Intercept)");
    }
    const int offset = intercept ? 1 : 0;
    for (std::size_t j = 1; j < k; ++j) {
        design.names.push_back("level" + study.level.levels[j]);
        design.term_of_column.push_back("level");
    }
    for (Eigen::Index r = 0; r < rows; ++r) {
        const int code = study.level.codes[std::size_t(r)];
        if (code > 0) design.x(r, offset + code - 1) = 1.0;
    }
    return design;
}

Statistic lmm_p(const SimulatedStudy& study) {
    mixed::LmmSpec spec;
    spec.y =
        Eigen::Map<const Eigen::VectorXd>(study.y.data(), Eigen::Index(study.y.size()));
    spec.fixed = level_design(study, true);
    spec.random = {mixed::random_intercept(study.participant),
                   mixed::random_intercept(study.stimulus)};
    const mixed::LmmFit fit = mixed::fit_lmm(spec);
    return fit.anova.empty() ? std::nullopt : fit.anova.front().p;
}

Statistic clmm_p(const SimulatedStudy& study) {
    mixed::ClmmSpec spec;
    spec.response.name = "rating";
    std::vector<int> used(8, 0);
    for (double y : study.y) used[std::size_t(y)] = 1;
    std::vector<int> code_of(8, -1);
    for (int v = 1; v <= 7; ++v)
        if (used[std::size_t(v)]) {
            code_of[std::size_t(v)] = int(spec.response.levels.size());
            spec.response.levels.push_back(std::to_string(v));
        }
    if (spec.response.levels.size() < 2) return std::nullopt;
    for (double y : study.y) spec.response.codes.push_back(code_of[std::size_t(y)]);
    spec.fixed = level_design(study, false);
    spec.random_intercepts = {study.participant, study.stimulus};
    const mixed::ClmmFit fit = mixed::fit_clmm(spec);
    const auto test = mixed::clmm_likelihood_ratio_test(spec, fit, "level");
    if (test.df <= 0 || !std::isfinite(test.p)) return std::nullopt;
    return test.p;
}

// Each participant's mean per level, for the repeated-measures ANOVA.
Statistic by_participant_p(const CrossedPowerSpec& spec, const SimulatedStudy& study) {
    const std::size_t k = spec.level_means.size(), n = std::size_t(spec.participants);
    SubjectByLevel matrix;
    matrix.participants = study.participant.levels;
    matrix.levels = study.level.levels;
    matrix.values.assign(n * k, 0.0);
    for (std::size_t r = 0; r < study.y.size(); ++r)
        matrix.values[std::size_t(study.participant.codes[r]) * k +
                      std::size_t(study.level.codes[r])] +=
            study.y[r] / spec.stimuli_per_level;
    return repeated_measures_anova(matrix).p;
}

}  // namespace

void check_crossed_power_spec(const CrossedPowerSpec& spec) {
    if (spec.model != RatingModel::lmm && spec.model != RatingModel::clmm)
        throw InputError("--model must be lmm or clmm for a crossed design");
    if (spec.participants < 2)
        throw InputError("--participants must be at least 2, got " +
                         std::to_string(spec.participants));
    if (spec.stimuli_per_level < 2 || spec.stimuli_per_level > 1000)
        throw InputError("--stimuli must lie in [2, 1000] (pictures per level), got " +
                         std::to_string(spec.stimuli_per_level));
    if (spec.level_means.size() < 2 || spec.level_means.size() > 50)
        throw InputError("--means needs 2 to 50 levels, got " +
                         std::to_string(spec.level_means.size()));
    for (double m : spec.level_means)
        if (!std::isfinite(m)) throw InputError("--means must be finite numbers");
    for (auto [value, name] : {std::pair{spec.participant_sd, "--participant-sd"},
                               std::pair{spec.stimulus_sd, "--stimulus-sd"}})
        if (!(value >= 0.0 && std::isfinite(value)))
            throw InputError(std::string(name) + " must be a finite number >= 0");
    if (!(spec.residual_sd > 0.0 && std::isfinite(spec.residual_sd)))
        throw InputError("--residual-sd must be a finite number > 0");
    if (!(spec.alpha > 0.0 && spec.alpha < 1.0))
        throw InputError("--alpha must lie strictly between 0 and 1");
    if (spec.simulations < 10 || spec.simulations > 1000000)
        throw InputError("--simulations must lie in [10, 1000000], got " +
                         std::to_string(spec.simulations));
    const double ratings = double(spec.participants) * spec.stimuli_per_level *
                           double(spec.level_means.size());
    if (ratings > 2e6)
        throw InputError("the design has " + std::to_string(std::llround(ratings)) +
                         " ratings per simulated study; at most 2000000");
}

std::optional<double> crossed_closed_form_power(const CrossedPowerSpec& spec) {
    if (spec.model != RatingModel::lmm || spec.likert) return std::nullopt;
    const double k = double(spec.level_means.size()), m = spec.stimuli_per_level,
                 n = spec.participants;
    double grand = 0.0;
    for (double mean : spec.level_means) grand += mean / k;
    double spread = 0.0;
    for (double mean : spec.level_means) spread += (mean - grand) * (mean - grand);
    const double variance =
        spec.stimulus_sd * spec.stimulus_sd + spec.residual_sd * spec.residual_sd / n;
    const double df1 = k - 1.0, df2 = k * (m - 1.0);
    const double lambda = m * spread / variance;
    const double critical = boost::math::quantile(
        boost::math::complement(boost::math::fisher_f(df1, df2), spec.alpha));
    if (lambda == 0.0) return spec.alpha;
    return boost::math::cdf(
        boost::math::complement(boost::math::non_central_f(df1, df2, lambda), critical));
}

CrossedPowerResult estimate_crossed_power(const CrossedPowerSpec& spec,
                                          const std::function<void(int, int)>& progress) {
    check_crossed_power_spec(spec);
    CrossedPowerResult result;
    result.spec = spec;
    result.closed_form = crossed_closed_form_power(spec);
    NormalSource normal(spec.seed);
    SimulatedStudy study = layout(spec);
    long model_hits = 0, naive_hits = 0;
    for (int run = 0; run < spec.simulations; ++run) {
        draw(spec, normal, study);
        Statistic p;
        try {
            p = spec.model == RatingModel::lmm ? lmm_p(study) : clmm_p(study);
        } catch (const InputError&) {
            p.reset();
        }
        if (!p) ++result.failed_fits;
        model_hits += p && *p < spec.alpha;
        const Statistic naive = by_participant_p(spec, study);
        naive_hits += naive && *naive < spec.alpha;
        if (progress) progress(run + 1, spec.simulations);
    }
    result.model_test = power_estimate(model_hits, spec.simulations);
    result.by_participant = power_estimate(naive_hits, spec.simulations);
    return result;
}

}  // namespace lucent::analysis
