// What the thick_texture technique adds to a frame plan (David-Babin Sec. 3.5):
//   albedo            CPU pyramid: premultiplied c1 average, rho_op      -> albedo
//   walls, triangles  CPU pyramids of the per-texel counts (averages)   -> walls,
//   triangles bins_*            CPU run-length histograms (wide-hole fix, K > 1)   ->
//   bins_r0 ... layer_0..L-1      the sheet, depth peeled: premultiplied colour     ->
//   layer_k_colour composite         layers front to back over the backdrop            ->
//   colour
// Exact prunes: h = 0 or a texture without opaque texels -> plain alpha texturing (no
// walls, triangles, tangents); a texture without holes -> the same opaque draw, one
// layer; a flat mesh -> one layer. In full mode the thick shader runs with every layer.
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

Sampling sampling_of(const std::string& filter) {
    Sampling s;
    s.wrap = Wrap::repeat;
    s.filter = filter == "bilinear" || filter == "trilinear" ? TexelFilter::linear
                                                             : TexelFilter::nearest;
    s.mip = filter == "linear" || filter == "trilinear" ? MipFilter::linear
                                                        : MipFilter::nearest;
    return s;
}

bool is_flat(const Mesh& mesh) {
    if (mesh.normals.empty()) return true;
    const glm::vec3 n0 = mesh.normals.front();
    for (const glm::vec3& n : mesh.normals)
        if (glm::dot(n, n0) < 1.0f - 1e-6f) return false;
    // Equal normals on a connected sheet: every vertex on one plane as well.
    const glm::vec3 p0 = mesh.positions.front();
    const float scale = std::max(mesh.bounding_sphere().radius, 1e-6f);
    for (const glm::vec3& p : mesh.positions)
        if (std::abs(glm::dot(p - p0, n0)) > 1e-5f * scale) return false;
    return true;
}

// One pyramid channel group as TextureData (every level supplied).
template <typename Texel>
TextureData pyramid_texels(const RecordPyramid& pyramid, Texel texel) {
    TextureData data;
    data.size = {pyramid.sizes[0].x, pyramid.sizes[0].y, 1};
    for (const auto& level : pyramid.levels) {
        std::vector<float> values;
        values.reserve(level.size() * 4);
        for (const TexelRecord& r : level) {
            const glm::dvec4 v = texel(r);
            for (int c = 0; c < 4; ++c) values.push_back(float(v[c]));
        }
        data.levels.push_back(std::move(values));
    }
    return data;
}

