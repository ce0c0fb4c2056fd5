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

#include "common/number_text.h"
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

std::string number(double value) { return common::nine_digit_text(value); }

// What every stage reads, derived once from the scene and the knobs.
struct FrameInputs {
    FrameInputs(const Scene& scene, bool full);

    const Scene& scene;
    const Params p;
    const TexelGrid& grid;
    const Variant variant;
    const bool full;
    const bool thick;
    // The wide-hole bins join the fast path only (the thesis path is the thesis's
    // method).
    const int bins;
    const bool flat;
    const int layers;
    const Sampling sampling;
};

FrameInputs::FrameInputs(const Scene& scene, bool full)
    : scene(scene),
      p(params(scene)),
      grid(scene_texture(p)),
      variant(variant_of(p, grid)),
      full(full),
      thick(full || variant == Variant::thick),
      bins(thick && p.fetch_path != "thesis" ? p.wide_hole_bins : 1),
      flat(is_flat(*scene.mesh)),
      layers(full ? p.layers : (variant == Variant::opaque || flat ? 1 : p.layers)),
      sampling(sampling_of(p.filter)) {}

// The CPU pyramid, built once per plan and only when an upload asks for it.
struct LazyPyramid {
    const TexelGrid* grid;
    int bins;
    std::once_flag once;
    RecordPyramid pyramid;
    const RecordPyramid& get() {
        std::call_once(once, [&] { pyramid = build_pyramid(*grid, bins); });
        return pyramid;
    }
};

// What every pyramid upload shares: the one lazy pyramid and the texture's content
// hash.
struct PyramidSource {
    std::shared_ptr<LazyPyramid> lazy;
    std::string hash;
};

PyramidSource pyramid_source(const FrameInputs& f) {
    const Params& p = f.p;
    const TexelGrid& grid = f.grid;
    auto lazy = std::make_shared<LazyPyramid>();
    lazy->grid = &grid;  // scene_texture() keeps every texture for the process
    lazy->bins = f.bins;
    const std::string hash = p.texture + "|" + p.colour_source + "|" +
                             number(p.top_colour.r) + "," + number(p.top_colour.g) + "," +
                             number(p.top_colour.b) + "|" + std::to_string(grid.width) +
                             "x" + std::to_string(grid.height);
    return {lazy, hash};
}

// One channel group of the pyramid as an upload pass writing the texture `name`.
void add_pyramid_upload(PlanBuilder& plan, const FrameInputs& f,
                        const PyramidSource& source, const std::string& name,
                        const std::string& purpose,
                        std::function<glm::dvec4(const TexelRecord&)> texel) {
    plan.create(
        texture_2d(name, ResourceFormat::rgba32f, f.grid.width, f.grid.height, 0));
    Pass pass{name, purpose, PassKind::upload};
    pass.writes = {name};
    pass.data = {source.hash + "|" + name + "|k" + std::to_string(f.bins),
                 [lazy = source.lazy, texel](const ProduceOptions&) {
                     return pyramid_texels(lazy->get(), texel);
                 }};
    plan.add(pass);
}

// The run-length histograms of the wide-hole fix, four bins per texture and direction.
void add_wide_hole_bins(PlanBuilder& plan, const FrameInputs& f,
                        const PyramidSource& source, std::vector<Read>& texture_reads) {
    const char* directions[4] = {"r", "l", "u", "d"};
    for (int d = 0; d < 4; ++d)
        for (int g = 0; g < f.bins / 4; ++g) {
            const std::string name =
                std::string("bins_") + directions[d] + std::to_string(g);
            add_pyramid_upload(plan, f, source, name,
                               "pyramid: run-length bins " + std::to_string(4 * g) +
                                   ".." + std::to_string(4 * g + 3) + " towards " +
                                   directions[d] + " (wide-hole fix)",
                               [d, g](const TexelRecord& r) {
                                   return glm::dvec4(
                                       r.bins[d][4 * g], r.bins[d][4 * g + 1],
                                       r.bins[d][4 * g + 2], r.bins[d][4 * g + 3]);
                               });
            texture_reads.push_back(
                {name,
                 std::string("bins_") + directions[d] + "[" + std::to_string(g) + "]",
                 f.sampling});
        }
}

