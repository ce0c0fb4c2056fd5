#pragma once
// Move-only owners of OpenGL objects. Raw GLuint names never leave renderer/gl: technique
// code holds these and passes them to the helpers below. All use direct state access
// (4.5).
#include <epoxy/gl.h>

#include <utility>
#include <vector>

namespace lucent::gl {

template <void (*Delete)(GLuint)>
class Object {
public:
    Object() = default;
    explicit Object(GLuint id) : id_(id) {}
    ~Object() { reset(); }
    Object(Object&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
    Object& operator=(Object&& other) noexcept {
        if (this != &other) {
            reset();
            id_ = std::exchange(other.id_, 0);
        }
        return *this;
    }
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;

    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() {
        if (id_) Delete(id_);
        id_ = 0;
    }

private:
    GLuint id_ = 0;
};

namespace detail {
inline void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
inline void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
inline void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
inline void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
inline void delete_program(GLuint id) { glDeleteProgram(id); }
inline void delete_query(GLuint id) { glDeleteQueries(1, &id); }
inline void delete_sampler(GLuint id) { glDeleteSamplers(1, &id); }
}  // namespace detail

using Buffer = Object<detail::delete_buffer>;
using Texture = Object<detail::delete_texture>;
using Framebuffer = Object<detail::delete_framebuffer>;
using VertexArray = Object<detail::delete_vertex_array>;
using Program = Object<detail::delete_program>;
using Query = Object<detail::delete_query>;
using Sampler = Object<detail::delete_sampler>;

// Immutable-storage buffer holding `bytes` bytes copied from `data` (may be null).
Buffer make_buffer(const void* data, GLsizeiptr bytes, GLbitfield flags = 0);
// 2D texture with immutable storage, nearest filtering, clamped to edge.
Texture make_texture_2d(GLenum internal_format, int width, int height);
// Immutable 2D (depth 0) or 3D texture with `levels` mip levels; its filtering comes from
// the sampler objects bound with it (the texture's own state is nearest, clamped).
Texture make_texture(GLenum internal_format, int width, int height, int depth,
                     int levels);
// Sampler object with the given filters and one wrap mode on every axis.
Sampler make_sampler(GLenum min_filter, GLenum mag_filter, GLenum wrap,
                     const float border[4]);
VertexArray make_vertex_array();
Query make_query(GLenum target);

// Framebuffer with the given colour attachments (index i -> GL_COLOR_ATTACHMENTi) and an
// optional depth texture; throws std::runtime_error naming the incompleteness status.
Framebuffer make_framebuffer(std::initializer_list<const Texture*> colour,
                             const Texture* depth = nullptr);
// Same, attaching mip `level` of every texture; any number of colour attachments up to
// GL_MAX_COLOR_ATTACHMENTS and GL_MAX_DRAW_BUFFERS (std::runtime_error naming both
// above).
Framebuffer make_framebuffer(const std::vector<const Texture*>& colour,
                             const Texture* depth, int level);

}  // namespace lucent::gl
