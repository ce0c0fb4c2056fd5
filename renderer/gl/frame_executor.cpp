#include "renderer/gl/frame_executor.h"

#include <algorithm>
#include <chrono>
#include <set>
#include <stdexcept>

#include "renderer/core/pass_reuse.h"
#include "renderer/gl/errors.h"
#include "renderer/gl/program.h"
#include "renderer/gl/readback.h"

namespace lucent::gl {
namespace {

GLenum internal_format(ResourceFormat format) {
    switch (format) {
        case ResourceFormat::depth16:
            return GL_DEPTH_COMPONENT16;
        case ResourceFormat::depth24:
            return GL_DEPTH_COMPONENT24;
        case ResourceFormat::depth32f:
            return GL_DEPTH_COMPONENT32F;
        case ResourceFormat::r8:
            return GL_R8;
        case ResourceFormat::r32f:
            return GL_R32F;
        case ResourceFormat::rg32f:
            return GL_RG32F;
        case ResourceFormat::rgba8:
            return GL_RGBA8;
        case ResourceFormat::rgba16f:
            return GL_RGBA16F;
        case ResourceFormat::rgba32f:
            return GL_RGBA32F;
    }
    throw std::logic_error("not a texture format");
}

// Client format of `channels` floats per texel.
GLenum pixel_format(ResourceFormat format) {
    if (is_depth_format(format)) return GL_DEPTH_COMPONENT;
    switch (format_channels(format)) {
        case 1:
            return GL_RED;
        case 2:
            return GL_RG;
        default:
            return GL_RGBA;
    }
}

GLenum min_filter(const Sampling& s) {
    const bool linear = s.filter == TexelFilter::linear;
    switch (s.mip) {
        case MipFilter::none:
            return linear ? GL_LINEAR : GL_NEAREST;
        case MipFilter::nearest:
            return linear ? GL_LINEAR_MIPMAP_NEAREST : GL_NEAREST_MIPMAP_NEAREST;
        case MipFilter::linear:
            return linear ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST_MIPMAP_LINEAR;
    }
    return GL_NEAREST;
}

GLenum wrap_mode(Wrap wrap) {
    switch (wrap) {
        case Wrap::clamp_to_edge:
            return GL_CLAMP_TO_EDGE;
        case Wrap::repeat:
            return GL_REPEAT;
        case Wrap::clamp_to_border:
            return GL_CLAMP_TO_BORDER;
    }
    return GL_CLAMP_TO_EDGE;
}

std::string sampler_key(const Sampling& s) {
    return describe(s) + "/" + std::to_string(s.border.r) + "," +
           std::to_string(s.border.g) + "," + std::to_string(s.border.b) + "," +
           std::to_string(s.border.a);
}

bool same_storage(const ResourceDesc& a, const ResourceDesc& b) {
    return a.format == b.format && a.shape == b.shape && a.size == b.size &&
           a.levels == b.levels;
}

std::string program_key(const ShaderDesc& shader) {
    std::string key = shader.vertex + "|" + shader.fragment;
    for (const auto& d : shader.defines) key += "|" + d;
    return key;
}

bool is_stream(const ResourceDesc& desc) {
    return desc.shape == ResourceShape::vertex_stream;
}

// A linked pass program and what its source declares, to tell a name that is inactive in
// this variant (compiled out by a define, or optimised away) from one the shaders lack.
struct PassProgram {
    Program program;
    std::string stages;              // "a.vert + b.frag", for errors
    std::set<std::string> uniforms;  // declared in either stage
    std::set<int> vertex_inputs;     // attribute locations the vertex stage declares
};

// The location of `name` (a uniform or sampler the pass sets), -1 when inactive in this
// variant; a name the shaders do not declare at all fails the pass, naming both.
GLint uniform_location(const PassProgram& program, const Pass& pass,
                       const std::string& name, const char* what) {
    const GLint location = glGetUniformLocation(program.program.id(), name.c_str());
    if (location >= 0) return location;
    const std::string declared = name.substr(0, name.find_first_of("[."));
    if (!program.uniforms.count(declared))
        throw std::logic_error("pass '" + pass.name + "': " + what + " '" + name +
                               "' is not declared in " + program.stages);
    return -1;
}

void set_uniform(const PassProgram& pass_program, const Pass& pass,
                 const Uniform& uniform) {
    const GLuint program = pass_program.program.id();
    const GLint location = uniform_location(pass_program, pass, uniform.name, "uniform");
    if (location < 0) return;  // inactive in this variant: the compiler removed it
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, int>)
                glProgramUniform1i(program, location, v);
            else if constexpr (std::is_same_v<T, float>)
                glProgramUniform1f(program, location, v);
            else if constexpr (std::is_same_v<T, glm::vec3>)
                glProgramUniform3fv(program, location, 1, &v[0]);
            else if constexpr (std::is_same_v<T, glm::vec4>)
                glProgramUniform4fv(program, location, 1, &v[0]);
            else if constexpr (std::is_same_v<T, glm::mat3>)
                glProgramUniformMatrix3fv(program, location, 1, GL_FALSE, &v[0][0]);
            else
                glProgramUniformMatrix4fv(program, location, 1, GL_FALSE, &v[0][0]);
        },
        uniform.value);
}

