#pragma once
// A synthetic study from a latent normal model, so the whole pipeline can run without a
// lab: every participant rates every stimulus on every question; a stimulus belongs to
// one level of one factor. Latent score = level effect + participant offset + noise, cut
// into a 7-point rating at thresholds -2.5, -1.5, ..., 2.5 (so 0 maps to the middle, 4).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/data/long_table.h"

namespace lucent::analysis {

struct SimulationSpec {
    int participants = 38;      // the thesis's completed responses
    int stimuli_per_level = 1;  // images per level
    std::vector<std::string> questions{"translucent"};
    std::string factor = "thickness";
    std::vector<double> level_effects{0.0, 0.0,
                                      0.0};  // latent shift per level (sd units)
    double participant_sd = 0.0;  // between-participant spread of the latent mean
    double noise_sd = 1.0;        // per-rating latent noise
    // Spread of the stimuli's own offsets (one per stimulus and question), the stimulus
    // variance a mixed model with stimuli as random effects estimates. Drawn from a
    // stream of its own, so a study without it is the same as before for a seed.
    double stimulus_sd = 0.0;
    std::uint64_t seed = 1;
};

// Levels are named "1", "2", ...; stimuli "s<level>_<i>"; participants "p<i>".
LongTable simulate_study(const SimulationSpec& spec);

// Throws InputError when the spec cannot describe a study (no participants, ...).
void check_spec(const SimulationSpec& spec);

}  // namespace lucent::analysis
