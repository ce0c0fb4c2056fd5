// Registers the path technique: volumetric path tracing on the CPU, the ground truth.
#include "renderer/core/technique.h"

#include "renderer/core/mesh.h"
#include "renderer/techniques/path/path.h"

namespace lucent {
namespace {

class PathTechnique final : public Technique {
public:
    std::string_view name() const override { return "path"; }
    std::string_view description() const override {
        return "ground truth: volumetric path tracing (CPU, Embree) of the mesh as a "
               "dielectric-bounded medium, Jensen's materials or a density volume, in mm";
    }
    const std::vector<Knob>& knobs() const override { return path::knobs(); }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        path::add_passes(scene, plan);
    }
    // The image is the CPU's: the reference is the same estimate.
    Image render_reference(const Scene& scene) const override {
        return path::render_path(scene).mean;
    }
    std::optional<EstimatedImage> render_estimate(
        const Scene& scene, const ProduceOptions& options) const override {
        path::TraceOptions trace;
        trace.produce = options;
        return path::render_path(scene, trace);
    }
    void check_scene(const Scene& scene) const override {
        if (!scene.mesh->closed_facing_out)
            throw MeshError("mesh '" + scene.mesh->name +
                            "': the path technique needs a closed mesh facing out (the "
                            "boundary of a medium); this one is open or faces in");
        const path::Params p = path::params(scene);
        if (p.light_radius == 0.0 && path::medium_eta(p) != 1.0 &&
            scene.light.diffuse != glm::vec3(0.0f))
            throw KnobError(
                "light_radius: 0 (a directional light) is reachable only through an "
                "index-matched interface (eta = 1); give the key light a radius > 0");
    }
    // The explorer refines the image a few samples at a time, as the dipole's.
    ProgressiveRefinement progressive_refinement() const override {
        return {"paths", "seed", 1};
    }
};

}  // namespace

const Technique& path_technique() {
    static const PathTechnique technique;
    return technique;
}

}  // namespace lucent
