#pragma once
// Linear float RGBA images, top row first (as image files store them). Alpha is coverage:
// 1 where the object is, 0 on the background. The struct is the core's; the functions
// below that read, write or encode files are defined in lucent_renderer_io
// (renderer/io/image_files.cpp, OpenImageIO), which every program that renders links.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <stdexcept>
#include <vector>

#include "common/srgb.h"

namespace lucent {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgba;  // width * height * 4

    Image() = default;
    Image(int w, int h)
        : width(w), height(h), rgba(static_cast<std::size_t>(w) * h * 4, 0.0f) {}
    glm::vec4 at(int x, int y) const {
        const float* p = &rgba[(static_cast<std::size_t>(y) * width + x) * 4];
        return {p[0], p[1], p[2], p[3]};
    }
    void set(int x, int y, glm::vec4 value) {
        float* p = &rgba[(static_cast<std::size_t>(y) * width + x) * 4];
        p[0] = value.r;
        p[1] = value.g;
        p[2] = value.b;
        p[3] = value.a;
    }
};

// Replaces NaN with 0 and +-Inf with the largest finite float of that sign; returns how
// many values it replaced. Every image passes through this before it is written.
std::size_t replace_non_finite(Image& image);
// Pixels with at least one NaN or Inf channel: what replace_non_finite() would repair,
// counted per pixel for reports (manifests, `lucent render` warnings).
std::size_t count_non_finite_pixels(const Image& image);

class ImageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// How PNG data is compressed; both are lossless and deterministic (same pixels, same
// bytes on every write), they differ in encoding time and file size.
enum class PngEncoding {
    fast,     // Paeth filter on every row, zlib run-length strategy
    compact,  // libpng's defaults: adaptive filters, zlib level 6 (~4x slower, ~15%
              // smaller)
};

struct ImageWriteOptions {
    // PNG / TIFF: store linear values instead of sRGB-encoding them.
    bool linear = false;
    PngEncoding png = PngEncoding::fast;
};

// Writes by extension: ".exr" 32-bit float linear RGBA; ".png" 8-bit RGB,
// sRGB-encoded unless options.linear; ".tif"/".tiff" 16-bit RGB, same encoding rule.
// Non-finite values are replaced first (replace_non_finite) and 8/16-bit output clamps to
// [0, 1]. The file is written to a temporary name and renamed, so it is never truncated.
// Throws ImageError naming the file (unknown extension, I/O failure).
void write_image(const std::filesystem::path& path, const Image& image,
                 const ImageWriteOptions& options = {});
// Reads any image OpenImageIO can; channels beyond 4 are dropped, missing alpha is 1.
// Callable from the core (file textures): it goes through the CPU backend
// (core/cpu_backend.h) to lucent_renderer_io.
Image read_image(const std::filesystem::path& path);
// True when write_image() accepts the extension of `path`.
bool is_supported_image_path(const std::filesystem::path& path);

}  // namespace lucent
