// The GL executor on the frame plan's resource model, each checked against values
// computed independently on the CPU: exact box mips (double-precision block means),
// uploads only on a content-hash change, sampler state per read (hand-derived filter
// weights), any number of colour attachments with the viewport they imply, and blending.
#include "renderer/gl/frame_executor.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <random>
#include <string>
#include <vector>

#include "renderer/core/technique.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

class FrameExecutorGl : public test::HeadlessGlTest {
protected:
    // Test shaders live in tests/renderer/gl/test_shaders; renderer shaders still
    // resolve from the embedded copies.
    void SetUp() override {
        test::HeadlessGlTest::SetUp();
        const char* previous = std::getenv("LUCENT_SHADER_DIR");
        previous_dir_ = previous ? previous : "";
        const std::string dir = (test::source_dir() / "tests/renderer/gl").string();
        setenv("LUCENT_SHADER_DIR", dir.c_str(), 1);
        scene_.mesh = mesh();
    }
    void TearDown() override {
        if (previous_dir_.empty())
            unsetenv("LUCENT_SHADER_DIR");
        else
            setenv("LUCENT_SHADER_DIR", previous_dir_.c_str(), 1);
    }
    static std::shared_ptr<const Mesh> mesh() {
        static const auto m = std::make_shared<const Mesh>(load_mesh("sphere:200"));
        return m;
    }
    Scene scene_;

private:
    std::string previous_dir_;
};

Pass upload_pass(std::string name, std::string resource, std::string hash,
                 TextureData data) {
    Pass pass{std::move(name)};
    pass.kind = PassKind::upload;
    pass.writes = {std::move(resource)};
    pass.data = {std::move(hash),
                 [data = std::move(data)](const ProduceOptions&) { return data; }};
    return pass;
}

Pass fullscreen(std::string name, std::string fragment, std::vector<std::string> writes) {
    Pass pass{std::move(name)};
    pass.kind = PassKind::fullscreen;
    pass.shader = {"gl/shaders/fullscreen.vert", std::move(fragment), {}};
    pass.writes = std::move(writes);
    return pass;
}

std::vector<float> random_texels(std::size_t count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> texels(count);
    for (auto& t : texels) t = unit(rng);
    return texels;
}

// Level l of a W x H texture whose levels are W/w x H/h blocks of level 0 (true for
// power-of-two and 3 * 2^k sizes): each texel must be its block's mean, summed in double.
TEST_F(FrameExecutorGl, MipChainIsTheExactBoxMeanOfLevelZero) {
    struct Case {
        int width, height;
        ResourceFormat format;
    };
    for (const Case c :
         {Case{16, 8, ResourceFormat::rgba32f}, Case{12, 6, ResourceFormat::r32f},
          Case{1, 8, ResourceFormat::r32f}}) {
        const int channels = format_channels(c.format);
        const std::vector<float> base =
            random_texels(std::size_t(c.width) * c.height * channels,
                          unsigned(c.width * 100 + c.height));
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        builder.create(texture_2d("pyramid", c.format, c.width, c.height, 0));
        builder.add(
            upload_pass("base", "pyramid", "base", {{c.width, c.height, 1}, {base}}));
        Pass mips{"mips"};
        mips.kind = PassKind::build_mips;
        mips.writes = {"pyramid"};
        builder.add(mips);
        builder.set_output("pyramid");
        const FramePlan plan = builder.compile();
        gl::FrameExecutor executor;
        executor.execute(scene_, plan);
        const int levels = plan.resource("pyramid")->levels;
        ASSERT_EQ(levels, full_mip_levels({c.width, c.height, 1}, false));
        for (int level = 0; level < levels; ++level) {
            const TextureData got = executor.read_texture("pyramid", level);
            const glm::ivec3 size = mip_size({c.width, c.height, 1}, level, false);
            ASSERT_EQ(got.size, size);
            const int bx = c.width / size.x, by = c.height / size.y;
            double worst = 0.0;
            for (int y = 0; y < size.y; ++y)
                for (int x = 0; x < size.x; ++x)
                    for (int k = 0; k < channels; ++k) {
                        double sum = 0.0;
                        for (int v = y * by; v < (y + 1) * by; ++v)
                            for (int u = x * bx; u < (x + 1) * bx; ++u)
                                sum +=
                                    base[(std::size_t(v) * c.width + u) * channels + k];
                        const double expected = sum / (bx * by);
                        const float actual =
                            got.levels[0][(std::size_t(y) * size.x + x) * channels + k];
                        worst = std::max(worst, std::abs(actual - expected));
                    }
            EXPECT_LT(worst, 1e-6) << c.width << "x" << c.height << " level " << level;
        }
    }
}

