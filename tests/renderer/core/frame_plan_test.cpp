// The frame planner with no GL: which passes exist for each scene, that culled passes
// are never visited, and that the plan is a pure function of (scene, knobs).
#include "renderer/core/frame_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "renderer/core/recording_executor.h"
#include "renderer/core/technique.h"
#include "renderer/techniques/registry.h"

namespace lucent {
namespace {

std::vector<std::string> pass_names(const FramePlan& plan) {
    std::vector<std::string> names;
    for_each_pass(plan, [&](const Pass& pass) { names.push_back(pass.name); });
    return names;
}

std::vector<std::string> resource_names(const FramePlan& plan) {
    std::vector<std::string> names;
    for (const auto& r : plan.resources) names.push_back(r.name);
    std::sort(names.begin(), names.end());
    return names;
}

const Pass& pass_named(const FramePlan& plan, const std::string& name) {
    for (const auto& pass : plan.passes)
        if (pass.name == name) return pass;
    throw std::runtime_error("no pass " + name);
}

bool has_define(const Pass& pass, const std::string& define) {
    const auto& d = pass.shader.defines;
    return std::find(d.begin(), d.end(), define) != d.end();
}

// The thesis's layers by depth peeling (layer_method = peel; what every open mesh gets).
class EmpiricalPlan : public ::testing::Test {
protected:
    FramePlan plan(std::vector<KnobAssignment> settings,
                   PlanMode mode = PlanMode::pruned) {
        settings.push_back({"layer_method", "peel"});
        return plan_for(closed_sphere(), std::move(settings), mode);
    }
    static std::shared_ptr<const Mesh> closed_sphere() {
        static const auto mesh = std::make_shared<const Mesh>(load_mesh("sphere:200"));
        return mesh;
    }
    static FramePlan plan_for(const std::shared_ptr<const Mesh>& mesh,
                              const std::vector<KnobAssignment>& settings,
                              PlanMode mode = PlanMode::pruned,
                              const std::vector<std::string>& also_keep = {}) {
        const Technique& technique = find_technique("empirical");
        const auto knobs = knobs_for(technique);
        const Scene scene =
            make_scene(mesh, technique, resolve_knob_values(knobs, settings), 64, 48);
        return make_frame_plan(scene, technique, mode, also_keep);
    }
};

TEST_F(EmpiricalPlan, DefaultSceneRunsEveryPass) {
    const FramePlan p = plan({});
    EXPECT_EQ(pass_names(p),
              (std::vector<std::string>{"ambient_occlusion", "front_depth",
                                        "second_layer", "smooth_back_layer", "shade"}));
    EXPECT_TRUE(p.culled.empty());
    EXPECT_EQ(p.width, 64);
    EXPECT_EQ(p.height, 48);
    EXPECT_EQ(p.output, "colour");
    const Pass& shade = pass_named(p, "shade");
    EXPECT_TRUE(has_define(shade, "WITH_AMBIENT_OCCLUSION"));
    EXPECT_TRUE(has_define(shade, "WITH_BACKLIGHT"));
    EXPECT_TRUE(has_define(pass_named(p, "smooth_back_layer"), "KERNEL_SIZE 5"));
    EXPECT_EQ(p.resource("front_depth")->format, ResourceFormat::depth32f);
}

TEST_F(EmpiricalPlan, ZeroBacklightDropsPeelingSmoothingAndTheirTextures) {
    const FramePlan p = plan({{"backlight", "0"}});
    EXPECT_EQ(pass_names(p), (std::vector<std::string>{"ambient_occlusion", "shade"}));
    // front_depth was added but nothing reads it any more: the compiler culled it.
    EXPECT_EQ(p.culled, (std::vector<std::string>{"front_depth"}));
    EXPECT_EQ(resource_names(p),
              (std::vector<std::string>{"colour", "shade_depth", "vertex_ao"}));
    EXPECT_FALSE(has_define(pass_named(p, "shade"), "WITH_BACKLIGHT"));
}

TEST_F(EmpiricalPlan, ZeroAmbientOrZeroAmbientLightSkipsTheAoBake) {
    for (const auto& setting :
         {KnobAssignment{"ambient", "0"}, KnobAssignment{"light_ambient", "0"}}) {
        const FramePlan p = plan({setting});
        EXPECT_EQ(pass_names(p), (std::vector<std::string>{"front_depth", "second_layer",
                                                           "smooth_back_layer", "shade"}))
            << setting.key;
        EXPECT_EQ(p.culled, (std::vector<std::string>{"ambient_occlusion"}));
        EXPECT_EQ(p.resource("vertex_ao"), nullptr);
        EXPECT_FALSE(has_define(pass_named(p, "shade"), "WITH_AMBIENT_OCCLUSION"));
    }
    // One dark channel of the ambient light is not zero light: AO stays.
    EXPECT_NE(plan({{"light_ambient", "0,0,0.1"}}).resource("vertex_ao"), nullptr);
}

TEST_F(EmpiricalPlan, KernelOneDropsSmoothingAndShadesFromTheRawSecondLayer) {
    const FramePlan p = plan({{"blur_kernel", "1"}});
    EXPECT_EQ(pass_names(p), (std::vector<std::string>{"ambient_occlusion", "front_depth",
                                                       "second_layer", "shade"}));
    EXPECT_EQ(p.resource("smoothed_depth"), nullptr);
    const auto& reads = pass_named(p, "shade").reads;
    EXPECT_TRUE(std::any_of(reads.begin(), reads.end(), [](const Read& r) {
        return r.resource == "second_depth" && r.sampler == "back_depth";
    }));
    EXPECT_TRUE(has_define(pass_named(plan({{"blur_kernel", "3"}}), "smooth_back_layer"),
                           "KERNEL_SIZE 3"));
}

TEST_F(EmpiricalPlan, EverythingOffLeavesOnlyShading) {
    const FramePlan p = plan({{"backlight", "0"}, {"ambient", "0"}});
    EXPECT_EQ(pass_names(p), (std::vector<std::string>{"shade"}));
    EXPECT_EQ(resource_names(p), (std::vector<std::string>{"colour", "shade_depth"}));
}

TEST_F(EmpiricalPlan, FullModeForcesEveryPassAndEveryTerm) {
    const FramePlan p = plan({{"backlight", "0"}, {"ambient", "0"}, {"blur_kernel", "1"}},
                             PlanMode::full);
    EXPECT_EQ(pass_names(p),
              (std::vector<std::string>{"ambient_occlusion", "front_depth",
                                        "second_layer", "smooth_back_layer", "shade"}));
    EXPECT_TRUE(p.culled.empty());
    EXPECT_TRUE(has_define(pass_named(p, "smooth_back_layer"), "KERNEL_SIZE 1"));
    EXPECT_TRUE(has_define(pass_named(p, "shade"), "WITH_AMBIENT_OCCLUSION"));
    EXPECT_TRUE(has_define(pass_named(p, "shade"), "WITH_BACKLIGHT"));
}

TEST_F(EmpiricalPlan, DepthPrecisionPicksTheLayerFormatAndPlansArePure) {
    EXPECT_EQ(plan({{"depth_precision", "16"}}).resource("second_depth")->format,
              ResourceFormat::depth16);
    EXPECT_EQ(plan({{"depth_precision", "24"}}).resource("front_depth")->format,
              ResourceFormat::depth24);
    EXPECT_EQ(plan({{"shininess", "3"}}).explain(), plan({{"shininess", "3"}}).explain());
    const std::string text = plan({{"backlight", "0"}}).explain();
    EXPECT_NE(text.find("shade: vertex_ao -> colour (rgba32f), shade_depth (depth32f)"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("culled: front_depth"), std::string::npos) << text;
}

// layer_method = auto on a closed mesh facing out: the layers come from culling by
// facing.
TEST_F(EmpiricalPlan, AClosedMeshTakesItsLayersByFacingWithoutPeeling) {
    ASSERT_TRUE(closed_sphere()->closed_facing_out);
    const FramePlan p = plan_for(closed_sphere(), {});
    EXPECT_EQ(pass_names(p),
              (std::vector<std::string>{"ambient_occlusion", "second_layer", "shade"}));
    // The separate smoothing pass is planned but nothing reads it: `shade` smooths.
    EXPECT_EQ(p.culled, (std::vector<std::string>{"smooth_back_layer"}));
    const Pass& back = pass_named(p, "second_layer");
    EXPECT_EQ(back.cull, FaceCulling::front);
    EXPECT_TRUE(back.reads.empty());  // no peel: the first layer is not read
    EXPECT_EQ(back.writes, (std::vector<std::string>{"second_depth"}));
    const Pass& shade = pass_named(p, "shade");
    EXPECT_EQ(shade.kind, PassKind::draw_mesh);
    EXPECT_EQ(shade.cull, FaceCulling::back);
    EXPECT_TRUE(has_define(shade, "WITH_BACKLIGHT"));
    EXPECT_TRUE(has_define(shade, "SMOOTH_IN_SHADE"));
    EXPECT_TRUE(has_define(shade, "KERNEL_SIZE 5"));
    EXPECT_EQ(shade.writes, (std::vector<std::string>{"colour", "front_depth"}));
    EXPECT_TRUE(std::any_of(shade.reads.begin(), shade.reads.end(), [](const Read& r) {
        return r.resource == "second_depth" && r.sampler == "back_depth";
    }));
    EXPECT_EQ(p.resource("front_depth")->format, ResourceFormat::depth32f);
    EXPECT_EQ(p.resource("front_surface"), nullptr);
    EXPECT_EQ(p.resource("smoothed_depth"), nullptr);
    const std::string text = p.explain();
    EXPECT_NE(text.find("<culls front faces>"), std::string::npos) << text;
    EXPECT_NE(text.find("<culls back faces>"), std::string::npos) << text;
}

TEST_F(EmpiricalPlan, ByFacingKernelOneAndZeroBacklightKeepTheirPrunes) {
    const FramePlan raw = plan_for(closed_sphere(), {{"blur_kernel", "1"}});
    EXPECT_EQ(pass_names(raw),
              (std::vector<std::string>{"ambient_occlusion", "second_layer", "shade"}));
    EXPECT_FALSE(has_define(pass_named(raw, "shade"), "SMOOTH_IN_SHADE"));
    const FramePlan direct = plan_for(closed_sphere(), {{"backlight", "0"}});
    EXPECT_EQ(pass_names(direct),
              (std::vector<std::string>{"ambient_occlusion", "shade"}));
    EXPECT_EQ(pass_named(direct, "shade").cull, FaceCulling::back);
    EXPECT_FALSE(has_define(pass_named(direct, "shade"), "WITH_BACKLIGHT"));
    EXPECT_EQ(resource_names(direct),
              (std::vector<std::string>{"colour", "front_depth", "vertex_ao"}));
    // Full mode keeps every pass, the separate smoothing included.
    const FramePlan full =
        plan_for(closed_sphere(), {{"backlight", "0"}}, PlanMode::full);
    EXPECT_EQ(pass_names(full),
              (std::vector<std::string>{"ambient_occlusion", "second_layer",
                                        "smooth_back_layer", "shade"}));
}

TEST_F(EmpiricalPlan, AViewOfTheSmoothedLayerKeepsItsPass) {
    const FramePlan p =
        plan_for(closed_sphere(), {}, PlanMode::pruned, {"smoothed_depth"});
    EXPECT_EQ(pass_names(p),
              (std::vector<std::string>{"ambient_occlusion", "second_layer",
                                        "smooth_back_layer", "shade"}));
    ASSERT_NE(p.resource("smoothed_depth"), nullptr);
    // A resource the plan does not have keeps nothing more.
    EXPECT_EQ(pass_names(plan_for(closed_sphere(), {}, PlanMode::pruned, {"no_such"})),
              (std::vector<std::string>{"ambient_occlusion", "second_layer", "shade"}));
}

TEST_F(EmpiricalPlan, AnOpenMeshOrACameraInsideIsPeeled) {
    Mesh open = load_mesh("sphere:200");
    open.triangles.pop_back();  // a hole
    finalize_mesh(open);
    ASSERT_FALSE(open.closed_facing_out);
    const FramePlan p = plan_for(std::make_shared<const Mesh>(std::move(open)), {});
    EXPECT_EQ(pass_names(p),
              (std::vector<std::string>{"ambient_occlusion", "front_depth",
                                        "second_layer", "smooth_back_layer", "shade"}));
    EXPECT_EQ(pass_named(p, "second_layer").cull, FaceCulling::none);
    EXPECT_EQ(pass_named(p, "shade").cull, FaceCulling::none);

    // The same closed sphere seen from inside its bounding sphere, or with the near plane
    // cutting into it: culling by facing would show its inside, so it is peeled.
    const Technique& technique = find_technique("empirical");
    Scene scene = make_scene(closed_sphere(), technique,
                             resolve_knob_values(knobs_for(technique), {}), 64, 48);
    EXPECT_TRUE(facing_separates_layers(scene));
    Scene inside = scene;
    inside.camera.eye =
        inside.bounds.centre + glm::vec3(0.0f, 0.0f, 0.5f * inside.bounds.radius);
    EXPECT_FALSE(facing_separates_layers(inside));
    EXPECT_EQ(pass_named(make_frame_plan(inside, technique), "second_layer").cull,
              FaceCulling::none);
    Scene clipped = scene;
    clipped.camera.near_plane = glm::distance(clipped.camera.eye, clipped.bounds.centre);
    EXPECT_FALSE(facing_separates_layers(clipped));
}

// The compiler on a synthetic graph (Filament's SimplePassCulling): a pass whose output
// nobody reads is culled, transitively, and never visited.
TEST(PlanBuilder, CullsUnreadPassesTransitivelyAndNeverVisitsThem) {
    PlanBuilder builder(PlanMode::pruned, 8, 8);
    builder.create("a", ResourceFormat::r32f);
    builder.create("b", ResourceFormat::r32f);
    builder.create("unused", ResourceFormat::r32f);
    builder.create("out", ResourceFormat::rgba32f);
    Pass make_a{"make_a"}, make_b{"make_b"}, dead{"dead"}, final_pass{"final"};
    make_a.writes = {"a"};
    make_b.reads = {{"a", ""}};
    make_b.writes = {"b"};
    dead.reads = {{"b", ""}};
    dead.writes = {"unused"};
    final_pass.reads = {{"a", ""}};
    final_pass.writes = {"out"};
    for (auto* pass : {&make_a, &make_b, &dead, &final_pass}) builder.add(*pass);
    builder.set_output("out");
    const FramePlan plan = builder.compile();
    EXPECT_EQ(pass_names(plan), (std::vector<std::string>{"make_a", "final"}));
    EXPECT_EQ(plan.culled, (std::vector<std::string>{"make_b", "dead"}));
    EXPECT_EQ(resource_names(plan), (std::vector<std::string>{"a", "out"}));

    PlanBuilder full(PlanMode::full, 8, 8);
    full.create("a", ResourceFormat::r32f);
    full.create("b", ResourceFormat::r32f);
    full.create("unused", ResourceFormat::r32f);
    full.create("out", ResourceFormat::rgba32f);
    for (auto* pass : {&make_a, &make_b, &dead, &final_pass}) full.add(*pass);
    full.set_output("out");
    EXPECT_EQ(pass_names(full.compile()).size(), 4u);
}

// The message of the std::logic_error `f` throws, or "(accepted)".
std::string logic_error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::logic_error& e) {
        return e.what();
    }
    return "(accepted)";
}

// Names are checked where they are declared: add() rejects the pass (one line naming it
// and the name), so such a plan never compiles either.
TEST(PlanBuilder, RejectsReadsBeforeWritesAndUndeclaredResources) {
    PlanBuilder builder(PlanMode::pruned, 8, 8);
    builder.create("out", ResourceFormat::rgba32f);
    builder.create("unwritten", ResourceFormat::r32f);
    Pass reader{"reader"};
    reader.reads = {{"missing", ""}};
    reader.writes = {"out"};
    EXPECT_EQ(logic_error_of([&] { builder.add(reader); }),
              "frame plan: pass 'reader' reads 'missing', which no create() declared");
    reader.reads = {{"unwritten", ""}};
    EXPECT_EQ(logic_error_of([&] { builder.add(reader); }),
              "frame plan: pass 'reader' reads 'unwritten' before any pass writes it");
    builder.set_output("out");
    EXPECT_THROW(builder.compile(), std::logic_error);

    PlanBuilder undeclared(PlanMode::pruned, 8, 8);
    Pass writer{"writer"};
    writer.writes = {"nowhere"};
    EXPECT_EQ(logic_error_of([&] { undeclared.add(writer); }),
              "frame plan: pass 'writer' writes undeclared 'nowhere'");
    undeclared.set_output("nowhere");
    EXPECT_THROW(undeclared.compile(), std::logic_error);
    undeclared.create("nowhere", ResourceFormat::r32f);
    undeclared.add(writer);
    EXPECT_THROW(undeclared.add(writer), std::logic_error);  // duplicate pass name
}

// [SECTION] Resource shapes, levels, data, attachments (the frame plan of issue 11)

Pass pass_writing(std::string name, std::vector<std::string> writes,
                  std::vector<Read> reads = {}) {
    Pass pass{std::move(name)};
    pass.kind = PassKind::fullscreen;
    pass.writes = std::move(writes);
    pass.reads = std::move(reads);
    return pass;
}

DataSource constant_data(std::string hash, glm::ivec3 size, int channels) {
    return {std::move(hash), [size, channels](const ProduceOptions&) {
                return TextureData{
                    size,
                    {std::vector<float>(std::size_t(size.x) * size.y * size.z * channels,
                                        1.0f)}};
            }};
}

TEST(PlanBuilder, ResolvesShapesSizesAndFullMipChains) {
    PlanBuilder builder(PlanMode::pruned, 64, 48);
    builder.create(frame_texture("colour", ResourceFormat::rgba32f));
    builder.create(frame_texture("frame_mips", ResourceFormat::r32f, 0));
    builder.create(texture_2d("atlas", ResourceFormat::r32f, 256, 64, 0));
    builder.create(texture_3d("density", ResourceFormat::r8, 32, 16, 8));
    Pass upload{"density_volume"};
    upload.kind = PassKind::upload;
    upload.writes = {"density"};
    upload.data = constant_data("d1", {32, 16, 8}, 1);
    builder.add(upload);
    builder.add(pass_writing("atlas_pass", {"atlas"}, {{"density", ""}}));
    builder.add(pass_writing("frame_pass", {"frame_mips"}));
    builder.add(pass_writing(
        "shade", {"colour"},
        {{"atlas", "", {TexelFilter::linear, MipFilter::linear}}, {"frame_mips", ""}}));
    builder.set_output("colour");
    const FramePlan plan = builder.compile();
    // Frame-sized resources take the plan's size; 0 levels is the full chain, counted by
    // hand: 64x48 -> 32x24, 16x12, 8x6, 4x3, 2x1, 1x1 is 7 levels; 256x64 has 9.
    EXPECT_EQ(plan.resource("colour")->size, glm::ivec3(64, 48, 1));
    EXPECT_EQ(plan.resource("frame_mips")->levels, 7);
    EXPECT_EQ(plan.resource("atlas")->levels, 9);
    EXPECT_EQ(plan.resource("density")->size, glm::ivec3(32, 16, 8));
    EXPECT_EQ(mip_size({256, 64, 1}, 7, false), glm::ivec3(2, 1, 1));
    EXPECT_EQ(mip_size({5, 3, 7}, 1, true), glm::ivec3(2, 1, 3));
    // Every resource's size and format is in --explain, and sampler state of a read.
    const std::string text = plan.explain();
    for (const char* line :
         {"resource colour: 64x48 rgba32f (frame)",
          "resource frame_mips: 64x48 r32f, 7 levels",
          "resource atlas: 256x64 r32f, 9 levels", "resource density: 32x16x8 r8",
          "shade: atlas (linear/mip linear clamp), frame_mips -> colour (rgba32f)",
          "density_volume: - -> density (r8)  <upload, data d1>"})
        EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
    EXPECT_EQ(plan.viewport(pass_named(plan, "atlas_pass")), glm::ivec2(256, 64));
    EXPECT_EQ(plan.viewport(pass_named(plan, "shade")), glm::ivec2(64, 48));
}

TEST(PlanBuilder, ViewportIsTheAttachmentsLevelAndMixedSizesAreRejected) {
    PlanBuilder builder(PlanMode::pruned, 64, 48);
    builder.create(texture_2d("a", ResourceFormat::r32f, 32, 32, 0));
    builder.create(texture_2d("b", ResourceFormat::r32f, 32, 16, 3));
    builder.create(frame_texture("out", ResourceFormat::rgba32f));
    builder.add(pass_writing("level_zero", {"a"}));
    Pass level_two = pass_writing("level_two", {"a"});
    level_two.level = 2;  // 32 / 4 = 8
    level_two.clear = false;
    builder.add(level_two);
    Pass b_one = pass_writing("b_one", {"b"});
    b_one.level = 1;
    builder.add(b_one);
    builder.add(pass_writing("final", {"out"}, {{"a", ""}, {"b", ""}}));
    builder.set_output("out");
    const FramePlan plan = builder.compile();
    EXPECT_EQ(plan.viewport(pass_named(plan, "level_two")), glm::ivec2(8, 8));
    EXPECT_EQ(plan.viewport(pass_named(plan, "b_one")), glm::ivec2(16, 8));
    EXPECT_NE(
        plan.explain().find("level_two: - -> a (r32f)  <level 2>  <keeps contents>"),
        std::string::npos)
        << plan.explain();

    PlanBuilder mixed(PlanMode::pruned, 64, 48);
    mixed.create(texture_2d("a", ResourceFormat::r32f, 32, 32));
    mixed.create(frame_texture("out", ResourceFormat::rgba32f));
    mixed.add(pass_writing("both", {"a", "out"}));
    mixed.set_output("out");
    try {
        mixed.compile();
        ADD_FAILURE() << "mixed attachment sizes compiled";
    } catch (const std::logic_error& e) {
        EXPECT_STREQ(e.what(),
                     "frame plan: pass 'both' writes 'a' (32x32x1) and 'out' (64x48x1): "
                     "attachments differ in size");
    }
}

TEST(PlanBuilder, RejectsMalformedUploadsMipsLevelsAndFeedback) {
    const auto compile_with = [](std::vector<ResourceDesc> resources,
                                 std::vector<Pass> passes, std::string output) {
        PlanBuilder builder(PlanMode::pruned, 16, 16);
        for (auto& r : resources) builder.create(r);
        for (auto& p : passes) builder.add(p);
        builder.set_output(output);
        return builder.compile();
    };
    const ResourceDesc out = frame_texture("out", ResourceFormat::rgba32f);
    Pass no_hash{"table"};
    no_hash.kind = PassKind::upload;
    no_hash.writes = {"out"};
    no_hash.data.produce = [](const ProduceOptions&) { return TextureData{}; };
    EXPECT_THROW(compile_with({out}, {no_hash}, "out"), std::logic_error);
    Pass one_level_mips{"mips"};
    one_level_mips.kind = PassKind::build_mips;
    one_level_mips.writes = {"out"};
    EXPECT_THROW(compile_with({out}, {pass_writing("w", {"out"}), one_level_mips}, "out"),
                 std::logic_error);
    // build_mips needs level 0 written first.
    const ResourceDesc mipped = frame_texture("out", ResourceFormat::rgba32f, 0);
    EXPECT_THROW(compile_with({mipped}, {one_level_mips}, "out"), std::logic_error);
    EXPECT_NO_THROW(
        compile_with({mipped}, {pass_writing("w", {"out"}), one_level_mips}, "out"));
    Pass too_deep = pass_writing("deep", {"out"});
    too_deep.level = 5;  // 16x16 has levels 0..4
    EXPECT_THROW(compile_with({mipped}, {too_deep}, "out"), std::logic_error);
    EXPECT_THROW(compile_with({texture_2d("t", ResourceFormat::r32f, 0, 4)},
                              {pass_writing("w", {"t"})}, "t"),
                 std::logic_error);
    EXPECT_THROW(compile_with({out, frame_texture("x", ResourceFormat::r32f)},
                              {pass_writing("w", {"x"}),
                               pass_writing("loop", {"x", "out"}, {{"x", ""}})},
                              "out"),
                 std::logic_error);
    // A pass keeping its attachment's contents needs an earlier writer.
    Pass keep = pass_writing("composite", {"out"});
    keep.clear = false;
    EXPECT_THROW(compile_with({out}, {keep}, "out"), std::logic_error);
}

// Compositing passes depend on what they draw over, and build_mips on the level it
// reduces: culling keeps their producers.
TEST(PlanBuilder, KeptContentsAndMipsKeepTheirProducers) {
    PlanBuilder builder(PlanMode::pruned, 16, 16);
    builder.create(frame_texture("layers", ResourceFormat::rgba32f));
    builder.create(texture_2d("irradiance", ResourceFormat::r32f, 64, 64, 0));
    builder.create(frame_texture("unread", ResourceFormat::r32f));
    builder.add(pass_writing("irradiance", {"irradiance"}));
    Pass mips{"irradiance_mips"};
    mips.kind = PassKind::build_mips;
    mips.writes = {"irradiance"};
    builder.add(mips);
    builder.add(pass_writing("dead", {"unread"}, {{"irradiance", ""}}));
    builder.add(pass_writing("back_layer", {"layers"}, {{"irradiance", ""}}));
    Pass front = pass_writing("front_layer", {"layers"});
    front.clear = false;
    front.blend = Blend::premultiplied_over;
    builder.add(front);
    builder.set_output("layers");
    const FramePlan plan = builder.compile();
    EXPECT_EQ(pass_names(plan), (std::vector<std::string>{"irradiance", "irradiance_mips",
                                                          "back_layer", "front_layer"}));
    EXPECT_EQ(plan.culled, (std::vector<std::string>{"dead"}));
    const std::string text = plan.explain();
    EXPECT_NE(text.find("irradiance_mips: - -> irradiance (r32f)  <2x2 box mips>"),
              std::string::npos)
        << text;
    EXPECT_NE(
        text.find("front_layer: - -> layers (rgba32f)  <keeps contents>  <blend over>"),
        std::string::npos)
        << text;
}

// The new pass kinds take part in culling like the others, --plan full keeps them, and
// the recording executor runs them (calling a kept upload's producer once).
TEST(PlanBuilder, NewPassKindsAreCulledWhenUnreadAndKeptInFullMode) {
    int produced = 0;
    const auto build = [&](PlanMode mode) {
        PlanBuilder builder(mode, 8, 8);
        builder.create(texture_2d("unused_table", ResourceFormat::r32f, 4, 1));
        builder.create(texture_2d("unused_mips", ResourceFormat::r32f, 8, 8, 0));
        builder.create(frame_texture("out", ResourceFormat::rgba32f));
        Pass table{"unused_table", "", PassKind::upload};
        table.writes = {"unused_table"};
        table.data = {"h", [&produced](const ProduceOptions&) {
                          ++produced;
                          return TextureData{{4, 1, 1}, {std::vector<float>(4, 0.5f)}};
                      }};
        builder.add(table);
        builder.add(pass_writing("level_zero", {"unused_mips"}, {{"unused_table", ""}}));
        Pass mips{"mips", "", PassKind::build_mips};
        mips.writes = {"unused_mips"};
        builder.add(mips);
        builder.add(pass_writing("final", {"out"}));
        builder.set_output("out");
        return builder.compile();
    };
    const FramePlan pruned = build(PlanMode::pruned);
    EXPECT_EQ(pass_names(pruned), std::vector<std::string>{"final"});
    EXPECT_EQ(pruned.culled,
              (std::vector<std::string>{"unused_table", "level_zero", "mips"}));
    EXPECT_EQ(pruned.resource("unused_mips"), nullptr);
    RecordingExecutor recorder;
    EXPECT_EQ(recorder.execute(pruned), std::vector<std::string>{"final"});
    EXPECT_EQ(produced, 0);  // a culled upload never produces its data

    const FramePlan full = build(PlanMode::full);
    EXPECT_TRUE(full.culled.empty());
    RecordingExecutor full_recorder;
    EXPECT_EQ(full_recorder.execute(full),
              (std::vector<std::string>{"unused_table", "level_zero", "mips", "final"}));
    EXPECT_EQ(produced, 1);
    EXPECT_NE(full.explain().find("resource unused_mips: 8x8 r32f, 4 levels"),
              std::string::npos)
        << full.explain();
}

// A vertex stream is described once (format, vertex count, attribute), filled by an
// ordinary upload (here a bake, as the AO) and read by mesh passes only; executors hand
// every upload they perform to the UploadProducer, which sees what it is only through
// its DataSource.
TEST(PlanBuilder, VertexStreamsAreUploadedResourcesReadByMeshPasses) {
    int produced = 0;
    const auto build = [&](ResourceDesc stream, PassKind reader, std::string hash) {
        PlanBuilder builder(PlanMode::pruned, 8, 8);
        builder.create(stream);
        builder.create(frame_texture("out", ResourceFormat::rgba32f));
        Pass upload{"per_vertex", "", PassKind::upload};
        upload.writes = {stream.name};
        upload.data.content_hash = std::move(hash);
        upload.data.cost = ProductionCost::bake;
        upload.data.produce = [&produced](const ProduceOptions&) {
            ++produced;
            return TextureData{{5, 1, 1}, {std::vector<float>(10, 0.5f)}};
        };
        builder.add(upload);
        Pass draw = pass_writing("draw", {"out"}, {{stream.name, ""}});
        draw.kind = reader;
        builder.add(draw);
        builder.set_output("out");
        return builder.compile();
    };
    const ResourceDesc stream = vertex_stream("pairs", ResourceFormat::rg32f, 5, 6);
    const FramePlan plan = build(stream, PassKind::draw_mesh, "h1");
    EXPECT_EQ(pass_names(plan), (std::vector<std::string>{"per_vertex", "draw"}));
    EXPECT_TRUE(is_bake(plan.passes[0]));
    EXPECT_FALSE(is_bake(plan.passes[1]));
    EXPECT_NE(plan.explain().find("resource pairs: 5 vertices x rg32f at attribute 6"),
              std::string::npos)
        << plan.explain();

    RecordingExecutor recorder;
    std::vector<std::string> seen;
    recorder.set_upload_producer([&](const Pass& pass) {
        seen.push_back(pass.name + " " + pass.data.content_hash);
        return produce_upload(pass);
    });
    recorder.execute(plan);
    recorder.execute(plan);  // the same hash: nothing produced
    recorder.execute(build(stream, PassKind::draw_mesh, "h2"));
    EXPECT_EQ(seen, (std::vector<std::string>{"per_vertex h1", "per_vertex h2"}));
    EXPECT_EQ(produced, 2);
    // Another mesh (key) with the same data re-runs the stream's upload, as mesh passes.
    EXPECT_EQ(recorder.execute(build(stream, PassKind::draw_mesh, "h2"), "another"),
              (std::vector<std::string>{"per_vertex", "draw"}));

    EXPECT_EQ(
        logic_error_of([&] { build(stream, PassKind::fullscreen, "h"); }),
        "frame plan: pass 'draw' reads the vertex stream 'pairs' but draws no mesh");
    EXPECT_EQ(logic_error_of([&] {
                  build(vertex_stream("pairs", ResourceFormat::rg32f, 5, 1),
                        PassKind::draw_mesh, "h");
              }),
              "frame plan: resource 'pairs': attribute 1 is not a free vertex attribute "
              "location");
    EXPECT_EQ(logic_error_of([&] {
                  build(vertex_stream("pairs", ResourceFormat::rgba8, 5, 2),
                        PassKind::draw_mesh, "h");
              }),
              "frame plan: resource 'pairs': a vertex stream is r32f, rg32f or rgba32f, "
              "not rgba8");
    PlanBuilder drawn_into(PlanMode::pruned, 8, 8);
    drawn_into.create(stream);
    drawn_into.add(pass_writing("draw", {"pairs"}));
    drawn_into.set_output("pairs");
    EXPECT_EQ(logic_error_of([&] { drawn_into.compile(); }),
              "frame plan: pass 'draw' draws into the vertex stream 'pairs'; streams are "
              "uploaded");
}

TEST(TextureData, ChecksSizeLevelsAndTexelCounts) {
    const ResourceDesc volume{
        "v", ResourceFormat::rgba32f, ResourceShape::fixed_3d, {4, 2, 3}, 1};
    EXPECT_EQ(
        check_texture_data(volume, {{4, 2, 3}, {std::vector<float>(4 * 2 * 3 * 4)}}), "");
    EXPECT_EQ(check_texture_data(volume, {{4, 2, 3}, {std::vector<float>(4 * 2 * 3)}}),
              "level 0 has 24 floats, expected 96");
    EXPECT_EQ(check_texture_data(volume, {{4, 2, 2}, {std::vector<float>(64)}}),
              "data is 4x2x2, the resource 4x2x3");
    const ResourceDesc pyramid{
        "p", ResourceFormat::r32f, ResourceShape::fixed_2d, {4, 4, 1}, 3};
    EXPECT_EQ(check_texture_data(pyramid, {{4, 4, 1},
                                           {std::vector<float>(16), std::vector<float>(4),
                                            std::vector<float>(1)}}),
              "");
    EXPECT_EQ(check_texture_data(pyramid, {{4, 4, 1}, {}}),
              "0 data levels for a resource of 3");
}

}  // namespace
}  // namespace lucent
