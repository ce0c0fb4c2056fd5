#include "gl/objects.h"

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
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    Framebuffer fbo(id);
    GLenum buffers[8];
    GLsizei count = 0;
    for (const Texture* texture : colour) {
        if (count == 8) throw std::runtime_error("framebuffer: more than 8 colour attachments");
        glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0 + count, texture->id(), 0);
        buffers[count] = GL_COLOR_ATTACHMENT0 + count;
        ++count;
    }
    if (depth) glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, depth->id(), 0);
    if (count > 0)
        glNamedFramebufferDrawBuffers(id, count, buffers);
    else
        glNamedFramebufferDrawBuffer(id, GL_NONE);
    const GLenum status = glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("framebuffer incomplete: glCheckFramebufferStatus = " +
                                 std::to_string(status));
    return fbo;
}

}  // namespace lucent::gl
