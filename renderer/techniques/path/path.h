#pragma once
// The path technique: volumetric path tracing on the CPU (Embree through RayCaster), the
// ground truth every other technique is measured against. The mesh bounds a medium
// behind a smooth dielectric interface; the lights are a uniform environment (Ia), the
// key light as a disc of finite angular radius (Id), and the background behind the
// object. What the knobs, the tracer and the plan share; README.md beside this file
// states every decision.
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"
#include "renderer/core/technique.h"
#include "renderer/techniques/path/transport.h"

namespace lucent::path {

struct Params {
    // The dipole's defaults, so that one knob name has one default (docs/parameters.md).
    std::string material = "skin1";         // a Jensen et al. 2001 preset or "custom"
    glm::dvec3 sigma_a{0.032, 0.17, 0.48};  // custom, mm^-1
    glm::dvec3 sigma_s_prime{0.74, 0.88, 1.01};  // custom, mm^-1
    double eta = 1.3;                            // custom: relative index, [1, 2]
    double g = 0.0;             // Henyey-Greenstein asymmetry, [-0.95, 0.95]
    double model_size = 10.0;   // mm: the mesh's bounding-box diagonal
    double light_radius = 2.0;  // degrees: the key light's angular radius
    int paths = 16;             // per pixel and channel
    double time_budget = 0.0;   // seconds, 0: none (then deterministic)
    int seed = 0;
    bool operator==(const Params&) const = default;
};

const std::vector<Knob>& knobs();
Params params(const Scene& scene);

// One channel's medium of the scene in object units (coefficients times mm per unit),
// with the scene's density volume, if any, scaling them.
ChannelMedium channel_medium(const Scene& scene, const Params& p, int channel);
// The medium's relative index (the preset's, or the custom eta).
double medium_eta(const Params& p);

// What the tracer will skip for this scene, one phrase each (for --explain): "no Fresnel
// (eta = 1)", "no collisions (sigma_s = 0)", "no density lookups (constant)", "key light
// off", "environment off". Empty with PlanMode::full.
std::vector<std::string> shortcuts_taken(const Scene& scene, const Params& p);

// Where the tracer reports its progress, and whether it may take its shortcuts.
struct TraceOptions {
    bool full = false;  // PlanMode::full: none of the shortcuts (for the tests)
    // False: the key light only through phase-sampled hits of its disc, no shadow rays
    // (for the test that holds the two estimators equal).
    bool light_sampling = true;
    ProduceOptions produce;
};

// What a render did, for `lucent bench truth`: the walks' events and the CPU time the
// tracing threads used (their sum over threads).
struct TraceStatistics {
    WalkCounters counters;
    double cpu_seconds = 0.0;
    double wall_seconds = 0.0;
    int paths_done = 0;
};

// Renders the scene's estimate: the mean per pixel (rows top first, alpha = coverage of
// the pixel centre's ray, as the rasteriser's), its standard error, and a summary line.
EstimatedImage render_path(const Scene& scene, const TraceOptions& options = {},
                           TraceStatistics* statistics = nullptr);

// The plan: one upload pass whose producer is the tracer (a bake: batch renders run it
// before their workers, the explorer in the background), the output.
void add_passes(const Scene& scene, PlanBuilder& plan);

}  // namespace lucent::path
