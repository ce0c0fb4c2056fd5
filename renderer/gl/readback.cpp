#include "renderer/gl/readback.h"

namespace lucent::gl {

std::vector<float> read_texture_rgba32f(const Texture& texture, int width, int height) {
    std::vector<float> pixels(static_cast<size_t>(width) * height * 4);
    glGetTextureImage(texture.id(), 0, GL_RGBA, GL_FLOAT,
                      static_cast<GLsizei>(pixels.size() * sizeof(float)), pixels.data());
    return pixels;
}

std::vector<float> read_texture_r32f(const Texture& texture, GLenum format, int width,
                                     int height) {
    std::vector<float> pixels(static_cast<size_t>(width) * height);
    glGetTextureImage(texture.id(), 0, format, GL_FLOAT,
                      static_cast<GLsizei>(pixels.size() * sizeof(float)), pixels.data());
    return pixels;
}

std::vector<std::uint8_t> read_framebuffer_rgba8(int width, int height) {
    std::vector<std::uint8_t> pixels(static_cast<size_t>(width) * height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    return pixels;
}

}  // namespace lucent::gl
