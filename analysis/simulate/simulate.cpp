#include "analysis/simulate/simulate.h"

#include <cmath>
#include <random>

#include "analysis/simulate/normal_source.h"

namespace lucent::analysis {
namespace {

int likert_from_latent(double latent) {
    int rating = 4 + static_cast<int>(std::lround(latent));
    return rating < 1 ? 1 : rating > 7 ? 7 : rating;
}

}  // namespace

void check_spec(const SimulationSpec& spec) {
    if (spec.participants < 1) throw InputError("--participants must be at least 1");
    if (spec.stimuli_per_level < 1)
        throw InputError("--stimuli-per-level must be at least 1");
    if (spec.level_effects.size() < 1)
        throw InputError("--effects needs at least one level");
    if (spec.questions.empty())
        throw InputError("--questions needs at least one question");
    if (!(spec.noise_sd >= 0.0) || !(spec.participant_sd >= 0.0) ||
        !(spec.stimulus_sd >= 0.0) || !std::isfinite(spec.stimulus_sd))
        throw InputError("--noise-sd, --participant-sd and --stimulus-sd must be >= 0");
    for (double e : spec.level_effects)
        if (!std::isfinite(e)) throw InputError("--effects must be finite numbers");
}

LongTable simulate_study(const SimulationSpec& spec) {
    check_spec(spec);
    NormalSource normal(spec.seed);
    std::vector<double> stimulus_offset(spec.level_effects.size() *
                                            std::size_t(spec.stimuli_per_level) *
                                            spec.questions.size(),
                                        0.0);
    if (spec.stimulus_sd > 0.0) {
        NormalSource stimulus_normal(spec.seed ^ 0x9e3779b97f4a7c15ULL);
        for (double& offset : stimulus_offset)
            offset = spec.stimulus_sd * stimulus_normal.next();
    }
    LongTable table;
    std::size_t row_number = 1;  // as if line 1 were a header
    for (int p = 1; p <= spec.participants; ++p) {
        const double offset = spec.participant_sd * normal.next();
        for (std::size_t level = 0; level < spec.level_effects.size(); ++level) {
            for (int s = 1; s <= spec.stimuli_per_level; ++s) {
                for (std::size_t q = 0; q < spec.questions.size(); ++q) {
                    const std::string& question = spec.questions[q];
                    const double stimulus =
                        stimulus_offset[(level * std::size_t(spec.stimuli_per_level) +
                                         std::size_t(s - 1)) *
                                            spec.questions.size() +
                                        q];
                    const double latent = spec.level_effects[level] + offset + stimulus +
                                          spec.noise_sd * normal.next();
                    RatingRow row;
                    row.participant = "p" + std::to_string(p);
                    row.stimulus =
                        "s" + std::to_string(level + 1) + "_" + std::to_string(s);
                    row.factor = spec.factor;
                    row.level = std::to_string(level + 1);
                    row.question = question;
                    row.rating = likert_from_latent(latent);
                    row.source_line = ++row_number;
                    table.rows.push_back(std::move(row));
                }
            }
        }
    }
    return table;
}

}  // namespace lucent::analysis