// Passes timed by wall clock: CPU work (producing and uploading data).
bool cpu_pass(PassKind kind) { return kind == PassKind::upload; }

}  // namespace

struct FrameExecutor::Impl {
    struct FrameTexture {
        ResourceDesc desc;  // resolved by compile(): size and levels are final
        Texture texture;
        std::string uploaded_hash;  // content hash of the last upload into it
        int width() const { return desc.size.x; }
        int height() const { return desc.size.y; }
    };
    // A vertex stream: a buffer of desc.size.x vertices, filled by its upload pass and
    // bound at desc.attribute of the mesh passes that read it.
    struct VertexStream {
        ResourceDesc desc;
        Buffer buffer;
        std::string uploaded_hash;
    };
    // Mesh buffers, re-uploaded when the mesh changes (compared by content hash + size).
    std::string mesh_key;
    Buffer positions, normals, indices;
    Buffer uvs, tangents;  // attributes 3 and 4, only for meshes with UVs
    GLsizei index_count = 0;
    std::size_t vertex_count = 0;
    VertexArray mesh_vao;
    VertexArray empty_vao;  // full-screen passes draw without attributes
    std::map<std::string, FrameTexture> textures;
    std::map<std::string, VertexStream> streams;
    std::map<std::string, Sampler> samplers;  // by sampler_key
    std::size_t uploads = 0;
    PassReuse reuse;
    bool reuse_enabled = false;
    std::map<std::string, PassProgram> programs;
    std::vector<Query> queries;
    UploadProducer producer = produce_upload;

    void upload_mesh(const Mesh& mesh) {
        const std::string key = mesh.content_hash + "/" +
                                std::to_string(mesh.vertex_count()) + "/" +
                                std::to_string(mesh.face_count()) + "/" + mesh.name;
        if (key == mesh_key) return;
        if (mesh.normals.size() != mesh.positions.size())
            throw std::runtime_error("mesh '" + mesh.name +
                                     "': normals and positions differ in count");
        positions = make_buffer(
            mesh.positions.data(),
            static_cast<GLsizeiptr>(mesh.positions.size() * sizeof(glm::vec3)));
        normals =
            make_buffer(mesh.normals.data(),
                        static_cast<GLsizeiptr>(mesh.normals.size() * sizeof(glm::vec3)));
        indices = make_buffer(
            mesh.triangles.data(),
            static_cast<GLsizeiptr>(mesh.triangles.size() * sizeof(glm::uvec3)));
        index_count = static_cast<GLsizei>(mesh.triangles.size() * 3);
        vertex_count = mesh.vertex_count();
        mesh_vao = make_vertex_array();
        const GLuint vao = mesh_vao.id();
        glVertexArrayVertexBuffer(vao, 0, positions.id(), 0, sizeof(glm::vec3));
        glVertexArrayVertexBuffer(vao, 1, normals.id(), 0, sizeof(glm::vec3));
        for (GLuint i = 0; i < 2; ++i) {
            glEnableVertexArrayAttrib(vao, i);
            glVertexArrayAttribFormat(vao, i, 3, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, i, i);
        }
        if (mesh.has_uvs() && mesh.tangents.size() == mesh.positions.size()) {
            // Texture coordinates (3) and tangents with handedness (4).
            uvs =
                make_buffer(mesh.uvs.data(),
                            static_cast<GLsizeiptr>(mesh.uvs.size() * sizeof(glm::vec2)));
            tangents = make_buffer(
                mesh.tangents.data(),
                static_cast<GLsizeiptr>(mesh.tangents.size() * sizeof(glm::vec4)));
            glVertexArrayVertexBuffer(vao, 3, uvs.id(), 0, sizeof(glm::vec2));
            glVertexArrayVertexBuffer(vao, 4, tangents.id(), 0, sizeof(glm::vec4));
            glEnableVertexArrayAttrib(vao, 3);
            glVertexArrayAttribFormat(vao, 3, 2, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, 3, 3);
            glEnableVertexArrayAttrib(vao, 4);
            glVertexArrayAttribFormat(vao, 4, 4, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, 4, 4);
        }
        glVertexArrayElementBuffer(vao, indices.id());
        mesh_key = key;
    }

