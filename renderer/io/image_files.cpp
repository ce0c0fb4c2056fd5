// Image files through OpenImageIO, and the sRGB encodings they use (core/image.h
// declares them; lucent_renderer_io defines them, so the core links no image library).
#include "renderer/io/image_files.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>

#include "renderer/core/display_transform.h"
#include "renderer/core/image.h"

namespace lucent {
namespace {

std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& why) {
    throw ImageError(path.string() + ": " + why);
}

// A channel value as written to 8/16-bit files: NaN as 0, clamped to [0, 1] (so -Inf
// is 0 and +Inf is 1: what replace_non_finite() followed by the clamp gives).
float clamp_unit(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

std::uint16_t encode_channel(float v, bool linear, float scale) {
    return static_cast<std::uint16_t>(
        std::lround((linear ? clamp_unit(v) : display_value(v)) * scale));
}

// Rows stay top first; both OIIO and Image store them so.
template <typename T>
std::vector<T> encode_rgb(const Image& image, bool linear, float scale) {
    std::vector<T> out(static_cast<std::size_t>(image.width) * image.height * 3);
    const std::size_t values = out.size();
    if (!linear && sizeof(T) == 1) {  // the common case: by table
        for (std::size_t i = 0; i < values; ++i)
            out[i] = static_cast<T>(display_code(image.rgba[i / 3 * 4 + i % 3]));
        return out;
    }
    for (std::size_t i = 0; i < values; ++i)
        out[i] =
            static_cast<T>(encode_channel(image.rgba[i / 3 * 4 + i % 3], linear, scale));
    return out;
}

// PNG settings: zlib's run-length strategy after the Paeth filter on every row. Lossless
// like any PNG, deterministic (same pixels, same bytes), and about 4x faster to encode
// than libpng's default (level 6, adaptive filters) on renders with flat backgrounds,
// for files ~15% larger (measured on the thesis set; stimuli/README.md).
constexpr const char* kPngStrategy = "rle";
constexpr int kPngFilterPaeth = 0x80;  // libpng's PNG_FILTER_PAETH

}  // namespace

std::size_t replace_non_finite(Image& image) {
    std::size_t replaced = 0;
    for (float& v : image.rgba) {
        if (std::isfinite(v)) continue;
        ++replaced;
        v = std::isnan(v) ? 0.0f : std::copysign(std::numeric_limits<float>::max(), v);
    }
    return replaced;
}

std::size_t count_non_finite_pixels(const Image& image) {
    std::size_t pixels = 0;
    for (std::size_t i = 0; i + 3 < image.rgba.size(); i += 4)
        if (!std::isfinite(image.rgba[i]) || !std::isfinite(image.rgba[i + 1]) ||
            !std::isfinite(image.rgba[i + 2]) || !std::isfinite(image.rgba[i + 3]))
            ++pixels;
    return pixels;
}

bool is_supported_image_path(const std::filesystem::path& path) {
    const std::string ext = lower_extension(path);
    return ext == ".exr" || ext == ".png" || ext == ".tif" || ext == ".tiff";
}

void write_image(const std::filesystem::path& path, const Image& input,
                 const ImageWriteOptions& options) {
    const std::string ext = lower_extension(path);
    if (!is_supported_image_path(path))
        fail(path, "unsupported image format '" + ext + "' (use .exr, .png or .tif)");
    if (input.width <= 0 || input.height <= 0 ||
        input.rgba.size() != static_cast<std::size_t>(input.width) * input.height * 4)
        fail(path, "image has no pixels");
    // Only EXR stores floats as they are; 8/16-bit encoders map NaN and Inf themselves
    // (encode_rgb), so the image is copied for EXR alone.
    Image repaired;
    if (ext == ".exr") {
        repaired = input;
        replace_non_finite(repaired);
    }
    const Image& image = ext == ".exr" ? repaired : input;

    // Write to a temporary sibling, then rename: readers never see a half-written file.
    std::filesystem::path temporary = path;
    temporary += ".partial" + ext;
    auto out = OIIO::ImageOutput::create(temporary.string());
    if (!out) fail(path, "OpenImageIO cannot write '" + ext + "': " + OIIO::geterror());
    bool ok = false;
    if (ext == ".exr") {
        OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
        spec.attribute("compression", "zip");
        spec.attribute("DateTime",
                       "");  // OIIO stamps the time otherwise: same image, other bytes
        ok = out->open(temporary.string(), spec) &&
             out->write_image(OIIO::TypeDesc::FLOAT, image.rgba.data());
    } else if (ext == ".png") {
        OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", options.linear ? "linear" : "sRGB");
        if (options.png == PngEncoding::fast) {
            spec.attribute("compression", kPngStrategy);
            spec.attribute("png:filter", kPngFilterPaeth);
        }
        const auto pixels = encode_rgb<std::uint8_t>(image, options.linear, 255.0f);
        ok = out->open(temporary.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
    } else {
        OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT16);
        spec.attribute("oiio:ColorSpace", options.linear ? "linear" : "sRGB");
        spec.attribute("compression", "zip");
        spec.attribute("DateTime", "");  // as for EXR: no timestamp in the file
        const auto pixels = encode_rgb<std::uint16_t>(image, options.linear, 65535.0f);
        ok = out->open(temporary.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT16, pixels.data());
    }
    const std::string error = ok ? "" : out->geterror();
    ok = out->close() && ok;
    if (!ok) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        fail(path, "write failed: " + (error.empty() ? out->geterror() : error));
    }
    std::error_code rename_error;
    std::filesystem::rename(temporary, path, rename_error);
    if (rename_error)
        fail(path, "cannot rename temporary file: " + rename_error.message());
}

Image read_image_file(const std::filesystem::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) fail(path, "cannot read: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    const int channels = spec.nchannels;
    std::vector<float> pixels(static_cast<std::size_t>(spec.width) * spec.height *
                              channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
        fail(path, "cannot read pixels: " + in->geterror());
    Image image(spec.width, spec.height);
    for (std::size_t i = 0, n = static_cast<std::size_t>(spec.width) * spec.height; i < n;
         ++i)
        for (int c = 0; c < 4; ++c)
            image.rgba[i * 4 + c] = c < channels    ? pixels[i * channels + c]
                                    : c == 3        ? 1.0f
                                    : channels == 1 ? pixels[i * channels]
                                                    : 0.0f;
    return image;
}

}  // namespace lucent
