// The path technique's plan: its image is made on the CPU, so the plan is one upload of
// the traced image (a bake: batch renders trace before their GL workers, the explorer in
// the background) and that image is the output. Its content hash is the scene's, so an
// unchanged scene is not traced again.
#include <cstdio>

#include "common/content_hash.h"
#include "renderer/techniques/path/path.h"

namespace lucent::path {
namespace {

std::string scene_hash(const Scene& scene, bool full) {
    common::ContentHash hash;
    hash.field(scene.mesh->content_hash).field(scene.technique);
    if (scene.density) hash.field(scene.density->content_hash);
    for (const Knob& knob : path::knobs())
        hash.field(knob.name).field(format_knob_value(scene.values.get(knob.name)));
    const glm::mat4 view = scene.camera.view(), projection = scene.camera.projection();
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            hash.float_bits(view[i][j]).float_bits(projection[i][j]);
    for (const glm::vec3 v : {scene.light.ambient, scene.light.diffuse,
                              scene.light.direction, scene.background})
        hash.float_bits(v.x).float_bits(v.y).float_bits(v.z);
    hash.word(std::uint32_t(scene.width)).word(std::uint32_t(scene.height)).word(full);
    return "path-" + hash.hex();
}

std::string purpose(const Scene& scene, const Params& p, bool full) {
    std::string text = "volumetric path tracing on the CPU: " + std::to_string(p.paths) +
                       " paths per pixel and channel, per-channel walks";
    const std::vector<std::string> taken =
        full ? std::vector<std::string>{} : shortcuts_taken(scene, p);
    text += taken.empty() ? "; no shortcuts" : "; shortcuts:";
    for (std::size_t i = 0; i < taken.size(); ++i) text += (i ? ", " : " ") + taken[i];
    return text;
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan) {
    const Params p = params(scene);
    const bool full = plan.full();
    plan.create("path_image", ResourceFormat::rgba32f);
    Pass trace{"path_trace", purpose(scene, p, full), PassKind::upload};
    trace.writes = {"path_image"};
    trace.data.content_hash = scene_hash(scene, full);
    trace.data.cost = ProductionCost::bake;
    trace.data.produce = [scene, full](const ProduceOptions& options) {
        TraceOptions trace_options;
        trace_options.full = full;
        trace_options.produce = options;
        const Image image = render_path(scene, trace_options).mean;
        // Texture rows start at the bottom (GL's t = 0); the image's at the top.
        TextureData data;
        data.size = {image.width, image.height, 1};
        std::vector<float> texels(image.rgba.size());
        const std::size_t row_floats = std::size_t(image.width) * 4;
        for (int row = 0; row < image.height; ++row)
            std::copy_n(&image.rgba[std::size_t(image.height - 1 - row) * row_floats],
                        row_floats, &texels[std::size_t(row) * row_floats]);
        data.levels = {std::move(texels)};
        return data;
    };
    plan.add(trace);
    plan.set_output("path_image");
}

}  // namespace lucent::path