    const PassProgram& pass_program(const ShaderDesc& shader) {
        const std::string key = program_key(shader);
        auto it = programs.find(key);
        if (it == programs.end()) {
            const ShaderStage vertex =
                shader_stage(GL_VERTEX_SHADER, shader.vertex, shader.defines);
            const ShaderStage fragment =
                shader_stage(GL_FRAGMENT_SHADER, shader.fragment, shader.defines);
            PassProgram linked{link_program({vertex, fragment}),
                               vertex.name + " + " + fragment.name,
                               declared_uniforms(vertex.source),
                               declared_input_locations(vertex.source)};
            linked.uniforms.merge(declared_uniforms(fragment.source));
            it = programs.emplace(key, std::move(linked)).first;
        }
        return it->second;
    }
    GLuint program(const ShaderDesc& shader) { return pass_program(shader).program.id(); }

    // Allocates the plan's textures and vertex streams (reusing ones of the same
    // storage) and frees the ones it does not name.
    void allocate(const FramePlan& plan) {
        std::map<std::string, FrameTexture> kept;
        std::map<std::string, VertexStream> kept_streams;
        for (const auto& r : plan.resources) {
            if (is_stream(r)) {
                auto it = streams.find(r.name);
                if (it != streams.end() && same_storage(it->second.desc, r) &&
                    it->second.desc.attribute == r.attribute)
                    kept_streams.emplace(r.name, std::move(it->second));
                else
                    kept_streams.emplace(r.name, VertexStream{r, Buffer(), ""});
                continue;
            }
            auto it = textures.find(r.name);
            if (it != textures.end() && same_storage(it->second.desc, r)) {
                kept.emplace(r.name, std::move(it->second));
            } else {
                const bool three_d = r.shape == ResourceShape::fixed_3d;
                kept.emplace(
                    r.name,
                    FrameTexture{r,
                                 make_texture(internal_format(r.format), r.size.x,
                                              r.size.y, three_d ? r.size.z : 0, r.levels),
                                 ""});
            }
        }
        textures = std::move(kept);
        streams = std::move(kept_streams);
    }

    GLuint sampler_for(const Sampling& sampling) {
        const std::string key = sampler_key(sampling);
        auto it = samplers.find(key);
        if (it == samplers.end()) {
            const GLenum mag =
                sampling.filter == TexelFilter::linear ? GL_LINEAR : GL_NEAREST;
            it = samplers
                     .emplace(key,
                              make_sampler(min_filter(sampling), mag,
                                           wrap_mode(sampling.wrap), &sampling.border[0]))
                     .first;
        }
        return it->second.id();
    }

