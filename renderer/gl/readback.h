#pragma once
// Reading pixels back from textures and framebuffers into CPU images.
#include <cstdint>
#include <vector>

#include "renderer/gl/objects.h"

namespace lucent::gl {

// Reads an RGBA float texture (level 0) into `width*height*4` floats, bottom row first
// (OpenGL order).
std::vector<float> read_texture_rgba32f(const Texture& texture, int width, int height);
// Reads a single-channel float texture (e.g. depth) into width*height floats.
std::vector<float> read_texture_r32f(const Texture& texture, GLenum format, int width,
                                     int height);
// Reads the current read framebuffer's colour attachment 0 / back buffer as RGBA8.
std::vector<std::uint8_t> read_framebuffer_rgba8(int width, int height);

}  // namespace lucent::gl
