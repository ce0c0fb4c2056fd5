#include "core/technique.h"

namespace lucent {

FramePlan make_frame_plan(const Scene& scene, const Technique& technique, PlanMode mode) {
    PlanBuilder builder(mode, scene.width, scene.height);
    technique.plan(scene, builder);
    return builder.compile();
}

}  // namespace lucent
