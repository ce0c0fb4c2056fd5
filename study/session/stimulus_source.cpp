#include "session/stimulus_source.h"

#include <OpenImageIO/imageio.h>

#include "core/image.h"
#include "session/stimulus_provenance.h"

#include <cmath>
#include <filesystem>

namespace lucent::study {

namespace {
uint8_t encode_srgb(float linear) {
    if (!std::isfinite(linear)) return 0;  // no NaN reaches the screen
    return static_cast<uint8_t>(std::lround(lucent::srgb_encode(linear) * 255.f));
}
}  // namespace

CpuImage load_image_rgba8(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw StimulusError(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.width > 16384 ||
        spec.height > 16384)
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
            image.rgba[i * 4 + c] = linear ? encode_srgb(rgb[c])
                                           : static_cast<uint8_t>(std::lround(
                                                 std::fmin(std::fmax(rgb[c], 0.f), 1.f) * 255.f));
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

StimulusTexture upload_texture(const CpuImage& image) {
    StimulusTexture t;
    t.width = image.width;
    t.height = image.height;
    t.texture = gl::make_texture_2d(GL_RGBA8, image.width, image.height);
    glTextureSubImage2D(t.texture.id(), 0, 0, 0, image.width, image.height, GL_RGBA,
                        GL_UNSIGNED_BYTE, image.rgba.data());
    return t;
}

std::string PrerenderedStimuli::path_for(const StimulusSpec& spec) const {
    if (!spec.image.empty()) return spec.image;
    if (images_dir_.empty()) return "";
    for (const char* ext : {".png", ".tif", ".exr"}) {
        const auto p = std::filesystem::path(images_dir_) / (spec.id + ext);
        if (std::filesystem::exists(p)) return p.string();
    }
    return "";
}

void PrerenderedStimuli::check(const Protocol& protocol) const {
    for (const StimulusSpec& s : protocol.stimuli) {
        const std::string path = path_for(s);
        if (path.empty())
            throw StimulusError(
                protocol.source + ": stimulus '" + s.id + "' (technique " + s.technique +
                "): live rendering is not wired into 'lucent run' yet; pre-render the set "
                "(e.g. 'lucent render --preset thesis --out DIR') and pass --images DIR" +
                (images_dir_.empty() ? "" : " (no " + s.id + ".png/.tif/.exr in " + images_dir_ + ")"));
        if (!std::filesystem::exists(path))
            throw StimulusError(protocol.source + ": stimulus '" + s.id + "': image " + path +
                                " does not exist");
    }
}

std::vector<StimulusProvenance> PrerenderedStimuli::provenance(const Protocol& protocol) const {
    return resolve_stimuli(protocol, images_dir_);
}

StimulusTexture PrerenderedStimuli::render(const StimulusSpec& spec, int, int) {
    const std::string path = path_for(spec);
    if (path.empty()) throw StimulusError("stimulus '" + spec.id + "': no image");
    return upload_texture(load_image_rgba8(path));
}

}  // namespace lucent::study
