// The thick_texture knobs and the scene geometry the GL path and the reference share
// (the sheet's rotation, the backdrop).
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "renderer/core/knob_binding.h"
#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

constexpr double kPi = 3.14159265358979323846;

Knob texture_knob() {
    Knob texture{"texture",
                 "binary texture: net:H,W (holes H, walls W texels), stripes:H,W, "
                 "checker, random:P,SEED, weave:T,G, curtain:SEED or an image file "
                 "(alpha < 0.5 = hole)",
                 KnobKind::text, 0.0, 0.0};
    // Its meaning (spec or file) is checked by Technique::check_scene, which names
    // the texture; here only that there is one.
    texture.check = [](std::string_view text) -> std::string {
        return text.empty() ? "empty" : "";
    };
    texture.accepted =
        "non-empty text such as net:5,1, weave:2,1, random:0.5,1, curtain:1 or "
        "holes.png";
    return texture;
}

void bind(Params& p, KnobBinder& b) {
    b.knob(p.texture, texture_knob());
    b.knob(p.thickness,
           {"thickness", "h: height of the opaque texels, in level-0 texel widths",
            KnobKind::scalar, 0.0, 64.0});
    b.knob(p.texel_density,
           {"texel_density", "level-0 texels per uv unit (the sheets: per 2 mesh units)",
            KnobKind::scalar, 1.0, 8192.0});
    b.knob(p.tilt, {"tilt",
                    "sheet rotation about the vertical axis, degrees (the viewing angle "
                    "of a flat sheet)",
                    KnobKind::scalar, 0.0, 89.0});
    b.knob(p.azimuth,
           {"azimuth", "sheet rotation about its own normal before the tilt, degrees",
            KnobKind::scalar, -180.0, 180.0});
    b.choice(p.filter, "filter",
             "texture filtering (Fig. 4.6): nearest texel and level, linear = "
             "nearest texel blended across levels, bilinear, trilinear",
             {"nearest", "linear", "bilinear", "trilinear"});
    b.choice(p.fetch_path, "fetch_path",
             "hardware: normalised averages, hardware filtering, 3 fetches; thesis: "
             "Algorithm 3.1 on 8 texels, 32 fetches (Sec. 3.5)",
             {"hardware", "thesis"});
    b.choice(p.wide_hole_bins, "wide_hole_bins",
             "K: 1 = the thesis's neighbour walls only; 4 or 8 = run-length bins per "
             "direction (the future-work fix for holes wider than a texel)",
             {"1", "4", "8"});
    b.knob(p.layers, {"layers", "sheet layers by depth peeling (folds in front of folds)",
                      KnobKind::integer, 1.0, 4.0});
    b.knob(
        p.top_colour,
        {"top_colour", "c1: colour of the opaque texels' tops (textures without colours)",
         KnobKind::rgb, 0.0, 1.0});
    b.knob(p.wall_colour, {"wall_colour", "c2: colour of the hole walls (linear rgb)",
                           KnobKind::rgb, 0.0, 1.0});
    b.choice(p.colour_source, "colour_source",
             "c1 from the texture's colours (weave, curtain, files) or top_colour",
             {"texture", "knob"});
    b.choice(p.backdrop, "backdrop",
             "opaque plane behind the sheet, perpendicular to the view",
             {"checker", "stripes", "plain"});
    b.knob(p.backdrop_a,
           {"backdrop_a", "first backdrop colour (linear rgb)", KnobKind::rgb, 0.0, 1.0});
    b.knob(p.backdrop_b, {"backdrop_b", "second backdrop colour (linear rgb)",
                          KnobKind::rgb, 0.0, 1.0});
    b.knob(p.backdrop_period,
           {"backdrop_period", "backdrop squares / stripes, mesh units", KnobKind::scalar,
            0.001, 100.0});
    b.knob(p.reference_rays,
           {"reference_rays", "CPU reference: rays per pixel (n x n stratified)",
            KnobKind::integer, 1.0, 4096.0});
}

}  // namespace

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = list_knobs<Params>(bind);
    return list;
}

Params params(const Scene& scene) { return read_knobs<Params>(scene.values, bind); }

const TexelGrid& scene_texture(const Params& p) {
    // Textures are small; keep every one asked for (the explorer switches back and
    // forth).
    static std::mutex mutex;
    static std::map<std::string, std::shared_ptr<const TexelGrid>> cache;
    const glm::vec3 colour(p.top_colour);
    const std::string key = p.texture + "|" + p.colour_source + "|" +
                            std::to_string(colour.r) + "," + std::to_string(colour.g) +
                            "," + std::to_string(colour.b);
    std::lock_guard lock(mutex);
    auto& slot = cache[key];
    if (!slot) {
        TexelGrid grid = make_texel_grid(p.texture, colour);
        if (p.colour_source == "knob") {
            grid.coloured = false;
            std::fill(grid.colour.begin(), grid.colour.end(), colour);
        }
        slot = std::make_shared<const TexelGrid>(std::move(grid));
    }
    return *slot;
}

glm::dmat4 model_matrix(const Scene& scene, const Params& p) {
    const glm::dvec3 c(scene.bounds.centre);
    const double t = p.tilt * kPi / 180.0, a = p.azimuth * kPi / 180.0;
    glm::dmat4 spin(1.0), tilt(1.0), to(1.0), back(1.0);
    spin[0] = {std::cos(a), std::sin(a), 0, 0};
    spin[1] = {-std::sin(a), std::cos(a), 0, 0};
    tilt[0] = {std::cos(t), 0, -std::sin(t), 0};
    tilt[2] = {std::sin(t), 0, std::cos(t), 0};
    to[3] = glm::dvec4(c, 1.0);
    back[3] = glm::dvec4(-c, 1.0);
    return to * tilt * spin * back;
}

double backdrop_distance(const Scene& scene) {
    // Behind everything the camera can see of the object: the far side of the bounding
    // sphere plus a margin (the camera sits at one diameter from the centre).
    return double(scene.bounds.diameter()) + 1.5 * double(scene.bounds.radius);
}

glm::dvec3 backdrop_colour(const Params& p, const Scene& scene,
                           glm::dvec3 eye_direction) {
    const glm::dvec3 a = p.backdrop_a, b = p.backdrop_b;
    if (p.backdrop == "plain" || !(eye_direction.z < 0.0)) return a;
    const double distance = backdrop_distance(scene);
    const glm::dvec2 xy = glm::dvec2(eye_direction) * (distance / -eye_direction.z);
    const auto parity = [&](double x) {
        return int(std::floor(x / p.backdrop_period)) & 1;
    };
    const int cell = p.backdrop == "stripes" ? parity(xy.x) : parity(xy.x) ^ parity(xy.y);
    return cell == 0 ? a : b;
}

void require_uvs(const Mesh& mesh) {
    if (!mesh.has_uvs() || mesh.tangents.size() != mesh.positions.size())
        throw MeshError(mesh.name +
                        ": has no texture coordinates, which thick_texture needs (use "
                        "square, wave, drape or a mesh file with UVs)");
}

Variant variant_of(const Params& p, const TexelGrid& grid) {
    const double holes = grid.hole_fraction();
    if (holes == 0.0) return Variant::opaque;
    if (holes == 1.0) return Variant::empty;
    if (p.thickness == 0.0) return Variant::thin_alpha;
    return Variant::thick;
}

}  // namespace lucent::thick_texture