    // The upload's data from the producer, checked against the resource it fills.
    TextureData produce(const Pass& pass, const ResourceDesc& target) {
        TextureData data = producer(pass);
        const std::string problem = check_texture_data(target, data);
        if (!problem.empty())
            throw std::runtime_error("pass '" + pass.name + "': data for '" +
                                     target.name + "': " + problem);
        return data;
    }

    // Calls the producer and uploads only when the content hash differs from the last
    // upload into this texture or stream (a reallocated one has none).
    void upload(const Pass& pass) {
        if (auto stream = streams.find(pass.writes.at(0)); stream != streams.end())
            return upload_stream(pass, stream->second);
        FrameTexture& target = textures.at(pass.writes.at(0));
        if (target.uploaded_hash == pass.data.content_hash) return;
        const TextureData data = produce(pass, target.desc);
        const bool three_d = target.desc.shape == ResourceShape::fixed_3d;
        const GLenum format = pixel_format(target.desc.format);
        for (std::size_t l = 0; l < data.levels.size(); ++l) {
            const glm::ivec3 s = mip_size(target.desc.size, static_cast<int>(l), three_d);
            if (three_d)
                glTextureSubImage3D(target.texture.id(), static_cast<GLint>(l), 0, 0, 0,
                                    s.x, s.y, s.z, format, GL_FLOAT,
                                    data.levels[l].data());
            else
                glTextureSubImage2D(target.texture.id(), static_cast<GLint>(l), 0, 0, s.x,
                                    s.y, format, GL_FLOAT, data.levels[l].data());
        }
        target.uploaded_hash = pass.data.content_hash;
        ++uploads;
    }

    void upload_stream(const Pass& pass, VertexStream& target) {
        if (target.uploaded_hash == pass.data.content_hash) return;
        const TextureData data = produce(pass, target.desc);
        const std::vector<float>& values = data.levels[0];
        target.buffer = make_buffer(
            values.data(), static_cast<GLsizeiptr>(values.size() * sizeof(float)));
        target.uploaded_hash = pass.data.content_hash;
        ++uploads;
    }

    // Binds the vertex streams `pass` reads at their attribute locations of the mesh's
    // vertex array; returns the locations, to disable after the draw.
    std::vector<GLuint> bind_streams(const Pass& pass, const PassProgram& program) {
        std::vector<GLuint> bound;
        for (const auto& read : pass.reads) {
            auto it = streams.find(read.resource);
            if (it == streams.end()) continue;
            const VertexStream& stream = it->second;
            const ResourceDesc& desc = stream.desc;
            if (!program.vertex_inputs.count(desc.attribute))
                throw std::logic_error("pass '" + pass.name + "': vertex stream '" +
                                       desc.name + "' is bound at attribute " +
                                       std::to_string(desc.attribute) + ", which " +
                                       pass.shader.vertex + " does not declare");
            if (static_cast<std::size_t>(desc.size.x) != vertex_count)
                throw std::runtime_error(
                    "pass '" + pass.name + "': vertex stream '" + desc.name + "' has " +
                    std::to_string(desc.size.x) + " vertices, the mesh " +
                    std::to_string(vertex_count));
            if (!stream.buffer.id())
                throw std::logic_error("pass '" + pass.name + "': vertex stream '" +
                                       desc.name + "' was never uploaded");
            const GLuint vao = mesh_vao.id(), location = GLuint(desc.attribute);
            const int channels = format_channels(desc.format);
            glVertexArrayVertexBuffer(vao, location, stream.buffer.id(), 0,
                                      static_cast<GLsizei>(channels * sizeof(float)));
            glVertexArrayAttribFormat(vao, location, channels, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, location, location);
            glEnableVertexArrayAttrib(vao, location);
            bound.push_back(location);
        }
        return bound;
    }

