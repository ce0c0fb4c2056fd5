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
    if (!(spec.noise_sd >= 0.0) || !(spec.participant_sd >= 0.0))
        throw InputError("--noise-sd and --participant-sd must be >= 0");
    for (double e : spec.level_effects)
        if (!std::isfinite(e)) throw InputError("--effects must be finite numbers");
}

LongTable simulate_study(const SimulationSpec& spec) {
    check_spec(spec);
    NormalSource normal(spec.seed);
    LongTable table;
    std::size_t row_number = 1;  // as if line 1 were a header
    for (int p = 1; p <= spec.participants; ++p) {
        const double offset = spec.participant_sd * normal.next();
        for (std::size_t level = 0; level < spec.level_effects.size(); ++level) {
            for (int s = 1; s <= spec.stimuli_per_level; ++s) {
                for (const std::string& question : spec.questions) {
                    const double latent = spec.level_effects[level] + offset +
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