TEST_F(FrameExecutorGl, UploadsOnlyWhenTheContentHashChanges) {
    int produced = 0;
    const auto plan_with = [&](std::string hash, int width, float value) {
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        builder.create(texture_2d("table", ResourceFormat::r32f, width, 1));
        Pass pass{"table"};
        pass.kind = PassKind::upload;
        pass.writes = {"table"};
        pass.data = {hash, [&produced, width, value](const ProduceOptions&) {
                         ++produced;
                         return TextureData{
                             {width, 1, 1},
                             {std::vector<float>(std::size_t(width), value)}};
                     }};
        builder.add(pass);
        builder.set_output("table");
        return builder.compile();
    };
    gl::FrameExecutor executor;
    executor.execute(scene_, plan_with("h1", 4, 1.0f));
    executor.execute(scene_, plan_with("h1", 4, 1.0f));
    EXPECT_EQ(produced, 1);
    EXPECT_EQ(executor.uploads_performed(), 1u);
    executor.execute(scene_, plan_with("h2", 4, 2.0f));
    EXPECT_EQ(produced, 2);
    EXPECT_EQ(executor.read_texture("table").levels[0], std::vector<float>(4, 2.0f));
    // A new size reallocates the texture, which then holds nothing: upload again.
    executor.execute(scene_, plan_with("h2", 8, 2.0f));
    EXPECT_EQ(produced, 3);
    EXPECT_EQ(executor.uploads_performed(), 3u);

    // Data of the wrong size is a one-line error naming the pass and the resource.
    PlanBuilder bad(PlanMode::pruned, 4, 4);
    bad.create(texture_2d("table", ResourceFormat::r32f, 4, 1));
    bad.add(upload_pass("table_pass", "table", "short",
                        {{4, 1, 1}, {std::vector<float>(3)}}));
    bad.set_output("table");
    try {
        executor.execute(scene_, bad.compile());
        ADD_FAILURE() << "short data uploaded";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(
            e.what(),
            "pass 'table_pass': data for 'table': level 0 has 3 floats, expected 4");
    }
}

