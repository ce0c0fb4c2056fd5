#include "study/session/stimulus_source.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "renderer/core/display_transform.h"
#include "renderer/core/image.h"
#include "renderer/gl/errors.h"
#include "renderer/gl/upload.h"
#include "study/session/stimulus_provenance.h"

namespace lucent::study {

CpuImage load_image_rgba8(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw StimulusError(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
        spec.width > 16384 || spec.height > 16384)
        throw StimulusError(path + ": unusable image size");
    CpuImage image;
    image.width = spec.width;
    image.height = spec.height;
    const int channels = spec.nchannels;
    const size_t pixels = static_cast<size_t>(spec.width) * spec.height;
    const bool linear = spec.format.is_floating_point();  // EXR: linear light
    std::vector<float> values(pixels * channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, values.data()))
        throw StimulusError(path + ": cannot read image: " + in->geterror());
    image.rgba.resize(pixels * 4);
    for (size_t i = 0; i < pixels; ++i) {
        const float* v = &values[i * channels];
        float rgb[3] = {v[0], channels >= 3 ? v[1] : v[0], channels >= 3 ? v[2] : v[0]};
        const float alpha = channels == 4 ? v[3] : channels == 2 ? v[1] : 1.f;
        for (int c = 0; c < 3; ++c)
            image.rgba[i * 4 + c] =
                linear ? display_code(rgb[c])
                       : static_cast<uint8_t>(
                             std::lround(std::fmin(std::fmax(rgb[c], 0.f), 1.f) * 255.f));
        image.rgba[i * 4 + 3] = static_cast<uint8_t>(
            std::lround(std::fmin(std::fmax(alpha, 0.f), 1.f) * 255.f));
    }
    return image;
}

void save_image_rgba8(const std::string& path, const CpuImage& image) {
    auto out = OIIO::ImageOutput::create(path);
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT8);
    if (!out || !out->open(path, spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, image.rgba.data()) || !out->close())
        throw StimulusError(path + ": cannot write image: " + OIIO::geterror());
}

// Straight alpha both ways ("oiio:UnassociatedAlpha"): OIIO would otherwise divide the
// colour by alpha on the way out and multiply on the way in, which does not round-trip
// in 8 bits.
std::string encode_png_rgba8(const CpuImage& image) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput memory(bytes);
    auto out = OIIO::ImageOutput::create("served.png", &memory);
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);
    // The fastest deflate level: each serving is encoded anew (picture_names.h).
    spec.attribute("png:compressionLevel", 1);
    if (!out || !out->open("served.png", spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, image.rgba.data()) || !out->close())
        throw StimulusError("cannot encode a PNG: " + OIIO::geterror());
    return std::string(bytes.begin(), bytes.end());
}

CpuImage decode_png_rgba8(std::string_view png, const std::string& what) {
    OIIO::Filesystem::IOMemReader memory(png.data(), png.size());
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // With a config, OIIO 2.4 takes the proxy from it, not from the argument.
    OIIO::Filesystem::IOProxy* proxy = &memory;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    auto in = OIIO::ImageInput::open("served.png", &config, &memory);
    if (!in) throw StimulusError(what + ": cannot read the PNG: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.width > 16384 ||
        spec.height > 16384 || spec.nchannels != 4)
        throw StimulusError(what + ": not an RGBA PNG of a usable size");
    CpuImage image;
    image.width = spec.width;
    image.height = spec.height;
    image.rgba.resize(static_cast<size_t>(spec.width) * spec.height * 4);
    if (!in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, image.rgba.data()))
        throw StimulusError(what + ": cannot read the PNG: " + in->geterror());
    return image;
}

