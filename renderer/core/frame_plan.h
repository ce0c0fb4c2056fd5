#pragma once
// The frame plan (Filament's FrameGraph, smaller): a list of passes, each naming the
// resources it reads and writes. A technique adds the passes a scene calls for; compile()
// then culls every pass whose outputs nobody reads, so an effect that is off costs no
// pass and no texture. Pure data, no GL: renderer/gl/frame_executor runs it.
//
// Resource/pass model (design notes, with what each coming technique uses, are in
// renderer/core/README.md):
//  - a resource is described once (ResourceDesc): format, shape (frame-sized, fixed 2D,
//    fixed 3D, or a vertex stream: one element per mesh vertex at an attribute
//    location), size, mip levels. Sampler state travels with each Read, not the texture.
//  - a pass writes attachments at one mip level; the viewport is their common size.
//  - CPU-made data (textures and vertex streams alike) is a resource written by an
//    `upload` pass whose DataSource carries a content hash and a producer; the producer
//    runs only when the hash changes, through the executor's UploadProducer hook.
//  - `build_mips` fills levels 1.. of a 2D resource by an exact 2x2 box mean.
//  - names are checked where they are declared: PlanBuilder::add rejects a read or write
//    of a resource no create() declared (or a read before any pass writes it).
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace lucent {

// [SECTION] Resources

// Element formats (float or normalised: shaders read textures with float samplers and
// vertex streams as float attributes).
enum class ResourceFormat {
    depth16,
    depth24,
    depth32f,
    r8,  // normalised [0, 1]: a binary texture, a density stored coarsely
    r32f,
    rg32f,
    rgba8,  // normalised [0, 1]: colour textures
    rgba16f,
    rgba32f,
};
bool is_depth_format(ResourceFormat format);
const char* format_name(ResourceFormat format);
// Floats per texel or vertex (1 for depth).
int format_channels(ResourceFormat format);

enum class ResourceShape {
    frame,     // the plan's width x height (every resource of the first techniques)
    fixed_2d,  // size.x x size.y
    fixed_3d,  // size.x x size.y x size.z (a volume; sampled with sampler3D)
    // size.x elements, one per vertex of the scene's mesh, each format_channels(format)
    // floats (r32f, rg32f or rgba32f), bound at vertex attribute `attribute` of the
    // draw_mesh passes that read it (per-vertex AO, say).
    vertex_stream,
};

struct ResourceDesc {
    std::string name;
    ResourceFormat format;
    ResourceShape shape = ResourceShape::frame;
    glm::ivec3 size{0, 0, 1};  // fixed shapes only; compile() fills it for frame-sized
    // Mip levels, 1 = base only, 0 = the full chain down to 1x1 (compile() resolves 0).
    // Level l is max(1, floor(size / 2^l)) per axis, as in GL.
    int levels = 1;
    // vertex_stream only: the vertex attribute location it is bound to, one the mesh's
    // own attributes leave free (see kMeshAttributes).
    int attribute = -1;
};
// Attribute locations of every mesh's own data in draw_mesh passes: 0 position,
// 1 normal, 3 uv and 4 tangent (meshes with UVs). A vertex stream takes another one.
inline constexpr int kMeshAttributes[] = {0, 1, 3, 4};
// Descriptions for PlanBuilder::create.
ResourceDesc frame_texture(std::string name, ResourceFormat format, int levels = 1);
ResourceDesc texture_2d(std::string name, ResourceFormat format, int width, int height,
                        int levels = 1);
ResourceDesc texture_3d(std::string name, ResourceFormat format, int width, int height,
                        int depth);
ResourceDesc vertex_stream(std::string name, ResourceFormat format, int vertex_count,
                           int attribute);
// Size of `level` of a texture whose level 0 is `base` (2D textures keep z = 1).
glm::ivec3 mip_size(glm::ivec3 base, int level, bool three_d);
// Number of levels of a full chain for `base`.
int full_mip_levels(glm::ivec3 base, bool three_d);

// CPU-made texels for an upload: level 0 first, optionally further levels (a count
// pyramid that is not a box mean). Texels are x fastest, then y, then z, format_channels
// floats each; row y = 0 is the one GL samples at t = 0. A vertex stream's data is one
// level of size {vertices, 1, 1}, vertex i's floats at i * format_channels.
struct TextureData {
    glm::ivec3 size{0, 0, 1};
    std::vector<std::vector<float>> levels;
};
// Describes why `data` cannot fill `desc` (resolved by compile()), or "" when it fits.
std::string check_texture_data(const ResourceDesc& desc, const TextureData& data);

// How a producer is asked to run. The defaults are a frame's: caches allowed, no
// progress report.
struct ProduceOptions {
    // False: do the work itself, bypassing any disk cache (a bench timing the bake, the
    // explorer's re-bake).
    bool use_caches = true;
    // Called now and then with (done, total) by a producer that can tell; may be empty.
    std::function<void(std::size_t, std::size_t)> progress;
};

// How long producing takes, which decides where callers run it (nothing else does).
enum class ProductionCost {
    frame,  // within a frame's budget (tables, atlases, volumes): produced in line
    // Seconds of CPU work (a ray-traced bake, disk-cached): batch renders produce it
    // before their workers, the explorer in the background, benchmarks time it apart
    // from the frame (is_bake()).
    bake,
};

// What an upload pass supplies: equal hashes promise equal texels, so the executor calls
// `produce` (maybe expensive: an atlas bake) only when the hash differs from the one it
// uploaded last for the resource.
struct DataSource {
    std::string content_hash;
    std::function<TextureData(const ProduceOptions&)> produce;
    ProductionCost cost = ProductionCost::frame;
    // Optional, for bakes: cheap data a preview may show instead of waiting for the bake
    // (AO: every vertex open). Never used for an image that is saved or measured.
    std::function<TextureData()> stand_in;
};

// [SECTION] Passes

enum class PassKind {
    draw_mesh,   // rasterise the mesh: its attributes (kMeshAttributes) and the vertex
                 // streams the pass reads
    fullscreen,  // one full-screen triangle (gl/shaders/fullscreen.vert)
    upload,      // CPU data (Pass::data) into the one written resource (texture or
                 // vertex stream)
    build_mips,  // levels 1.. of the one written 2D resource: exact 2x2 box mean of the
                 // level above (reads that same resource)
};
const char* pass_kind_name(PassKind kind);

// Paths relative to renderer/; `defines` select the compiled variant ("NAME" or "NAME
// 5").
struct ShaderDesc {
    std::string vertex;
    std::string fragment;
    std::vector<std::string> defines;
};

using UniformValue = std::variant<int, float, glm::vec3, glm::vec4, glm::mat3, glm::mat4>;
struct Uniform {
    std::string name;
    UniformValue value;
};

// The transforms a mesh vertex stage reads, for a camera or light with this view and
// projection: u_model_view, u_projection and u_normal_matrix (the inverse transpose of
// the view's 3x3, so normals stay perpendicular under non-uniform scale).
std::vector<Uniform> mesh_transform_uniforms(const glm::mat4& view,
                                             const glm::mat4& projection);
// `a` followed by `b`.
std::vector<Uniform> with_uniforms(std::vector<Uniform> a, const std::vector<Uniform>& b);

// Sampler state of one read (GL sampler objects, so two passes may read one texture
// differently). The defaults are the first techniques' texelFetch-like reads.
enum class TexelFilter { nearest, linear };
enum class MipFilter {
    none,     // base level only
    nearest,  // nearest level
    linear,   // blend two levels (with TexelFilter::linear: trilinear)
};
enum class Wrap { clamp_to_edge, repeat, clamp_to_border };
struct Sampling {
    TexelFilter filter = TexelFilter::nearest;
    MipFilter mip = MipFilter::none;
    Wrap wrap = Wrap::clamp_to_edge;
    glm::vec4 border{0.0f};  // Wrap::clamp_to_border only
};
std::string describe(
    const Sampling& sampling);  // "nearest clamp", "linear/linear border"

// A resource a pass reads; textures are bound to the sampler uniform `sampler` (the
// resource name when empty), vertex streams to their attribute location.
struct Read {
    std::string resource;
    std::string sampler;
    Sampling sampling{};
};

// How a pass combines its fragments with its colour attachments.
enum class Blend {
    none,                 // replace
    additive,             // dst + src (accumulate samples or lights)
    premultiplied_over,   // src + (1 - src.a) dst (layers drawn back to front)
    premultiplied_under,  // (1 - dst.a) src + dst (layers drawn front to back)
};

// Which rasterised triangles a mesh pass drops by their facing (counter-clockwise as seen
// = front). Only valid where the mesh bounds a solid facing out (Mesh::closed_facing_out)
// and the camera is outside it: then the nearest surface faces the viewer and the one
// behind it faces away, so a pass that wants either needs only that facing.
enum class FaceCulling {
    none,   // both facings count as layers, as ray hits do
    back,   // keep front faces: the nearest surface
    front,  // keep back faces: the surface behind the nearest (a closed mesh's exit)
};

struct Pass {
    std::string name;     // unique in the plan, e.g. "second_layer"
    std::string purpose;  // one line for --explain
    PassKind kind = PassKind::draw_mesh;
    ShaderDesc shader;
    std::vector<Read> reads;
    std::vector<std::string> writes;  // attachments (depth and/or colour), or uploaded
    std::vector<Uniform> uniforms;
    glm::vec4 clear_colour{0.0f};  // colour attachments are cleared to this, depth to 1
    int level = 0;                 // the mip level the attachments are written at
    // False: keep the attachments' contents (compositing onto an earlier pass's output;
    // the attachments then count as read too).
    bool clear = true;
    Blend blend = Blend::none;
    FaceCulling cull = FaceCulling::none;  // draw_mesh only
    DataSource data;                       // upload only
};

// An upload whose producer is a bake (ProductionCost::bake).
bool is_bake(const Pass& pass);

// Produces an upload pass's data when an executor must upload it (its content hash
// differs from the resource's last upload). Executors call it for every upload, so a
// caller sees all CPU-made data without knowing what it is: to time it (benchmarks,
// batch renders), hand over data produced ahead or in the background (by content hash),
// or show a stand-in. The default, produce_upload, calls pass.data.produce({}).
using UploadProducer = std::function<TextureData(const Pass& upload)>;
TextureData produce_upload(const Pass& upload);

enum class PlanMode {
    pruned,  // simulate only what the scene calls for (the default)
    full,    // every pass of the technique, nothing culled (to check pruning)
};

struct FramePlan {
    int width = 0;
    int height = 0;
    std::vector<ResourceDesc> resources;  // only those the kept passes touch, resolved
    std::vector<Pass> passes;             // in execution order
    std::vector<std::string> culled;      // names of passes removed by compile()
    std::string output;                   // the rgba32f image resource

    const ResourceDesc* resource(const std::string& name) const;
    // Size of `pass`'s attachments (its viewport); compile() checked that they agree.
    glm::ivec2 viewport(const Pass& pass) const;
    // The resources, one per line ("resource name: 64x48 rgba32f, 7 levels"), then one
    // pass per line: "name: reads a, b -> writes c  [purpose]", then culled passes.
    std::string explain() const;
};

class PlanBuilder {
public:
    PlanBuilder(PlanMode mode, int width, int height);
    // True for PlanMode::full: techniques then add every pass and enable every term.
    bool full() const { return mode_ == PlanMode::full; }
    void create(std::string name, ResourceFormat format);  // frame-sized, one level
    void create(ResourceDesc desc);
    void set_output(std::string resource);
    // Keeps the passes that produce `resource` as if it were the output too, for a view
    // of an intermediate layer (the explorer's depth views). A resource that no pass
    // writes keeps nothing.
    void also_keep(std::string resource);
    // Checks the rest (std::logic_error naming the pass or resource otherwise): a pass's
    // attachments agree in size at its level, upload and build_mips passes write exactly
    // one fitting resource, only draw_mesh passes read vertex streams, sizes are
    // positive. Then culls unread passes (pruned mode).
    FramePlan compile() const;
    // Checks the names where they are declared (std::logic_error, one line naming the
    // pass and the name): every read names a created resource an earlier pass writes,
    // every write a created resource, and the name is new.
    void add(Pass pass);

private:
    PlanMode mode_;
    int width_, height_;
    std::vector<ResourceDesc> resources_;
    std::vector<Pass> passes_;
    std::string output_;
    std::vector<std::string> also_keep_;
    std::vector<std::string> written_;  // by the passes added so far
};

// Visits the passes of a plan in order: the one loop every executor (GL, recording test
// executors) shares, so a culled pass is never visited.
void for_each_pass(const FramePlan& plan, const std::function<void(const Pass&)>& visit);

}  // namespace lucent
