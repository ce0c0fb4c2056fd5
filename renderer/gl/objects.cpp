#include "renderer/gl/objects.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace lucent::gl {

Buffer make_buffer(const void* data, GLsizeiptr bytes, GLbitfield flags) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, bytes > 0 ? bytes : 1, data, flags);
    return Buffer(id);
}

Texture make_texture_2d(GLenum internal_format, int width, int height) {
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    glTextureStorage2D(id, 1, internal_format, width, height);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return Texture(id);
}

VertexArray make_vertex_array() {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    return VertexArray(id);
}

Query make_query(GLenum target) {
    GLuint id = 0;
    glCreateQueries(target, 1, &id);
    return Query(id);
}

Framebuffer make_framebuffer(std::initializer_list<const Texture*> colour,
                             const Texture* depth) {
    return make_framebuffer(std::vector<const Texture*>(colour), depth, 0);
}

Framebuffer make_framebuffer(const std::vector<const Texture*>& colour,
                             const Texture* depth, int level) {
    GLint max_attachments = 0, max_draw_buffers = 0;
    glGetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &max_attachments);
    glGetIntegerv(GL_MAX_DRAW_BUFFERS, &max_draw_buffers);
    const GLint limit = std::min(max_attachments, max_draw_buffers);
    if (static_cast<GLint>(colour.size()) > limit)
        throw std::runtime_error(
            "framebuffer: " + std::to_string(colour.size()) +
            " colour attachments, this GL allows " + std::to_string(limit) +
            " (GL_MAX_COLOR_ATTACHMENTS " + std::to_string(max_attachments) +
            ", GL_MAX_DRAW_BUFFERS " + std::to_string(max_draw_buffers) + ")");
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    Framebuffer fbo(id);
    std::vector<GLenum> buffers;
    for (const Texture* texture : colour) {
        const GLenum attachment =
            GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(buffers.size());
        glNamedFramebufferTexture(id, attachment, texture->id(), level);
        buffers.push_back(attachment);
    }
    if (depth) glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, depth->id(), level);
    if (!buffers.empty())
        glNamedFramebufferDrawBuffers(id, static_cast<GLsizei>(buffers.size()),
                                      buffers.data());
    else
        glNamedFramebufferDrawBuffer(id, GL_NONE);
    const GLenum status = glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("framebuffer incomplete: glCheckFramebufferStatus = " +
                                 std::to_string(status));
    return fbo;
}

Texture make_texture(GLenum internal_format, int width, int height, int depth,
                     int levels) {
    GLuint id = 0;
    glCreateTextures(depth > 0 ? GL_TEXTURE_3D : GL_TEXTURE_2D, 1, &id);
    if (depth > 0)
        glTextureStorage3D(id, levels, internal_format, width, height, depth);
    else
        glTextureStorage2D(id, levels, internal_format, width, height);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    return Texture(id);
}

Sampler make_sampler(GLenum min_filter, GLenum mag_filter, GLenum wrap,
                     const float border[4]) {
    GLuint id = 0;
    glCreateSamplers(1, &id);
    glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(min_filter));
    glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(mag_filter));
    for (GLenum axis : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glSamplerParameteri(id, axis, static_cast<GLint>(wrap));
    glSamplerParameterfv(id, GL_TEXTURE_BORDER_COLOR, border);
    return Sampler(id);
}

}  // namespace lucent::gl