StimulusTexture upload_texture(const CpuImage& image, const std::string& what) {
    const std::string size =
        std::to_string(image.width) + "x" + std::to_string(image.height);
    const auto fail = [&](const std::string& why) {
        throw StimulusError(what + ": the " + size + " picture cannot be shown: " + why);
    };
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != size_t(image.width) * size_t(image.height) * 4)
        fail("its pixels do not match its size");
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (image.width > max_size || image.height > max_size)
        fail("larger than this GPU's largest texture (" + std::to_string(max_size) +
             " pixels a side)");
    StimulusTexture t;
    t.width = image.width;
    t.height = image.height;
    try {
        // An error left by an earlier call is reported now, not blamed on this upload
        // later; then the rows are read as they are stored (no unpack buffer, no row
        // length or skips that other code, Dear ImGui's backend, may have left set).
        gl::check_errors("the session window before uploading a picture");
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
        glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
        t.texture = gl::make_texture_2d(GL_RGBA8, image.width, image.height);
        gl::check_errors("the texture storage of a " + size + " picture");
        gl::upload_texture_rgba8(t.texture, image.width, image.height, image.rgba);
    } catch (const gl::GlError& e) {
        fail(e.what());
    }
    // Complete: level 0 holds the whole picture (a texture without storage samples
    // black).
    GLint width = 0, height = 0;
    glGetTextureLevelParameteriv(t.texture.id(), 0, GL_TEXTURE_WIDTH, &width);
    glGetTextureLevelParameteriv(t.texture.id(), 0, GL_TEXTURE_HEIGHT, &height);
    if (width != image.width || height != image.height)
        fail("the texture has level 0 of " + std::to_string(width) + "x" +
             std::to_string(height) + " after the upload");
    return t;
}

std::string PrerenderedStimuli::path_for(const Stimulus& spec) const {
    if (!spec.image.empty()) return spec.image;
    if (images_dir_.empty()) return "";
    for (const char* ext : {".png", ".tif", ".exr"}) {
        const auto p = std::filesystem::path(images_dir_) / (spec.id + ext);
        if (std::filesystem::exists(p)) return p.string();
    }
    return "";
}

namespace {

// What to run so that `dir` holds the picture: `render --preset` when it is a built-in
// study (it writes every picture the study shows, practice, series and ladders
// included), else a stimulus set that lists the stimulus.
std::string how_to_render(const Protocol& protocol, const std::string& dir) {
    const std::string out = dir.empty() ? "DIR" : dir;
    const std::string preset = "preset:";
    const bool series =
        std::any_of(protocol.blocks.begin(), protocol.blocks.end(), [](const Block& b) {
            return b.task == Task::adjust || b.task == Task::staircase;
        });
    // A study with adjust or staircase blocks also needs their series and ladders.
    if (series)
        return "'lucent render " +
               (protocol.source.rfind(preset, 0) == 0
                    ? "--preset " + protocol.source.substr(preset.size())
                    : "--study " + protocol.source) +
               " --out " + out + "' writes every picture the study shows in the browser";
    if (protocol.source.rfind(preset, 0) == 0)
        return "'lucent render --preset " + protocol.source.substr(preset.size()) +
               " --out " + out +
               "' writes every picture of the built-in study, practice included";
    return "render a stimulus set that lists it ('lucent render CONFIG.toml --out " +
           out + "') and pass that folder";
}

}  // namespace

void PrerenderedStimuli::check(const Protocol& protocol) const {
    for (const Stimulus& s : protocol.stimuli) {
        const std::string path = path_for(s);
        if (path.empty())
            throw StimulusError(
                protocol.source + ": stimulus '" + s.id + "' (technique " + s.technique +
                "): " +
                (images_dir_.empty()
                     ? "no pre-rendered picture: pass --images DIR; "
                     : "no " + s.id + ".png, .tif or .exr in " + images_dir_ + "; ") +
                how_to_render(protocol, images_dir_));
        if (!std::filesystem::exists(path))
            throw StimulusError(protocol.source + ": stimulus '" + s.id + "': image " +
                                path + " does not exist");
    }
}

std::vector<StimulusProvenance> PrerenderedStimuli::provenance(
    const Protocol& protocol) const {
    return resolve_stimuli(protocol, images_dir_);
}

StimulusTexture PrerenderedStimuli::render(const Stimulus& spec, int, int) {
    const std::string path = path_for(spec);
    if (path.empty()) throw StimulusError("stimulus '" + spec.id + "': no image");
    return upload_texture(load_image_rgba8(path), path);
}

}  // namespace lucent::study
