#pragma once
// The interface every translucency technique implements. Techniques are known at compile
// time and listed once in renderer/techniques/registry.cpp; adding one is a folder under
// renderer/techniques/ plus one registry line. GL-free: a technique describes passes
// (shaders, reads, writes, uniforms) and renderer/gl executes them.
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/progressive.h"
#include "renderer/core/scene.h"

namespace lucent {

// A knob whose value trades accuracy for time, for `lucent bench accuracy`: the values
// to sweep (cheapest first) and the value the CPU reference image is rendered with.
// `with`: other knobs set for this sweep only, for a knob that matters only in a mode
// (the dipole's ring count L, say, only with hybrid=on).
struct QualitySweep {
    std::string knob;
    std::vector<KnobValue> values;
    KnobValue reference;
    // A scene knob swept for the table (thickness, viewing angle): the CPU reference is
    // rendered again at each value instead of once at `reference`.
    bool per_value_reference = false;
    std::vector<std::pair<std::string, KnobValue>> with = {};
};

// What `lucent bench frame` compares for a technique, as its source paper's cost table
// did: variants of one scene rendered on each mesh of a family, frames interleaved, each
// variant's median frame time and its ratio to the last variant (the baseline).
struct FrameComparison {
    std::string mesh;                // built-in family, e.g. "torus_knot"
    std::vector<std::string> faces;  // face budgets, one row each
    struct Variant {
        std::string label;  // column heading, e.g. "full"
        std::vector<KnobAssignment> settings;
    };
    std::vector<Variant> variants;  // at least two; the last is the baseline
    std::string note;               // one line under the table: what the ratios mean
    // Optional: what else to say of a variant's scene, e.g. "53 fetches per pixel".
    std::function<std::string(const Scene&)> detail = {};
};

// A Monte Carlo image with its per-pixel standard error (rgb per pixel, alpha 0) and a
// one-line summary (samples, time, events), from a technique that estimates its image.
struct EstimatedImage {
    Image mean;
    Image standard_error;
    std::string summary;
};

// A knob `lucent bench fidelity` fits to the path-traced truth, for a technique whose
// knobs are appearance, not physics: the range searched (narrower than the knob's own
// where that is wide; an rgb knob fits each channel in it).
struct FitRange {
    std::string knob;
    double lo = 0.0, hi = 1.0;
};

class Technique {
public:
    virtual ~Technique() = default;
    virtual std::string_view name() const = 0;         // registry name, e.g. "empirical"
    virtual std::string_view description() const = 0;  // one line for help text
    // The technique's own knobs, including shared material knobs it uses (albedo, ...).
    // The scene knobs (light, camera, background) are added by the registry.
    virtual const std::vector<Knob>& knobs() const = 0;
    // Adds the passes `scene` calls for (all of them when plan.full()) and sets the
    // output.
    virtual void plan(const Scene& scene, PlanBuilder& plan) const = 0;
    // The same image computed on the CPU (Embree ray casting), independent of the GL
    // path.
    virtual Image render_reference(const Scene& scene) const = 0;
    // Refuses a scene the technique cannot render, in one line: MeshError naming the mesh
    // (e.g. no UVs where the technique needs them) or KnobError naming the knob (e.g. a
    // texture spec or file that does not parse). build_scene() calls it.
    virtual void check_scene(const Scene& /*scene*/) const {}
    // Quality knobs for the accuracy bench; empty when the technique has none.
    virtual std::vector<QualitySweep> quality_sweeps() const { return {}; }
    // How an interactive view refines this technique's image over frames (none by
    // default): see core/progressive.h.
    virtual ProgressiveRefinement progressive_refinement() const { return {}; }
    // A technique whose image is a Monte Carlo estimate made on the CPU (the path
    // tracer) renders it with its standard error here, so `lucent render` can write the
    // error beside the image; nullopt for the others (their image is the GL plan's).
    virtual std::optional<EstimatedImage> render_estimate(
        const Scene& /*scene*/, const ProduceOptions& /*options*/) const {
        return std::nullopt;
    }
    // The knobs `lucent bench fidelity` fits to the truth (appearance, not physics: the
    // truth's material and scene knobs of the same names are taken as they are, as the
    // dipole takes its material); none: nothing is fitted.
    virtual std::vector<FitRange> fidelity_fit() const { return {}; }
    // The cost comparison of `lucent bench frame --technique NAME`; none: the bench
    // sweeps the first quality knob instead.
    virtual std::optional<FrameComparison> frame_comparison() const {
        return std::nullopt;
    }
};

// The plan of `scene` under its technique: technique.plan() then compile(), keeping also
// the passes that produce the resources named in `also_keep` (PlanBuilder::also_keep).
FramePlan make_frame_plan(const Scene& scene, const Technique& technique,
                          PlanMode mode = PlanMode::pruned,
                          const std::vector<std::string>& also_keep = {});

}  // namespace lucent