    // Levels 1.. of the written texture, each from the one above: that level alone is
    // made visible (base = max level), so the draw reads no level it writes.
    void build_mips(const Pass& pass) {
        FrameTexture& target = textures.at(pass.writes.at(0));
        const GLuint prog =
            program({"gl/shaders/fullscreen.vert", "gl/shaders/box_mip.frag", {}});
        const GLuint id = target.texture.id();
        glUseProgram(prog);
        glProgramUniform1i(prog, glGetUniformLocation(prog, "source"), 0);
        glDisable(GL_BLEND);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_CULL_FACE);
        glBindVertexArray(empty_vao.id());
        glBindTextureUnit(0, id);
        glBindSampler(0, sampler_for(Sampling{}));
        for (int level = 1; level < target.desc.levels; ++level) {
            glTextureParameteri(id, GL_TEXTURE_BASE_LEVEL, level - 1);
            glTextureParameteri(id, GL_TEXTURE_MAX_LEVEL, level - 1);
            Framebuffer fbo = make_framebuffer({&target.texture}, nullptr, level);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
            const glm::ivec3 size = mip_size(target.desc.size, level, false);
            glViewport(0, 0, size.x, size.y);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
        glTextureParameteri(id, GL_TEXTURE_BASE_LEVEL, 0);
        glTextureParameteri(id, GL_TEXTURE_MAX_LEVEL, target.desc.levels - 1);
        glUseProgram(0);
        glBindVertexArray(0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glBindTextureUnit(0, 0);
        glBindSampler(0, 0);
    }

    void draw(const Pass& pass, const FramePlan& plan) {
        // Attachments: the depth-format write becomes the depth attachment, the others
        // colour attachments in order.
        std::vector<const Texture*> colour;
        const Texture* depth = nullptr;
        for (const auto& w : pass.writes) {
            const FrameTexture& t = textures.at(w);
            if (is_depth_format(t.desc.format))
                depth = &t.texture;
            else
                colour.push_back(&t.texture);
        }
        Framebuffer fbo = [&] {
            try {
                return make_framebuffer(colour, depth, pass.level);
            } catch (const std::runtime_error& e) {
                throw std::runtime_error("pass '" + pass.name + "': " + e.what());
            }
        }();
        const PassProgram& linked = pass_program(pass.shader);
        const GLuint prog = linked.program.id();
        if (pass.clear) {
            for (std::size_t i = 0; i < colour.size(); ++i)
                glClearNamedFramebufferfv(fbo.id(), GL_COLOR, static_cast<GLint>(i),
                                          &pass.clear_colour[0]);
            if (depth) {
                const float one = 1.0f;
                glClearNamedFramebufferfv(fbo.id(), GL_DEPTH, 0, &one);
            }
        }
        glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
        const glm::ivec2 viewport = plan.viewport(pass);
        glViewport(0, 0, viewport.x, viewport.y);
        switch (pass.blend) {
            case Blend::none:
                glDisable(GL_BLEND);
                break;
            case Blend::additive:
                glEnable(GL_BLEND);
                glBlendFunc(GL_ONE, GL_ONE);
                break;
            case Blend::premultiplied_over:
                glEnable(GL_BLEND);
                glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
                break;
            case Blend::premultiplied_under:
                glEnable(GL_BLEND);
                glBlendFunc(GL_ONE_MINUS_DST_ALPHA, GL_ONE);
                break;
        }
        glBlendEquation(GL_FUNC_ADD);
        switch (pass.cull) {
            case FaceCulling::none:
                glDisable(GL_CULL_FACE);  // both facings count as layers, as ray hits do
                break;
            case FaceCulling::back:
            case FaceCulling::front:
                glEnable(GL_CULL_FACE);
                glFrontFace(GL_CCW);
                glCullFace(pass.cull == FaceCulling::back ? GL_BACK : GL_FRONT);
                break;
        }
        if (depth) {
            glEnable(GL_DEPTH_TEST);
            glDepthFunc(GL_LESS);
            glDepthMask(GL_TRUE);
        } else {
            glDisable(GL_DEPTH_TEST);
        }
        glUseProgram(prog);
        for (const auto& u : pass.uniforms) set_uniform(linked, pass, u);
        GLint unit = 0;
        for (const auto& read : pass.reads) {
            auto it = textures.find(read.resource);
            if (it == textures.end()) continue;  // a vertex stream: bind_streams()
            const std::string& sampler =
                read.sampler.empty() ? read.resource : read.sampler;
            glBindTextureUnit(static_cast<GLuint>(unit), it->second.texture.id());
            glBindSampler(static_cast<GLuint>(unit), sampler_for(read.sampling));
            const GLint location = uniform_location(linked, pass, sampler, "sampler");
            if (location >= 0) glProgramUniform1i(prog, location, unit);
            ++unit;
        }
        if (pass.kind == PassKind::draw_mesh) {
            const std::vector<GLuint> bound = bind_streams(pass, linked);
            glBindVertexArray(mesh_vao.id());
            glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
            for (GLuint location : bound)
                glDisableVertexArrayAttrib(mesh_vao.id(), location);
        } else {
            glBindVertexArray(empty_vao.id());
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
        // Leave nothing of ours bound: code that saves and restores GL state (ImGui's
        // back end) would otherwise restore names this executor has since deleted.
        glUseProgram(0);
        glBindVertexArray(0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDisable(GL_BLEND);
        glDisable(GL_CULL_FACE);
        for (GLint u = 0; u < unit; ++u) {
            glBindTextureUnit(static_cast<GLuint>(u), 0);
            glBindSampler(static_cast<GLuint>(u), 0);
        }
    }
};

FrameExecutor::FrameExecutor() : impl_(std::make_unique<Impl>()) {
    impl_->empty_vao = make_vertex_array();
}
FrameExecutor::~FrameExecutor() = default;

void FrameExecutor::set_upload_producer(UploadProducer producer) {
    impl_->producer = std::move(producer);
    // What was uploaded may differ from what the new producer gives: upload afresh.
    impl_->reuse.forget();
    for (auto& [name, texture] : impl_->textures) texture.uploaded_hash.clear();
    for (auto& [name, stream] : impl_->streams) stream.uploaded_hash.clear();
}

void FrameExecutor::set_reuse_unchanged_passes(bool reuse) {
    impl_->reuse_enabled = reuse;
}

void FrameExecutor::execute(const Scene& scene, const FramePlan& plan, bool time_passes) {
    if (plan.width <= 0 || plan.height <= 0)
        throw std::runtime_error("frame plan has no pixels");
    // Errors left by earlier calls are not this frame's: name them as such.
    check_errors("GL calls before this frame");
    impl_->upload_mesh(*scene.mesh);
    check_errors("upload of mesh '" + scene.mesh->name + "'");
    try {
        impl_->allocate(plan);
        check_errors("allocation of the frame's textures");
    } catch (...) {
        impl_->reuse.forget();  // textures may have been dropped: trust none of them
        throw;
    }

    GLint timer_bits = 0;
    if (time_passes) glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &timer_bits);
    const bool gpu_timer = timer_bits > 0;
    timings_ = FrameTimings{};
    timings_.gpu_timer = gpu_timer;
    while (impl_->queries.size() < plan.passes.size())
        impl_->queries.push_back(make_query(GL_TIME_ELAPSED));

    const std::vector<bool> run =
        impl_->reuse.schedule(plan, impl_->mesh_key, impl_->reuse_enabled);
    std::vector<double> wall_ms;
    std::size_t index = 0;
    try {
        for_each_pass(plan, [&](const Pass& pass) {
            const auto start = std::chrono::steady_clock::now();
            const bool runs = run[index];
            const bool gpu = runs && time_passes && gpu_timer && !cpu_pass(pass.kind);
            if (gpu) glBeginQuery(GL_TIME_ELAPSED, impl_->queries[index].id());
            switch (pass.kind) {
                case PassKind::upload:
                    if (runs) impl_->upload(pass);
                    break;
                case PassKind::build_mips:
                    if (runs) impl_->build_mips(pass);
                    break;
                case PassKind::draw_mesh:
                case PassKind::fullscreen:
                    if (runs) impl_->draw(pass, plan);
                    break;
            }
            if (gpu) glEndQuery(GL_TIME_ELAPSED);
            if (runs && time_passes && !gpu && !cpu_pass(pass.kind)) glFinish();
            check_errors("pass '" + pass.name + "'");
            wall_ms.push_back(std::chrono::duration<double, std::milli>(
                                  std::chrono::steady_clock::now() - start)
                                  .count());
            ++index;
        });
    } catch (...) {
        impl_->reuse.forget();  // what the failed pass left is unknown: rerun everything
        throw;
    }
    // Which passes ran is reported always; their times only when asked for.
    for (std::size_t i = 0; i < plan.passes.size(); ++i) {
        if (!run[i] || !time_passes) {
            timings_.passes.push_back({plan.passes[i].name, 0.0, !run[i]});
            continue;
        }
        double ms = wall_ms[i];
        if (gpu_timer && !cpu_pass(plan.passes[i].kind)) {
            GLuint64 ns = 0;
            glGetQueryObjectui64v(impl_->queries[i].id(), GL_QUERY_RESULT, &ns);
            ms = static_cast<double>(ns) * 1e-6;
        }
        timings_.passes.push_back({plan.passes[i].name, ms});
        timings_.total_milliseconds += ms;
    }
    if (time_passes) check_errors("reading the pass timer queries");
}

Image FrameExecutor::read_output(const FramePlan& plan) const {
    const auto& texture = impl_->textures.at(plan.output);
    const std::vector<float> pixels =
        read_texture_rgba32f(texture.texture, texture.width(), texture.height());
    check_errors("read-back of '" + plan.output + "'");
    Image image(texture.width(), texture.height());
    const std::size_t row = static_cast<std::size_t>(texture.width()) * 4;
    for (int y = 0; y < texture.height(); ++y)  // GL rows are bottom first
        std::copy_n(&pixels[static_cast<std::size_t>(texture.height() - 1 - y) * row],
                    row, &image.rgba[static_cast<std::size_t>(y) * row]);
    return image;
}

std::vector<float> FrameExecutor::read_channel(const std::string& resource) const {
    const auto& texture = impl_->textures.at(resource);
    const GLenum format =
        is_depth_format(texture.desc.format) ? GL_DEPTH_COMPONENT : GL_RED;
    const std::vector<float> pixels =
        read_texture_r32f(texture.texture, format, texture.width(), texture.height());
    check_errors("read-back of '" + resource + "'");
    std::vector<float> flipped(pixels.size());
    const std::size_t row = static_cast<std::size_t>(texture.width());
    for (int y = 0; y < texture.height(); ++y)
        std::copy_n(&pixels[static_cast<std::size_t>(texture.height() - 1 - y) * row],
                    row, &flipped[static_cast<std::size_t>(y) * row]);
    return flipped;
}

TextureData FrameExecutor::read_texture(const std::string& resource, int level) const {
    auto it = impl_->textures.find(resource);
    if (it == impl_->textures.end())
        throw std::runtime_error("read-back: no texture '" + resource +
                                 "' in this frame");
    const ResourceDesc& desc = it->second.desc;
    if (level < 0 || level >= desc.levels)
        throw std::runtime_error("read-back: '" + resource + "' has no level " +
                                 std::to_string(level));
    const glm::ivec3 size =
        mip_size(desc.size, level, desc.shape == ResourceShape::fixed_3d);
    TextureData data;
    data.size = size;
    data.levels.emplace_back(static_cast<std::size_t>(size.x) * size.y * size.z *
                             static_cast<std::size_t>(format_channels(desc.format)));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(it->second.texture.id(), level, pixel_format(desc.format), GL_FLOAT,
                      static_cast<GLsizei>(data.levels[0].size() * sizeof(float)),
                      data.levels[0].data());
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    check_errors("read-back of '" + resource + "' level " + std::to_string(level));
    return data;
}

std::size_t FrameExecutor::uploads_performed() const { return impl_->uploads; }

Image FrameExecutor::render(const Scene& scene, const FramePlan& plan) {
    execute(scene, plan);
    return read_output(plan);
}

std::vector<std::string> FrameExecutor::allocated_resources() const {
    std::vector<std::string> names;
    for (const auto& [name, texture] : impl_->textures) names.push_back(name);
    for (const auto& [name, stream] : impl_->streams) names.push_back(name);
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace lucent::gl
