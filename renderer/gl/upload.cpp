#include "renderer/gl/upload.h"

#include <stdexcept>
#include <string>

#include "renderer/gl/errors.h"

namespace lucent::gl {

void upload_texture_rgba8(const Texture& texture, int width, int height,
                          std::span<const std::uint8_t> rgba) {
    const std::string what = "upload of " + std::to_string(width) + "x" +
                             std::to_string(height) + " RGBA8 pixels";
    if (width <= 0 || height <= 0 ||
        rgba.size() != static_cast<std::size_t>(width) * std::size_t(height) * 4)
        throw std::invalid_argument(what + ": " + std::to_string(rgba.size()) +
                                    " bytes given");
    glTextureSubImage2D(texture.id(), 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE,
                        rgba.data());
    check_errors(what);
}

}  // namespace lucent::gl
