#pragma once
// The frame plan (Filament's FrameGraph, smaller): a list of passes, each naming the
// resources it reads and writes. A technique adds the passes a scene calls for; compile()
// then culls every pass whose outputs nobody reads, so an effect that is off costs no
// pass and no texture. Pure data, no GL: renderer/gl/frame_executor runs it.
#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <variant>
#include <vector>

namespace lucent {

// Resource formats. Textures are frame-sized; the vertex stream is one float per vertex.
enum class ResourceFormat {
    depth16,
    depth24,
    depth32f,
    r32f,
    rgba32f,
    vertex_float,  // per-vertex attribute at location 2 (ambient occlusion)
};
bool is_depth_format(ResourceFormat format);
const char* format_name(ResourceFormat format);

struct ResourceDesc {
    std::string name;
    ResourceFormat format;
};

enum class PassKind {
    bake_ambient_occlusion,  // CPU: per-vertex AO (cached bake) uploaded as a vertex
                             // stream
    draw_mesh,               // rasterise the mesh: attributes 0 position, 1 normal, 2 AO
    fullscreen,              // one full-screen triangle (gl/shaders/fullscreen.vert)
};

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

// A resource a pass reads; textures are bound to the sampler uniform `sampler` (the
// resource name when empty).
struct Read {
    std::string resource;
    std::string sampler;
};

struct Pass {
    std::string name;     // unique in the plan, e.g. "second_layer"
    std::string purpose;  // one line for --explain
    PassKind kind = PassKind::draw_mesh;
    ShaderDesc shader;
    std::vector<Read> reads;
    std::vector<std::string> writes;  // attachments (depth and/or colour) or the stream
    std::vector<Uniform> uniforms;
    glm::vec4 clear_colour{0.0f};  // colour attachments are cleared to this, depth to 1
    int ao_rays = 0;               // bake_ambient_occlusion only
};

enum class PlanMode {
    pruned,  // simulate only what the scene calls for (the default)
    full,    // every pass of the technique, nothing culled (to check pruning)
};

struct FramePlan {
    int width = 0;
    int height = 0;
    std::vector<ResourceDesc> resources;  // only those the kept passes touch
    std::vector<Pass> passes;             // in execution order
    std::vector<std::string> culled;      // names of passes removed by compile()
    std::string output;                   // the rgba32f image resource

    const ResourceDesc* resource(const std::string& name) const;
    // One pass per line: "name: reads a, b -> writes c  [purpose]", then culled passes.
    std::string explain() const;
};

class PlanBuilder {
public:
    PlanBuilder(PlanMode mode, int width, int height);
    // True for PlanMode::full: techniques then add every pass and enable every term.
    bool full() const { return mode_ == PlanMode::full; }
    void create(std::string name, ResourceFormat format);
    void add(Pass pass);
    void set_output(std::string resource);
    // Checks that every read names a resource written earlier and every write a created
    // resource (std::logic_error otherwise), then culls unread passes (pruned mode).
    FramePlan compile() const;

private:
    PlanMode mode_;
    int width_, height_;
    std::vector<ResourceDesc> resources_;
    std::vector<Pass> passes_;
    std::string output_;
};

// Visits the passes of a plan in order: the one loop every executor (GL, recording test
// executors) shares, so a culled pass is never visited.
void for_each_pass(const FramePlan& plan, const std::function<void(const Pass&)>& visit);

}  // namespace lucent