// Each case samples a tiny uploaded texture at one coordinate through one Read's sampler
// state; the expected values follow from GL's filtering rules by hand.
TEST_F(FrameExecutorGl, SamplerStateTravelsWithTheRead) {
    gl::FrameExecutor executor;
    const auto sample = [&](ResourceDesc desc, TextureData data, Sampling sampling,
                            glm::vec3 at, float lod = 0.0f) {
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        const bool volume = desc.shape == ResourceShape::fixed_3d;
        builder.create(desc);
        builder.create(texture_2d("out", ResourceFormat::rgba32f, 1, 1));
        builder.add(upload_pass("data", desc.name, "fixed", std::move(data)));
        Pass read = fullscreen("read", "test_shaders/sample.frag", {"out"});
        if (volume) read.shader.defines = {"VOLUME"};
        read.reads = {{desc.name, "source", sampling}};
        read.uniforms = {{"origin", at}, {"step", glm::vec3(0.0f)}, {"lod", lod}};
        builder.add(read);
        builder.set_output("out");
        executor.execute(scene_, builder.compile());
        return executor.read_texture("out").levels[0][0];
    };
    // A 2x1 texture [0, 1]: texel centres at u = 0.25 and 0.75.
    const ResourceDesc pair = texture_2d("pair", ResourceFormat::r32f, 2, 1);
    const TextureData pair_data{{2, 1, 1}, {{0.0f, 1.0f}}};
    const Sampling nearest{};
    const Sampling linear{TexelFilter::linear};
    Sampling border = nearest;
    border.wrap = Wrap::clamp_to_border;
    border.border = glm::vec4(7.0f);
    Sampling repeat_nearest = nearest, repeat_linear = linear;
    repeat_nearest.wrap = repeat_linear.wrap = Wrap::repeat;
    const float v = 0.5f;  // the row's centre
    EXPECT_FLOAT_EQ(sample(pair, pair_data, nearest, {0.375f, v, 0}), 0.0f);
    EXPECT_FLOAT_EQ(sample(pair, pair_data, linear, {0.375f, v, 0}), 0.25f);
    EXPECT_FLOAT_EQ(sample(pair, pair_data, border, {-0.5f, v, 0}), 7.0f);
    EXPECT_FLOAT_EQ(sample(pair, pair_data, nearest, {-0.5f, v, 0}), 0.0f);
    EXPECT_FLOAT_EQ(sample(pair, pair_data, repeat_nearest, {-0.375f, v, 0}), 1.0f);
    // u = 1.125 wraps to 0.125, a quarter of the way from texel 1 (wrapped, at -0.25)
    // to texel 0: 0.25 * 1 + 0.75 * 0; clamped, both taps are texel 0.
    EXPECT_FLOAT_EQ(sample(pair, pair_data, repeat_linear, {1.125f, v, 0}), 0.25f);
    EXPECT_FLOAT_EQ(sample(pair, pair_data, linear, {1.125f, v, 0}), 1.0f);

    // Three levels holding 1, 3, 5: the mip filter picks or blends them.
    const ResourceDesc levels = texture_2d("levels", ResourceFormat::r32f, 4, 4, 3);
    const TextureData level_data{
        {4, 4, 1}, {std::vector<float>(16, 1.0f), std::vector<float>(4, 3.0f), {5.0f}}};
    Sampling mip_nearest = nearest, mip_linear = linear;
    mip_nearest.mip = MipFilter::nearest;
    mip_linear.mip = MipFilter::linear;
    EXPECT_FLOAT_EQ(sample(levels, level_data, nearest, {0.5f, 0.5f, 0}, 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(sample(levels, level_data, mip_nearest, {0.5f, 0.5f, 0}, 1.0f), 3.0f);
    EXPECT_FLOAT_EQ(sample(levels, level_data, mip_nearest, {0.5f, 0.5f, 0}, 2.0f), 5.0f);
    EXPECT_NEAR(sample(levels, level_data, mip_linear, {0.5f, 0.5f, 0}, 0.5f), 2.0f,
                1e-5f);

    // A 2x2x2 volume holding x + 2y + 4z: trilinear at the centre is the mean 3.5.
    const ResourceDesc volume = texture_3d("volume", ResourceFormat::r32f, 2, 2, 2);
    const TextureData volume_data{{2, 2, 2}, {{0, 1, 2, 3, 4, 5, 6, 7}}};
    EXPECT_NEAR(sample(volume, volume_data, linear, {0.5f, 0.5f, 0.5f}), 3.5f, 1e-5f);
    EXPECT_FLOAT_EQ(sample(volume, volume_data, nearest, {0.75f, 0.25f, 0.75f}), 5.0f);
}

TEST_F(FrameExecutorGl, AnyNumberOfColourAttachmentsAtTheirOwnViewport) {
    PlanBuilder builder(PlanMode::pruned, 64, 48);
    const std::vector<std::string> names{"a0", "a1", "a2", "a3"};
    for (const auto& name : names)
        builder.create(texture_2d(name, ResourceFormat::rgba32f, 5, 3));
    builder.add(fullscreen("four", "test_shaders/attachments.frag", names));
    builder.set_output("a0");
    const FramePlan plan = builder.compile();
    gl::FrameExecutor executor;
    executor.execute(scene_, plan);
    for (int k = 0; k < 4; ++k) {
        const TextureData got = executor.read_texture(names[k]);
        ASSERT_EQ(got.size, glm::ivec3(5, 3, 1));
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 5; ++x) {
                const float* t = &got.levels[0][(std::size_t(y) * 5 + x) * 4];
                EXPECT_EQ(t[0], float(k + 1)) << names[k];  // the attachment's own output
                EXPECT_EQ(t[1], x + 0.5f);                  // every texel was drawn once:
                EXPECT_EQ(t[2], y + 0.5f);                  // the viewport is 5x3
            }
    }

    // One more attachment than GL allows: a one-line error naming the pass.
    GLint limit = 0;
    glGetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &limit);
    PlanBuilder over(PlanMode::pruned, 8, 8);
    std::vector<std::string> many;
    for (GLint i = 0; i <= limit; ++i) {
        many.push_back("c" + std::to_string(i));
        over.create(texture_2d(many.back(), ResourceFormat::r32f, 2, 2));
    }
    over.add(fullscreen("too_many", "test_shaders/attachments.frag", many));
    over.set_output("c0");
    try {
        executor.execute(scene_, over.compile());
        ADD_FAILURE() << limit + 1 << " colour attachments were accepted";
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_EQ(
            message.rfind("pass 'too_many': framebuffer: " + std::to_string(limit + 1) +
                              " colour attachments, this GL allows",
                          0),
            0u)
            << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST_F(FrameExecutorGl, CompositingPassesBlendOntoKeptContents) {
    const auto composite = [&](glm::vec4 dst, glm::vec4 src, Blend blend) {
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        builder.create(texture_2d("layers", ResourceFormat::rgba32f, 2, 2));
        Pass back = fullscreen("back", "test_shaders/constant.frag", {"layers"});
        back.uniforms = {{"colour", dst}};
        Pass front = fullscreen("front", "test_shaders/constant.frag", {"layers"});
        front.uniforms = {{"colour", src}};
        front.clear = false;
        front.blend = blend;
        builder.add(back);
        builder.add(front);
        builder.set_output("layers");
        gl::FrameExecutor executor;
        executor.execute(scene_, builder.compile());
        const std::vector<float> t = executor.read_texture("layers").levels[0];
        return glm::vec4(t[0], t[1], t[2], t[3]);
    };
    const auto expect_vec4 = [](glm::vec4 got, glm::vec4 want) {
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(got[k], want[k], 1e-6f) << k;
    };
    const glm::vec4 dst{0.2f, 0.4f, 0.6f, 1.0f}, src{0.5f, 0.25f, 0.0f, 0.5f};
    expect_vec4(composite(dst, src, Blend::none), src);
    expect_vec4(composite(dst, src, Blend::additive), dst + src);
    expect_vec4(composite(dst, src, Blend::premultiplied_over), src + 0.5f * dst);
    const glm::vec4 half_dst{0.1f, 0.2f, 0.3f, 0.5f}, near_src{0.4f, 0.4f, 0.4f, 0.8f};
    expect_vec4(composite(half_dst, near_src, Blend::premultiplied_under),
                0.5f * near_src + half_dst);
}

// One triangle whose positions are clip coordinates covering the whole viewport.
Scene clip_triangle_scene() {
    auto triangle = std::make_shared<Mesh>();
    triangle->name = "clip-space triangle";
    triangle->positions = {
        {-1.0f, -1.0f, 0.0f}, {3.0f, -1.0f, 0.0f}, {-1.0f, 3.0f, 0.0f}};
    triangle->normals.assign(3, glm::vec3(0.0f, 0.0f, 1.0f));
    triangle->triangles = {{0u, 1u, 2u}};
    triangle->content_hash = "triangle";
    Scene scene;
    scene.mesh = triangle;
    return scene;
}

// A vertex stream is a CPU-made resource like any texture: uploaded by an `upload` pass
// (through the executor's UploadProducer, once per content hash) and bound at its
// attribute by the mesh passes that read it.
TEST_F(FrameExecutorGl, VertexStreamsAreUploadedAndBoundAtTheirAttribute) {
    const Scene scene = clip_triangle_scene();
    const auto plan_with = [](std::string hash, float value, float scale) {
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        builder.create(vertex_stream("values", ResourceFormat::r32f, 3, 2));
        builder.create(texture_2d("out", ResourceFormat::rgba32f, 2, 2));
        Pass upload{"values", "", PassKind::upload};
        upload.writes = {"values"};
        upload.data = {hash, [value](const ProduceOptions&) {
                           return TextureData{{3, 1, 1}, {std::vector<float>(3, value)}};
                       }};
        builder.add(upload);
        Pass draw{"draw",
                  "",
                  PassKind::draw_mesh,
                  {"test_shaders/stream.vert", "test_shaders/stream.frag", {}}};
        draw.reads = {{"values", ""}};
        draw.writes = {"out"};
        draw.uniforms = {{"u_scale", scale}};
        builder.add(draw);
        builder.set_output("out");
        return builder.compile();
    };
    gl::FrameExecutor executor;
    std::vector<std::string> produced;
    executor.set_upload_producer([&](const Pass& pass) {
        produced.push_back(pass.data.content_hash);
        return produce_upload(pass);
    });
    const auto red = [&] {  // of every texel of `out`
        const std::vector<float> texels = executor.read_texture("out").levels[0];
        std::vector<float> r;
        for (std::size_t i = 0; i < texels.size(); i += 4) r.push_back(texels[i]);
        return r;
    };
    executor.execute(scene, plan_with("a", 0.25f, 2.0f));
    EXPECT_EQ(red(), std::vector<float>(4, 0.5f));
    executor.execute(scene, plan_with("a", 0.25f, 4.0f));  // same data: no upload
    EXPECT_EQ(red(), std::vector<float>(4, 1.0f));
    executor.execute(scene, plan_with("b", 0.125f, 4.0f));
    EXPECT_EQ(red(), std::vector<float>(4, 0.5f));
    EXPECT_EQ(produced, (std::vector<std::string>{"a", "b"}));
    EXPECT_EQ(executor.uploads_performed(), 2u);
    EXPECT_EQ(executor.allocated_resources(),
              (std::vector<std::string>{"out", "values"}));
}

// A uniform, sampler or vertex stream whose name the pass's shaders do not declare fails
// the pass in one line naming both; one they declare but this variant compiles out (or
// the compiler optimises away) is fine.
TEST_F(FrameExecutorGl, NamesTheShadersLackFailThePass) {
    const Scene scene = clip_triangle_scene();
    const auto failure = [&](const FramePlan& plan) -> std::string {
        gl::FrameExecutor executor;
        try {
            executor.execute(scene, plan);
        } catch (const std::logic_error& e) {
            return e.what();
        }
        return "(ran)";
    };
    const auto draw_plan = [](std::vector<Uniform> uniforms,
                              std::vector<std::string> defines, int attribute) {
        PlanBuilder builder(PlanMode::pruned, 4, 4);
        builder.create(vertex_stream("values", ResourceFormat::r32f, 3, attribute));
        builder.create(texture_2d("out", ResourceFormat::rgba32f, 2, 2));
        Pass upload{"values", "", PassKind::upload};
        upload.writes = {"values"};
        upload.data = {"v", [](const ProduceOptions&) {
                           return TextureData{{3, 1, 1}, {std::vector<float>(3, 1.0f)}};
                       }};
        builder.add(upload);
        Pass draw{"draw",
                  "",
                  PassKind::draw_mesh,
                  {"test_shaders/stream.vert", "test_shaders/stream.frag", defines}};
        draw.reads = {{"values", ""}};
        draw.writes = {"out"};
        draw.uniforms = std::move(uniforms);
        builder.add(draw);
        builder.set_output("out");
        return builder.compile();
    };
    EXPECT_EQ(failure(draw_plan({{"u_scale", 1.0f}}, {}, 2)), "(ran)");
    EXPECT_EQ(failure(draw_plan({{"u_scael", 1.0f}}, {}, 2)),
              "pass 'draw': uniform 'u_scael' is not declared in "
              "test_shaders/stream.vert + test_shaders/stream.frag");
    // u_offset is declared, in the variant without WITH_OFFSET compiled out.
    EXPECT_EQ(failure(draw_plan({{"u_scale", 1.0f}, {"u_offset", 0.5f}}, {}, 2)),
              "(ran)");
    EXPECT_EQ(
        failure(draw_plan({{"u_scale", 1.0f}, {"u_offset", 0.5f}}, {"WITH_OFFSET"}, 2)),
        "(ran)");
    EXPECT_EQ(failure(draw_plan({{"u_scale", 1.0f}}, {}, 5)),
              "pass 'draw': vertex stream 'values' is bound at attribute 5, which "
              "test_shaders/stream.vert does not declare");

    PlanBuilder sampled(PlanMode::pruned, 4, 4);
    sampled.create(texture_2d("pair", ResourceFormat::r32f, 2, 1));
    sampled.create(texture_2d("out", ResourceFormat::rgba32f, 1, 1));
    sampled.add(upload_pass("data", "pair", "fixed", {{2, 1, 1}, {{0.0f, 1.0f}}}));
    Pass read = fullscreen("read", "test_shaders/sample.frag", {"out"});
    read.reads = {{"pair", "sorce"}};
    read.uniforms = {
        {"origin", glm::vec3(0.0f)}, {"step", glm::vec3(0.0f)}, {"lod", 0.0f}};
    sampled.add(read);
    sampled.set_output("out");
    EXPECT_EQ(failure(sampled.compile()),
              "pass 'read': sampler 'sorce' is not declared in "
              "gl/shaders/fullscreen.vert + test_shaders/sample.frag");
}

// Reuse on: a second identical frame runs no pass, a changed uniform re-runs its pass
// only, and each image equals, bit for bit, one rendered from scratch by a new executor.
TEST_F(FrameExecutorGl, ReusedPassesLeaveTheImageAFreshRenderWouldGive) {
    using Names = std::vector<std::string>;
    // The closed sphere by facing (auto) and by peeling: each reuse must leave the image
    // a fresh executor renders.
    for (const std::string method : {"auto", "peel"}) {
        const bool peel = method == "peel";
        const auto scene_with = [&](std::vector<KnobAssignment> settings) {
            RenderRequest request;
            request.mesh = "sphere:2k";
            request.settings = std::move(settings);
            request.settings.push_back({"layer_method", method});
            request.width = 48;
            request.height = 40;
            return build_scene(request);
        };
        const auto fresh = [](const Scene& scene) {
            gl::FrameExecutor executor;
            return executor.render(
                scene, make_frame_plan(scene, find_technique(scene.technique)));
        };
        const auto ran = [](const gl::FrameExecutor& executor) {
            Names names;
            for (const auto& t : executor.last_timings().passes)
                if (!t.cached) names.push_back(t.pass);
            return names;
        };
        gl::FrameExecutor executor;
        executor.set_reuse_unchanged_passes(true);
        const Scene first = scene_with({});
        const FramePlan first_plan = make_frame_plan(first, find_technique("empirical"));
        executor.execute(first, first_plan, /*time_passes=*/true);
        EXPECT_EQ(ran(executor).size(), first_plan.passes.size()) << method;
        const Image reference = fresh(first);
        EXPECT_EQ(executor.read_output(first_plan).rgba, reference.rgba) << method;

        executor.execute(first, make_frame_plan(first, find_technique("empirical")),
                         true);
        EXPECT_EQ(ran(executor), Names{}) << method;
        EXPECT_EQ(executor.last_timings().passes.size(), first_plan.passes.size());
        EXPECT_EQ(executor.read_output(first_plan).rgba, reference.rgba) << method;

        for (const auto& [settings, expected] :
             std::vector<std::pair<std::vector<KnobAssignment>, Names>>{
                 {{{"shininess", "40"}}, {"shade"}},
                 // By facing, `shade` smooths: the kernel re-runs it alone.
                 {{{"shininess", "40"}, {"blur_kernel", "3"}},
                  peel ? Names{"smooth_back_layer", "shade"} : Names{"shade"}},
                 {{{"shininess", "40"}, {"blur_kernel", "3"}, {"backlight", "0"}},
                  {"shade"}},
                 // Back on: the layers' textures were freed with the plan that lacked
                 // them.
                 {{{"shininess", "40"}, {"blur_kernel", "3"}},
                  peel
                      ? Names{"front_depth", "second_layer", "smooth_back_layer", "shade"}
                      : Names{"second_layer", "shade"}}}) {
            const Scene scene = scene_with(settings);
            const FramePlan plan = make_frame_plan(scene, find_technique("empirical"));
            executor.execute(scene, plan, true);
            EXPECT_EQ(ran(executor), expected) << method << " " << settings.back().key;
            EXPECT_EQ(executor.read_output(plan).rgba, fresh(scene).rgba)
                << method << " " << settings.back().key;
        }
    }
}

}  // namespace
}  // namespace lucent
