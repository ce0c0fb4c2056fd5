#pragma once
// The thick_texture technique: David-Babin's semi-transparent textures of opaque and
// transparent texels with a thickness (seed 002, MSc 2022). What the knobs, the GL passes
// and the CPU reference share. Conventions (README.md beside this file): texel (i, j) has
// i along +u ("right"), j along +v ("top", GL row order); thickness h in level-0 texels;
// r = h (d.T, d.B) / |d.N| with d the propagation direction (eye -> fragment).
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"

namespace lucent::thick_texture {

// [SECTION] Binary textures (texture.cpp)

// A tile of texels, repeated over the sheet: opaque or a hole, and the top colour c1 of
// the opaque ones (linear rgb; the knob's colour where the texture has none).
struct TexelGrid {
    int width = 0, height = 0;
    std::vector<std::uint8_t> opaque;  // 1 opaque, 0 hole; row j = 0 is v = 0
    std::vector<glm::vec3> colour;     // one per texel (holes: unused)
    bool coloured = false;         // the texture gives colours (weave, curtain, files)
    bool at(int i, int j) const {  // wraps (the sheet repeats the tile)
        i %= width, j %= height;
        if (i < 0) i += width;
        if (j < 0) j += height;
        return opaque[std::size_t(j) * width + i] != 0;
    }
    glm::vec3 colour_at(int i, int j) const;
    double hole_fraction() const;
};

// Parses a texture spec: net:H,W (square holes of H texels, walls of W), stripes:H,W
// (columns), checker, random:P,SEED (P = hole probability), weave:T,G (threads T, gaps
// G, two thread colours), curtain:SEED (irregular coloured holes), or an image file
// (alpha < 0.5 = hole, colour = top colour; 8-bit files are sRGB). Procedural tiles are
// a whole number of periods, period x 2^k >= 256 texels, so every mip level up to k is an
// exact box mean. Throws KnobError "texture: ..." naming the spec or file.
TexelGrid make_texel_grid(const std::string& spec, glm::vec3 knob_colour);

// [SECTION] Per-texel records and their pyramid (pyramid.cpp)

// The 9 values of Sec. 3.4 per level-0 texel (our neighbour rule for the triangles, see
// README): walls (top, left, bottom, right), triangles (TR, TL, BL, BR) in 0..2, opaque.
struct TexelRecord {
    glm::dvec4 walls{0.0};
    glm::dvec4 triangles{0.0};
    double opaque = 0.0;
    glm::dvec3 premultiplied{0.0};  // c1 * opaque
    // Wide-hole fix: run-length histograms per direction (R, L, U, D), bin k = number of
    // transparent texels between this one and the first opaque one (last bin: >= K-1).
    std::array<std::vector<double>, 4> bins;
};

// Level-0 records of a tile (with `bins` > 1: histograms of K = bins).
std::vector<TexelRecord> level0_records(const TexelGrid& grid, int bins);
// Every level of the pyramid as averages (sum of the covered level-0 records / their
// count): level l+1 texel = mean of its 2x2 footprint in level l, widened to 3 at the
// last row / column of an odd level, as renderer/gl's box mip. Level 0 first.
struct RecordPyramid {
    std::vector<glm::ivec2> sizes;
    std::vector<std::vector<TexelRecord>> levels;
};
RecordPyramid build_pyramid(const TexelGrid& grid, int bins);

// [SECTION] The model (model.cpp)

// Occluded / opaque / transparent fractions of a texel record (averages: T = 1).
struct Fractions {
    double opaque = 0.0, occluded = 0.0, transparent = 1.0;
};
// Algorithm 3.1 corrected: |r| and the facing walls, a = min(|rx|, 1), b = min(|ry|, 1),
// O clamped to [0, 1 - opaque]. With record.bins non-empty: the wide-hole fix (hybrid:
// O + P(A) - P(A0)).
Fractions model_fractions(const TexelRecord& record, glm::dvec2 r);
// r for a propagation direction in the tangent frame (d.T, d.B, d.N), finite at grazing
// angles: each component's magnitude is capped at `cap` texels.
glm::dvec2 scaled_ray(glm::dvec3 d_tangent, double thickness, double cap = 64.0);

// [SECTION] Exact traversal (traversal.cpp)

// What a ray entering the top of the slab at texel position p (level-0 texel units,
// continuous) with tangent displacement r over the thickness sees: the top of an opaque
// texel, a wall (the first opaque texel its 2D Amanatides-Woo walk enters before the
// bottom), or nothing (through). `steps` reports the texels visited.
enum class SlabHit { top, wall, through };
SlabHit trace_slab(const TexelGrid& grid, glm::dvec2 p, glm::dvec2 r,
                   int* steps = nullptr);
// The wall texel's colour is needed for colour_source = texture: the texel it entered.
SlabHit trace_slab(const TexelGrid& grid, glm::dvec2 p, glm::dvec2 r, glm::ivec2& texel,
                   int* steps = nullptr);
// Exact fractions over one whole tile: S x S entry points per texel (offset so none lies
// on a texel diagonal), each traced. For tests and the bench.
Fractions exact_fractions(const TexelGrid& grid, glm::dvec2 r, int samples_per_axis);

// [SECTION] Knobs (knobs.cpp)

struct Params {
    std::string texture = "net:5,1";
    double thickness = 1.0;            // h, level-0 texels, [0, 64]
    double texel_density = 96.0;       // level-0 texels per uv unit, [1, 8192]
    double tilt = 0.0;                 // degrees about the vertical axis, [0, 89]
    double azimuth = 0.0;              // degrees the sheet spins about its normal first
    std::string filter = "trilinear";  // nearest | linear | bilinear | trilinear
    std::string fetch_path = "hardware";  // hardware (3 fetches) | thesis (32)
    int wide_hole_bins = 1;               // K: 1 = the thesis's method, 4 or 8 = the fix
    int layers = 2;                       // depth-peeled sheet layers, [1, 4]
    glm::dvec3 top_colour{0.85, 0.82, 0.75};
    glm::dvec3 wall_colour{0.35, 0.33, 0.3};
    std::string colour_source = "texture";  // texture | knob (c1)
    std::string backdrop = "checker";       // checker | stripes | plain
    glm::dvec3 backdrop_a{0.9, 0.2, 0.15};
    glm::dvec3 backdrop_b{0.1, 0.15, 0.5};
    double backdrop_period = 0.2;  // mesh units on the backdrop plane
    int reference_rays = 256;      // per pixel, n x n stratified
    bool operator==(const Params&) const = default;
};
const std::vector<Knob>& knobs();
Params params(const Scene& scene);
// The texture of the scene's knobs (cached by spec and colour).
const TexelGrid& scene_texture(const Params& p);

// [SECTION] Scene geometry shared by GL and the reference

// Object -> object rotation of the sheet about the bounding-sphere centre (azimuth about
// +Z, then tilt about +Y), as a 4x4 model matrix.
glm::dmat4 model_matrix(const Scene& scene, const Params& p);
// The backdrop: a plane perpendicular to the view axis at this eye-space distance.
double backdrop_distance(const Scene& scene);
// Colour of the backdrop where an eye-space direction (z < 0) meets it.
glm::dvec3 backdrop_colour(const Params& p, const Scene& scene, glm::dvec3 eye_direction);

// Throws MeshError "NAME: has no texture coordinates, ..." for a mesh without UVs (the
// planner, the reference and build_scene's check all call it).
void require_uvs(const Mesh& mesh);

// Which variant the planner picks (GL and --explain): thin alpha (h = 0), opaque (no
// hole), empty (no opaque texel), or thick.
enum class Variant { thin_alpha, opaque, empty, thick };
Variant variant_of(const Params& p, const TexelGrid& grid);

void add_passes(const Scene& scene, PlanBuilder& plan);
Image render_reference(const Scene& scene);

}  // namespace lucent::thick_texture
