#include "analysis/simulate/crossed_power.h"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/non_central_f.hpp>
#include <cmath>
#include <string>

#include "analysis/models/rating_model.h"
#include "analysis/simulate/normal_source.h"
#include "analysis/stats/repeated_measures.h"

namespace lucent::analysis {
namespace {

CrossedSample layout(const CrossedPowerSpec& spec) {
    CrossedSample study;
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

void draw(const CrossedPowerSpec& spec, NormalSource& normal, CrossedSample& study) {
    const int k = int(spec.level_means.size()), m = spec.stimuli_per_level,
              n = spec.participants;
    std::vector<double> participant(static_cast<std::size_t>(n));
    std::vector<double> stimulus(static_cast<std::size_t>(k * m));
    for (double& p : participant) p = spec.participant_sd * normal.next();
    for (double& s : stimulus) s = spec.stimulus_sd * normal.next();
    const bool rounded = spec.likert || find_rating_model(spec.model)->rounds_to_scale;
    for (std::size_t r = 0; r < study.y.size(); ++r) {
        const double latent = spec.level_means[std::size_t(study.level.codes[r])] +
                              participant[std::size_t(study.participant.codes[r])] +
                              stimulus[std::size_t(study.stimulus.codes[r])] +
                              spec.residual_sd * normal.next();
        study.y[r] = rounded ? std::clamp(std::round(latent), 1.0, 7.0) : latent;
    }
}

// Each participant's mean per level, for the repeated-measures ANOVA.
Statistic by_participant_p(const CrossedPowerSpec& spec, const CrossedSample& study) {
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

mixed::FixedDesign crossed_level_design(const CrossedSample& study, bool intercept) {
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

void check_crossed_power_spec(const CrossedPowerSpec& spec) {
    const RatingModelSpec* model = find_rating_model(spec.model);
    if (!model || !model->crossed_p) {
        std::string simulated;
        for (const RatingModelSpec* m : rating_models())
            if (m->crossed_p) simulated += (simulated.empty() ? "" : " or ") + m->name;
        throw InputError(
            "--model must be " + simulated + " for a crossed design" +
            (model ? " ('" + spec.model + "' has no power simulation)" : ""));
    }
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
    // The closed form is the linear model's F test of the stimulus means.
    if (spec.model != "lmm" || spec.likert) return std::nullopt;
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
    CrossedSample study = layout(spec);
    const RatingModelSpec& model = *find_rating_model(spec.model);
    long model_hits = 0, naive_hits = 0;
    for (int run = 0; run < spec.simulations; ++run) {
        draw(spec, normal, study);
        Statistic p;
        try {
            p = model.crossed_p(study);
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
