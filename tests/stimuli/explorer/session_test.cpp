// The explorer's session without a window: parameter sets validate and round values the
// way `--set` does, the request for `lucent render` reproduces them, and the view
// helpers (orbit, light drag, zoom) move in the documented directions and stay in range.
#include "stimuli/explorer/session.h"

#include <gtest/gtest.h>

#include <cmath>

#include "renderer/core/common_knobs.h"
#include "renderer/techniques/registry.h"

namespace lucent::explorer {
namespace {

TEST(ParameterSet, StartsAtTheRegistryDefaults) {
    const ParameterSet set("empirical");
    for (const Knob& knob : knobs_for(find_technique("empirical")))
        EXPECT_EQ(set.values().get(knob.name), knob.default_value) << knob.name;
}

TEST(ParameterSet, ValuesRoundTripThroughTheCommandLinePath) {
    ParameterSet set("empirical");
    set.set("backlight", static_cast<double>(0.7f));  // a float slider's value
    set.set("albedo", glm::dvec3(0.1f, 0.2f, 0.3f));
    // What `lucent render --set` would resolve from the request's texts.
    const RenderRequest request = [&] {
        ExplorerSession session;
        session.sets[0] = set;
        return render_request(session, 0, 64, 48);
    }();
    const KnobValues resolved =
        resolve_knob_values(knobs_for(find_technique("empirical")), request.settings);
    EXPECT_EQ(resolved.all(), set.values().all());
    EXPECT_EQ(request.width, 64);
    EXPECT_EQ(request.height, 48);
}

TEST(ParameterSet, RejectsOutOfRangeAndUnknownKnobsKeepingTheOldValue) {
    ParameterSet set("empirical");
    const double before = set.values().scalar("backlight");
    EXPECT_THROW(set.set("backlight", 11.0), KnobError);  // documented range [0, 10]
    EXPECT_THROW(set.set("roughness", 0.1), KnobError);   // a ward knob
    EXPECT_THROW(set.set("light_direction", glm::dvec3(0.0)), KnobError);
    EXPECT_EQ(set.values().scalar("backlight"), before);
}

TEST(ParameterSet, SwitchingTechniqueKeepsEachTechniquesValues) {
    ParameterSet set("empirical");
    set.set("backlight", 2.5);
    set.set_technique("ward");
    EXPECT_FALSE(set.values().contains("backlight"));
    set.set_technique("empirical");
    EXPECT_EQ(set.values().scalar("backlight"), 2.5);
    EXPECT_THROW(set.set_technique("nonsense"), KnobError);
}

TEST(KnobGroups, EveryKnobOfEveryTechniqueLandsInOnePanel) {
    for (const Technique* technique : all_techniques()) {
        for (const Knob& knob : knobs_for(*technique)) {
            const bool scene_knob = find_knob(scene_knobs(), knob.name) != nullptr;
            const KnobGroup group = knob_group(knob);
            EXPECT_EQ(scene_knob, group == KnobGroup::light || group == KnobGroup::camera)
                << knob.name;
        }
    }
    EXPECT_EQ(knob_group(*find_knob(scene_knobs(), "fov_y")), KnobGroup::camera);
    EXPECT_EQ(knob_group(albedo_knob()), KnobGroup::material);
    EXPECT_EQ(knob_group(ao_rays_knob()), KnobGroup::ambient_occlusion);
    const auto knobs = knobs_for(find_technique("empirical"));
    EXPECT_EQ(knob_group(*find_knob(knobs, "backlight")), KnobGroup::technique);
}

TEST(View, DefaultLooksAlongPlusZLikeLucentRender) {
    ExplorerSession session;
    EXPECT_TRUE(session.default_view());
    const glm::vec3 d = view_direction(session);
    EXPECT_NEAR(d.x, 0.f, 1e-7f);
    EXPECT_NEAR(d.y, 0.f, 1e-7f);
    EXPECT_NEAR(d.z, 1.f, 1e-7f);
}

TEST(View, OrbitTurnsAboutYAndClampsPitch) {
    ExplorerSession session;
    orbit(session, -225.f, 0.f);  // 0.4 degrees per pixel: 90 degrees
    EXPECT_NEAR(session.yaw_degrees, 90.f, 1e-4f);
    EXPECT_NEAR(view_direction(session).x, 1.f, 1e-6f);
    orbit(session, 0.f, 1e6f);
    EXPECT_EQ(session.pitch_degrees, 89.f);
    EXPECT_TRUE(std::isfinite(view_direction(session).y));
}

TEST(View, RightDragTurnsTheLightTowardsTheDrag) {
    ExplorerSession session;
    session.current().set("light_direction", glm::dvec3(0, 0, 1));
    drag_light(session, 50.f, 0.f);  // 0.5 rad about +Y: z turns towards +x
    const glm::dvec3 d = session.current().values().vec3("light_direction");
    EXPECT_NEAR(d.x, std::sin(0.5), 1e-6);
    EXPECT_NEAR(d.z, std::cos(0.5), 1e-6);
    EXPECT_NEAR(glm::length(d), 1.0, 1e-6);
}

TEST(View, ZoomScalesFovAndStaysInItsRange) {
    ExplorerSession session;
    const double fov = session.current().values().scalar("fov_y");
    zoom(session, 1.f);
    EXPECT_NEAR(session.current().values().scalar("fov_y"), fov * 0.95, 1e-6);
    zoom(session, 1000.f);
    EXPECT_EQ(session.current().values().scalar("fov_y"),
              find_knob(scene_knobs(), "fov_y")->min);
    zoom(session, -100000.f);
    EXPECT_EQ(session.current().values().scalar("fov_y"),
              find_knob(scene_knobs(), "fov_y")->max);
}

}  // namespace
}  // namespace lucent::explorer
