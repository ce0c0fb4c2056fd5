#pragma once
// CPU pixels into GL textures, checked: a size mismatch is refused before GL sees it and
// a GL error (e.g. a region outside the texture) throws GlError naming the upload.
#include <cstdint>
#include <span>

#include "renderer/gl/objects.h"

namespace lucent::gl {

// Replaces level 0 of `texture` (at least width x height) with `rgba`: width * height
// RGBA8 pixels, row 0 into texture row 0 (GL's bottom row). Throws std::invalid_argument
// when `rgba` has another size, GlError when GL rejects the upload.
void upload_texture_rgba8(const Texture& texture, int width, int height,
                          std::span<const std::uint8_t> rgba);

}  // namespace lucent::gl
