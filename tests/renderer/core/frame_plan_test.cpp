// The frame planner with no GL: which passes exist for each scene, that culled passes
// are never visited, and that the plan is a pure function of (scene, knobs).
#include "core/frame_plan.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/technique.h"
#include "techniques/registry.h"

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

class EmpiricalPlan : public ::testing::Test {
protected:
    FramePlan plan(std::vector<KnobAssignment> settings,
                   PlanMode mode = PlanMode::pruned) {
        static const auto mesh = std::make_shared<const Mesh>(load_mesh("sphere:200"));
        const Technique& technique = find_technique("empirical");
        const auto knobs = knobs_for(technique);
        const Scene scene =
            make_scene(mesh, technique, resolve_knob_values(knobs, settings), 64, 48);
        return make_frame_plan(scene, technique, mode);
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

TEST(PlanBuilder, RejectsReadsBeforeWritesAndUndeclaredResources) {
    PlanBuilder builder(PlanMode::pruned, 8, 8);
    builder.create("out", ResourceFormat::rgba32f);
    Pass reader{"reader"};
    reader.reads = {{"missing", ""}};
    reader.writes = {"out"};
    builder.add(reader);
    builder.set_output("out");
    EXPECT_THROW(builder.compile(), std::logic_error);

    PlanBuilder undeclared(PlanMode::pruned, 8, 8);
    Pass writer{"writer"};
    writer.writes = {"nowhere"};
    undeclared.add(writer);
    undeclared.set_output("nowhere");
    EXPECT_THROW(undeclared.compile(), std::logic_error);
    EXPECT_THROW(undeclared.add(writer), std::logic_error);  // duplicate pass name
}

}  // namespace
}  // namespace lucent
