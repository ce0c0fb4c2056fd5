#include "renderer/core/technique.h"

namespace lucent {

FramePlan make_frame_plan(const Scene& scene, const Technique& technique, PlanMode mode,
                          const std::vector<std::string>& also_keep) {
    PlanBuilder builder(mode, scene.width, scene.height);
    technique.plan(scene, builder);
    for (const auto& resource : also_keep) builder.also_keep(resource);
    return builder.compile();
}

}  // namespace lucent