// The CPU pyramids the layers sample; returns the layers' reads of them.
std::vector<Read> add_pyramid_uploads(PlanBuilder& plan, const FrameInputs& f) {
    const PyramidSource source = pyramid_source(f);
    add_pyramid_upload(
        plan, f, source, "albedo",
        "pyramid: premultiplied top colour c1 * rho_op and rho_op (averages)",
        [](const TexelRecord& r) { return glm::dvec4(r.premultiplied, r.opaque); });
    std::vector<Read> texture_reads = {{"albedo", "", f.sampling}};
    if (f.thick) {
        add_pyramid_upload(plan, f, source, "walls",
                           "pyramid: walls top, left, bottom, right (Sec. 3.4, averages)",
                           [](const TexelRecord& r) { return r.walls; });
        add_pyramid_upload(plan, f, source, "triangles",
                           "pyramid: corner triangles TR, TL, BL, BR (0..2, averages)",
                           [](const TexelRecord& r) { return r.triangles; });
        texture_reads.push_back({"walls", "", f.sampling});
        texture_reads.push_back({"triangles", "", f.sampling});
        if (f.bins > 1) add_wide_hole_bins(plan, f, source, texture_reads);
    }
    return texture_reads;
}

// The layer shader's variant: thin or thick, and the thick texture's fetch path.
std::vector<std::string> layer_defines(const FrameInputs& f) {
    std::vector<std::string> defines;
    if (!f.thick) defines.push_back("THIN");
    if (f.thick && f.p.fetch_path == "thesis") {
        defines.push_back("THESIS_PATH");
        if (f.sampling.filter == TexelFilter::linear)
            defines.push_back("FILTER_TEXEL_LINEAR");
        if (f.sampling.mip == MipFilter::linear) defines.push_back("FILTER_MIP_LINEAR");
    }
    if (f.thick && f.bins > 1 && f.p.fetch_path != "thesis")
        defines.push_back("BINS " + std::to_string(f.bins));
    return defines;
}

// What was pruned and why, for the first layer's purpose (--explain).
std::string pruned_note(const FrameInputs& f) {
    std::string pruned;
    if (!f.full && f.variant == Variant::thin_alpha)
        pruned = "; pruned: walls and triangles (h = 0: plain alpha texture)";
    if (!f.full && f.variant == Variant::empty)
        pruned = "; pruned: walls and triangles (no opaque texel: nothing occludes)";
    if (!f.full && f.variant == Variant::opaque)
        pruned = "; pruned: walls, triangles and layers behind (no hole: opaque draw)";
    if (!f.full && f.flat && f.layers < f.p.layers && f.variant != Variant::opaque)
        pruned += "; pruned: layers behind (flat mesh)";
    return pruned;
}

// The sheet, depth peeled front to back: layer k keeps what lies behind layer k - 1.
void add_sheet_layers(PlanBuilder& plan, const FrameInputs& f,
                      const std::vector<Read>& texture_reads) {
    const Scene& scene = f.scene;
    const Params& p = f.p;
    const bool thick = f.thick;
    const glm::mat4 model_view = scene.camera.view() * glm::mat4(model_matrix(scene, p));
    const float uv_scale = float(p.texel_density);
    const std::vector<std::string> defines = layer_defines(f);
    const std::string pruned = pruned_note(f);
    for (int k = 0; k < f.layers; ++k) {
        const std::string colour = "layer_" + std::to_string(k) + "_colour";
        const std::string depth = "layer_" + std::to_string(k) + "_depth";
        plan.create(colour, ResourceFormat::rgba32f);
        plan.create(depth, ResourceFormat::depth32f);
        Pass layer{"layer_" + std::to_string(k),
                   std::string(thick ? "thick texture (Alg. 3.1" : "alpha texture (") +
                       (thick && p.fetch_path == "thesis" ? ", 8 texels x 4 fetches"
                        : thick                           ? ", 3 filtered fetches"
                                                          : "1 fetch") +
                       (f.bins > 1 ? ", wide-hole bins" : "") + "), sheet layer " +
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
            {"u_uv_scale", glm::vec3(uv_scale / float(f.grid.width),
                                     uv_scale / float(f.grid.height), 0.0f)});
        if (thick) {
            layer.uniforms.push_back({"u_thickness", float(p.thickness)});
            layer.uniforms.push_back({"u_wall_colour", glm::vec3(p.wall_colour)});
        }
        layer.writes = {colour, depth};
        plan.add(layer);
    }
}

void add_composite(PlanBuilder& plan, const FrameInputs& f) {
    const Scene& scene = f.scene;
    const Params& p = f.p;
    plan.create("colour", ResourceFormat::rgba32f);
    Pass composite{
        "composite",
        "layers front to back over the " + p.backdrop + " backdrop (box-filtered)",
        PassKind::fullscreen,
        {"gl/shaders/fullscreen.vert",
         "techniques/thick_texture/shaders/composite.frag",
         {"LAYERS " + std::to_string(f.layers)}}};
    for (int k = 0; k < f.layers; ++k)
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
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan) {
    require_uvs(*scene.mesh);  // the explorer plans without build_scene's check
    const FrameInputs f(scene, plan.full());
    const std::vector<Read> texture_reads = add_pyramid_uploads(plan, f);
    add_sheet_layers(plan, f, texture_reads);
    add_composite(plan, f);
    plan.set_output("colour");
}

}  // namespace lucent::thick_texture
