// Passes whose inputs did not change are not re-run, checked with the recording
// executor (no GL): a second identical frame runs nothing, a changed uniform re-runs its
// pass and what depends on it, new storage re-runs its writers, and uploads call their
// producer only when the content hash changes.
#include "renderer/core/pass_reuse.h"

#include <gtest/gtest.h>

#include "renderer/core/recording_executor.h"
#include "renderer/core/technique.h"
#include "renderer/techniques/registry.h"

namespace lucent {
namespace {

using Names = std::vector<std::string>;

// table (upload) -> atlas (fixed 32x32, mips) ; tint (uniform) -> tinted ;
// combine(atlas, tinted) -> colour (frame) ; overlay composites onto colour.
struct SyntheticPlan {
    std::string table_hash = "t1";
    float tint = 0.5f;
    int width = 16;
    float overlay_alpha = 0.25f;
    int* produced = nullptr;

    FramePlan build() const {
        PlanBuilder b(PlanMode::pruned, width, 8);
        b.create(texture_2d("table", ResourceFormat::r32f, 4, 1));
        b.create(texture_2d("atlas", ResourceFormat::r32f, 32, 32, 0));
        b.create(texture_2d("tinted", ResourceFormat::rgba32f, 8, 8));
        b.create(frame_texture("colour", ResourceFormat::rgba32f));
        Pass table{"table", "", PassKind::upload};
        table.writes = {"table"};
        int* counter = produced;
        table.data = {table_hash, [counter](const ProduceOptions&) {
                          if (counter) ++*counter;
                          return TextureData{{4, 1, 1}, {std::vector<float>(4, 1.0f)}};
                      }};
        b.add(table);
        Pass atlas{"atlas", "", PassKind::fullscreen};
        atlas.reads = {{"table", ""}};
        atlas.writes = {"atlas"};
        b.add(atlas);
        Pass mips{"atlas_mips", "", PassKind::build_mips};
        mips.writes = {"atlas"};
        b.add(mips);
        Pass tinted{"tint", "", PassKind::fullscreen};
        tinted.writes = {"tinted"};
        tinted.uniforms = {{"u_tint", tint}};
        b.add(tinted);
        Pass combine{"combine", "", PassKind::draw_mesh};
        combine.reads = {{"atlas", "", {TexelFilter::linear, MipFilter::linear}},
                         {"tinted", ""}};
        combine.writes = {"colour"};
        b.add(combine);
        Pass overlay{"overlay", "", PassKind::fullscreen};
        overlay.writes = {"colour"};
        overlay.clear = false;
        overlay.blend = Blend::premultiplied_over;
        overlay.uniforms = {{"u_alpha", overlay_alpha}};
        b.add(overlay);
        b.set_output("colour");
        return b.compile();
    }
};

TEST(PassReuse, SecondIdenticalFrameRunsNothingAndAChangeRerunsOnlyItsDependents) {
    int produced = 0;
    SyntheticPlan spec;
    spec.produced = &produced;
    RecordingExecutor executor;
    const Names all{"table", "atlas", "atlas_mips", "tint", "combine", "overlay"};
    EXPECT_EQ(executor.execute(spec.build()), all);
    EXPECT_EQ(executor.execute(spec.build()), Names{});  // a fresh but identical plan
    EXPECT_EQ(produced, 1);

    spec.tint = 0.75f;  // one uniform: its pass and what reads its output (and what
                        // composites onto that)
    EXPECT_EQ(executor.execute(spec.build()), (Names{"tint", "combine", "overlay"}));
    EXPECT_EQ(executor.execute(spec.build()), Names{});

    // The compositing pass: it drew over combine's output, which must be redrawn first.
    spec.overlay_alpha = 0.5f;
    EXPECT_EQ(executor.execute(spec.build()), (Names{"combine", "overlay"}));

    spec.table_hash = "t2";  // new data: upload, its readers, their mips, downstream
    EXPECT_EQ(executor.execute(spec.build()),
              (Names{"table", "atlas", "atlas_mips", "combine", "overlay"}));
    EXPECT_EQ(produced, 2);

    // A new frame size reallocates the frame-sized colour only: the fixed-size atlas,
    // tint and table are kept.
    spec.width = 20;
    EXPECT_EQ(executor.execute(spec.build()), (Names{"combine", "overlay"}));
    EXPECT_EQ(executor.execute(spec.build()), Names{});
    EXPECT_EQ(executor.uploads_performed(), 2u);
}

TEST(PassReuse, WithoutReuseEveryPassRunsButUploadsStillFollowTheHash) {
    int produced = 0;
    SyntheticPlan spec;
    spec.produced = &produced;
    RecordingExecutor executor(/*reuse_unchanged_passes=*/false);
    const Names all{"table", "atlas", "atlas_mips", "tint", "combine", "overlay"};
    EXPECT_EQ(executor.execute(spec.build()), all);
    EXPECT_EQ(executor.execute(spec.build()), all);
    EXPECT_EQ(produced, 1);
    spec.table_hash = "t2";
    executor.execute(spec.build());
    EXPECT_EQ(produced, 2);
}

// A resource written by two passes: when the first writer re-runs, the second must run
// again even though its own inputs are the same, since it overwrote what is now gone.
TEST(PassReuse, AnOverwrittenResourceRerunsItsLaterWriter) {
    const auto build = [](float first) {
        PlanBuilder b(PlanMode::pruned, 8, 8);
        b.create(frame_texture("x", ResourceFormat::r32f));
        b.create(frame_texture("y", ResourceFormat::r32f));
        b.create(frame_texture("out", ResourceFormat::rgba32f));
        Pass p1{"first_writer", "", PassKind::fullscreen};
        p1.writes = {"x"};
        p1.uniforms = {{"u", first}};
        Pass r1{"first_reader", "", PassKind::fullscreen};
        r1.reads = {{"x", ""}};
        r1.writes = {"y"};
        Pass p2{"second_writer", "", PassKind::fullscreen};
        p2.writes = {"x"};
        Pass r2{"final", "", PassKind::fullscreen};
        r2.reads = {{"x", ""}, {"y", ""}};
        r2.writes = {"out"};
        for (const Pass* p : {&p1, &r1, &p2, &r2}) b.add(*p);
        b.set_output("out");
        return b.compile();
    };
    RecordingExecutor executor;
    executor.execute(build(1.0f));
    EXPECT_EQ(executor.execute(build(2.0f)),
              (Names{"first_writer", "first_reader", "second_writer", "final"}));
}

class TechniqueReuse : public ::testing::Test {
protected:
    static FramePlan plan(const std::string& technique_name,
                          std::vector<KnobAssignment> settings,
                          glm::vec3 view = {0.0f, 0.0f, 1.0f}) {
        static const auto mesh = std::make_shared<const Mesh>(load_mesh("sphere:200"));
        const Technique& technique = find_technique(technique_name);
        const Scene scene =
            make_scene(mesh, technique,
                       resolve_knob_values(knobs_for(technique), settings), 64, 48, view);
        return make_frame_plan(scene, technique);
    }
};

TEST_F(TechniqueReuse, EmpiricalSlidersRerunOnlyThePassesTheyTouch) {
    // A closed mesh: back faces for the second layer, then front faces shaded with the
    // smoothing done per fragment.
    RecordingExecutor executor;
    EXPECT_EQ(executor.execute(plan("empirical", {})),
              (Names{"ambient_occlusion", "second_layer", "shade"}));
    EXPECT_EQ(executor.execute(plan("empirical", {})), Names{});
    // A shading uniform, or the smoothing kernel (a define of `shade`): shade only.
    EXPECT_EQ(executor.execute(plan("empirical", {{"shininess", "30"}})), Names{"shade"});
    EXPECT_EQ(
        executor.execute(plan("empirical", {{"shininess", "30"}, {"blur_kernel", "3"}})),
        Names{"shade"});
    // AO rays: the bake and the shading that reads it; the back layer stays.
    EXPECT_EQ(
        executor.execute(plan(
            "empirical", {{"shininess", "30"}, {"blur_kernel", "3"}, {"ao_rays", "64"}})),
        (Names{"ambient_occlusion", "shade"}));
    // Orbiting the camera: every drawing pass, never the AO bake.
    EXPECT_EQ(
        executor.execute(plan(
            "empirical", {{"shininess", "30"}, {"blur_kernel", "3"}, {"ao_rays", "64"}},
            {1.0f, 0.0f, 0.0f})),
        (Names{"second_layer", "shade"}));
    // Another mesh: everything that depends on it.
    EXPECT_EQ(executor.execute(
                  plan("empirical",
                       {{"shininess", "30"}, {"blur_kernel", "3"}, {"ao_rays", "64"}},
                       {1.0f, 0.0f, 0.0f}),
                  "another mesh"),
              (Names{"ambient_occlusion", "second_layer", "shade"}));
    // Without the backlight: AO rays re-run the bake and the shading only.
    executor.execute(plan("empirical", {{"backlight", "0"}, {"ao_rays", "64"}}));
    EXPECT_EQ(
        executor.execute(plan("empirical", {{"backlight", "0"}, {"ao_rays", "32"}})),
        (Names{"ambient_occlusion", "shade"}));
}

TEST_F(TechniqueReuse, EmpiricalPeelingSlidersRerunOnlyThePassesTheyTouch) {
    // The thesis's depth peeling (every open mesh; layer_method = peel).
    const auto peel = [](std::vector<KnobAssignment> settings,
                         glm::vec3 view = {0, 0, 1}) {
        settings.push_back({"layer_method", "peel"});
        return plan("empirical", settings, view);
    };
    RecordingExecutor executor;
    EXPECT_EQ(executor.execute(peel({})),
              (Names{"ambient_occlusion", "front_depth", "second_layer",
                     "smooth_back_layer", "shade"}));
    EXPECT_EQ(executor.execute(peel({})), Names{});
    // A shading uniform: the shade pass only.
    EXPECT_EQ(executor.execute(peel({{"shininess", "30"}})), Names{"shade"});
    // The smoothing kernel (a define): smoothing and shading, not the layers or the AO.
    EXPECT_EQ(executor.execute(peel({{"shininess", "30"}, {"blur_kernel", "3"}})),
              (Names{"smooth_back_layer", "shade"}));
    // AO rays: the bake, and the front layer that carries the AO to the (deferred)
    // shading, so everything drawn after it.
    EXPECT_EQ(executor.execute(
                  peel({{"shininess", "30"}, {"blur_kernel", "3"}, {"ao_rays", "64"}})),
              (Names{"ambient_occlusion", "front_depth", "second_layer",
                     "smooth_back_layer", "shade"}));
    // Orbiting the camera: every drawing pass, never the AO bake.
    EXPECT_EQ(executor.execute(
                  peel({{"shininess", "30"}, {"blur_kernel", "3"}, {"ao_rays", "64"}},
                       {1.0f, 0.0f, 0.0f})),
              (Names{"front_depth", "second_layer", "smooth_back_layer", "shade"}));
}

TEST_F(TechniqueReuse, EveryTechniqueRunsNothingOnAnIdenticalSecondFrame) {
    for (const char* name : {"empirical", "ward", "contrast_reversed"}) {
        RecordingExecutor executor;
        EXPECT_FALSE(executor.execute(plan(name, {})).empty()) << name;
        EXPECT_EQ(executor.execute(plan(name, {})), Names{}) << name;
    }
}

}  // namespace
}  // namespace lucent
