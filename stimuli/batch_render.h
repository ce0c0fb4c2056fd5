#pragma once
// Batch rendering of a stimulus set: every stimulus through the same single-image path
// as `lucent render --mesh` (make_scene + render_image + write_image), image statistics,
// and manifest.csv / manifest.json. The manifest is rewritten (atomically) before any
// file is replaced and after every finished stimulus, listing exactly the finished ones,
// so an interrupted run resumes where it stopped: a second run re-renders only stimuli
// whose inputs (input hash) or files changed, or that are missing; `force` re-renders
// all.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/stimulus_set.h"
#include "stimuli/manifest.h"

namespace lucent::stimuli {

struct BatchOptions {
    std::filesystem::path out_dir;
    // Render workers, each with its own headless GL context, and as many encode workers
    // (image files, statistics, manifest), which write one image while the next renders.
    int jobs = 1;
    bool force = false;  // re-render every stimulus
    // false: each render worker encodes its own images before rendering the next (no
    // encode workers; `lucent bench render` times both ways).
    bool overlap_encode = true;
    PngEncoding png = PngEncoding::fast;  // how PNG files are compressed (same pixels)
    bool progress = true;                 // progress line on stderr
    // Called on an encode worker's thread after each rendered stimulus is in the
    // manifest, with its id and how many have finished (tests interrupt a set here; may
    // throw: the run then stops and throws).
    std::function<void(const std::string& id, std::size_t finished)> after_stimulus;
};

// Where the time went (seconds, summed over workers; render and encode workers run at
// once, so the stages can add up to more than the wall time).
struct BatchTimings {
    // Bakes (ProductionCost::bake uploads: the AO) and their cache loads.
    double ao_seconds = 0.0;
    double gl_seconds = 0.0;          // plan + GL passes + read-back, bakes excluded
    double encode_seconds = 0.0;      // image encoding and writing (all formats)
    double statistics_seconds = 0.0;  // image statistics and content hashes
    double wall_seconds = 0.0;        // the whole batch, start to manifest
};

struct BatchResult {
    std::size_t rendered = 0;
    std::size_t reused = 0;  // inputs and files unchanged since the last run
    BatchTimings timings;
    std::vector<ManifestRow> rows;  // in set order, as written to the manifest
    // Stimuli whose image had pixels with NaN or Inf values (replaced before writing; the
    // manifest's non_finite_pixels column), with the pixel count, in set order.
    std::vector<std::pair<std::string, std::size_t>> non_finite;
};

// The hash of everything that determines a stimulus's files: software version and build,
// technique, mesh content hash, every parameter value, resolution and formats.
std::string input_hash(const StimulusSet& set, const Stimulus& stimulus,
                       const std::string& mesh_hash);

// Renders `set` into options.out_dir (created if needed). Throws std::runtime_error on
// GL or I/O failure; the stimuli already finished stay valid and listed in the manifest
// (each file is written to a temporary name and renamed).
BatchResult render_stimulus_set(const StimulusSet& set, const BatchOptions& options);

// `lucent render CONFIG.toml --out DIR` / `--preset NAME`: loads, renders and reports;
// returns the exit code (2 for config or usage errors, with nothing written; 1 for
// rendering failures, and after a complete set in which some image had NaN or Inf pixels:
// one warning line per such stimulus). Exactly one of config_path and preset is
// non-empty.
int run_render_set_command(const std::string& config_path, const std::string& preset,
                           const std::string& out_dir, int jobs, bool force);
// The same for the set `load_set` makes (throwing StimulusSetError, one line, for a set
// that cannot be made: exit code 2, nothing written).
int run_render_set_command(const std::function<StimulusSet()>& load_set,
                           const std::string& out_dir, int jobs, bool force);

}  // namespace lucent::stimuli