std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan) {
    require_uvs(*scene.mesh);  // the explorer plans without build_scene's check
    const Params p = params(scene);
    const TexelGrid& grid = scene_texture(p);
    const Variant variant = variant_of(p, grid);
    const bool full = plan.full();
    const bool thick = full || variant == Variant::thick;
    // The wide-hole bins join the fast path only (the thesis path is the thesis's
    // method).
    const int bins = thick && p.fetch_path != "thesis" ? p.wide_hole_bins : 1;
    const bool flat = is_flat(*scene.mesh);
    const int layers =
        full ? p.layers : (variant == Variant::opaque || flat ? 1 : p.layers);
    const Sampling sampling = sampling_of(p.filter);

    // The CPU pyramid, built once per plan and only when an upload asks for it.
    struct Lazy {
        const TexelGrid* grid;
        int bins;
        std::once_flag once;
        RecordPyramid pyramid;
        const RecordPyramid& get() {
            std::call_once(once, [&] { pyramid = build_pyramid(*grid, bins); });
            return pyramid;
        }
    };
    auto lazy = std::make_shared<Lazy>();
    lazy->grid = &grid;  // scene_texture() keeps every texture for the process
    lazy->bins = bins;
    const std::string hash = p.texture + "|" + p.colour_source + "|" +
                             number(p.top_colour.r) + "," + number(p.top_colour.g) + "," +
                             number(p.top_colour.b) + "|" + std::to_string(grid.width) +
                             "x" + std::to_string(grid.height);
    const auto upload = [&](const std::string& name, const std::string& purpose,
                            std::function<glm::dvec4(const TexelRecord&)> texel) {
        plan.create(
            texture_2d(name, ResourceFormat::rgba32f, grid.width, grid.height, 0));
        Pass pass{name, purpose, PassKind::upload};
        pass.writes = {name};
        pass.data = {hash + "|" + name + "|k" + std::to_string(bins),
                     [lazy, texel](const ProduceOptions&) {
                         return pyramid_texels(lazy->get(), texel);
                     }};
        plan.add(pass);
    };
    upload("albedo",
           "pyramid: premultiplied top colour c1 * rho_op and rho_op (averages)",
           [](const TexelRecord& r) { return glm::dvec4(r.premultiplied, r.opaque); });
    std::vector<Read> texture_reads = {{"albedo", "", sampling}};
    if (thick) {
        upload("walls", "pyramid: walls top, left, bottom, right (Sec. 3.4, averages)",
               [](const TexelRecord& r) { return r.walls; });
        upload("triangles", "pyramid: corner triangles TR, TL, BL, BR (0..2, averages)",
               [](const TexelRecord& r) { return r.triangles; });
        texture_reads.push_back({"walls", "", sampling});
        texture_reads.push_back({"triangles", "", sampling});
        if (bins > 1) {
            const char* directions[4] = {"r", "l", "u", "d"};
            for (int d = 0; d < 4; ++d)
                for (int g = 0; g < bins / 4; ++g) {
                    const std::string name =
                        std::string("bins_") + directions[d] + std::to_string(g);
                    upload(name,
                           "pyramid: run-length bins " + std::to_string(4 * g) + ".." +
                               std::to_string(4 * g + 3) + " towards " + directions[d] +
                               " (wide-hole fix)",
                           [d, g](const TexelRecord& r) {
                               return glm::dvec4(r.bins[d][4 * g], r.bins[d][4 * g + 1],
                                                 r.bins[d][4 * g + 2],
                                                 r.bins[d][4 * g + 3]);
                           });
                    texture_reads.push_back({name,
                                             std::string("bins_") + directions[d] + "[" +
                                                 std::to_string(g) + "]",
                                             sampling});
                }
        }
    }

    const glm::mat4 model_view = scene.camera.view() * glm::mat4(model_matrix(scene, p));
    const float uv_scale = float(p.texel_density);
    std::vector<std::string> defines;
    if (!thick) defines.push_back("THIN");
    if (thick && p.fetch_path == "thesis") {
        defines.push_back("THESIS_PATH");
        if (sampling.filter == TexelFilter::linear)
            defines.push_back("FILTER_TEXEL_LINEAR");
        if (sampling.mip == MipFilter::linear) defines.push_back("FILTER_MIP_LINEAR");
    }
    if (thick && bins > 1 && p.fetch_path != "thesis")
        defines.push_back("BINS " + std::to_string(bins));
    std::string pruned;
    if (!full && variant == Variant::thin_alpha)
        pruned = "; pruned: walls and triangles (h = 0: plain alpha texture)";
    if (!full && variant == Variant::empty)
        pruned = "; pruned: walls and triangles (no opaque texel: nothing occludes)";
    if (!full && variant == Variant::opaque)
        pruned = "; pruned: walls, triangles and layers behind (no hole: opaque draw)";
    if (!full && flat && layers < p.layers && variant != Variant::opaque)
        pruned += "; pruned: layers behind (flat mesh)";
    for (int k = 0; k < layers; ++k) {
        const std::string colour = "layer_" + std::to_string(k) + "_colour";
        const std::string depth = "layer_" + std::to_string(k) + "_depth";
        plan.create(colour, ResourceFormat::rgba32f);
        plan.create(depth, ResourceFormat::depth32f);
        Pass layer{"layer_" + std::to_string(k),
                   std::string(thick ? "thick texture (Alg. 3.1" : "alpha texture (") +
                       (thick && p.fetch_path == "thesis" ? ", 8 texels x 4 fetches"
                        : thick                           ? ", 3 filtered fetches"
                                                          : "1 fetch") +
                       (bins > 1 ? ", wide-hole bins" : "") + "), sheet layer " +
                       std::to_string(k) + (k == 0 ? pruned : ""),
                   PassKind::draw_mesh,
                   {"techniques/thick_texture/shaders/sheet.vert",
                    "techniques/thick_texture/shaders/layer.frag", defines}};
        layer.reads = texture_reads;
        if (k > 0) {
            layer.shader.defines.push_back("PEEL");
            layer.reads.push_back({"layer_" + std::to_string(k - 1) + "_depth",
                                   "previous_depth",
                                   {TexelFilter::nearest}});
            layer.uniforms.push_back({"u_epsilon", 1e-6f});
        }
        layer.uniforms.push_back({"u_model_view", model_view});
        layer.uniforms.push_back({"u_projection", scene.camera.projection()});
        layer.uniforms.push_back(
            {"u_uv_scale", glm::vec3(uv_scale / float(grid.width),
                                     uv_scale / float(grid.height), 0.0f)});
        if (thick) {
            layer.uniforms.push_back({"u_thickness", float(p.thickness)});
            layer.uniforms.push_back({"u_wall_colour", glm::vec3(p.wall_colour)});
        }
        layer.writes = {colour, depth};
        plan.add(layer);
    }

    plan.create("colour", ResourceFormat::rgba32f);
    Pass composite{
        "composite",
        "layers front to back over the " + p.backdrop + " backdrop (box-filtered)",
        PassKind::fullscreen,
        {"gl/shaders/fullscreen.vert",
         "techniques/thick_texture/shaders/composite.frag",
         {"LAYERS " + std::to_string(layers)}}};
    for (int k = 0; k < layers; ++k)
        composite.reads.push_back({"layer_" + std::to_string(k) + "_colour", ""});
    composite.reads.push_back({"layer_0_depth", ""});
    const double distance = backdrop_distance(scene);
    const double half_height = std::tan(0.5 * double(scene.camera.fov_y_degrees) *
                                        3.14159265358979323846 / 180.0) *
                               distance;
    const double half_width = half_height * double(scene.camera.aspect);
    composite.uniforms = {
        {"u_pixel_scale", glm::vec3(float(2.0 * half_width / scene.width),
                                    float(2.0 * half_height / scene.height), 0.0f)},
        {"u_viewport", glm::vec3(float(scene.width), float(scene.height), 0.0f)},
        {"u_backdrop", p.backdrop == "checker"   ? 0
                       : p.backdrop == "stripes" ? 1
                                                 : 2},
        {"u_backdrop_a", glm::vec3(p.backdrop_a)},
        {"u_backdrop_b", glm::vec3(p.backdrop_b)},
        {"u_period", float(p.backdrop_period)}};
    composite.writes = {"colour"};
    plan.add(composite);
    plan.set_output("colour");
}

}  // namespace lucent::thick_texture
