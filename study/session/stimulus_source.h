#pragma once
// Where stimulus pictures come from. The runner asks a StimulusRenderer for a texture
// per stimulus; PrerenderedStimuli loads image files (shown pixel for pixel), and a live
// renderer (techniques from renderer/) plugs in behind the same interface.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/gl/objects.h"
#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

// An image file that cannot be used; what() names the file and the reason.
class StimulusError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// 8-bit RGBA, sRGB-encoded, top row first.
struct CpuImage {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;
};

// Loads PNG/TIFF/JPEG as 8-bit; EXR (linear float) is sRGB-encoded on the way.
CpuImage load_image_rgba8(const std::string& path);
void save_image_rgba8(const std::string& path, const CpuImage& image);
// The same as PNG in memory (straight alpha: what is decoded is what was encoded), for
// lucent serve, which re-encodes each serving; StimulusError naming `what` when the
// bytes are not a PNG it can read.
std::string encode_png_rgba8(const CpuImage& image);
CpuImage decode_png_rgba8(std::string_view png, const std::string& what);

struct StimulusTexture {
    gl::Texture texture;  // RGBA8, nearest filtering, row 0 = top of the picture
    int width = 0;
    int height = 0;
};

class StimulusRenderer {
public:
    virtual ~StimulusRenderer() = default;
    // Renders (or loads) the stimulus at the protocol's size into a texture; a GL
    // context is current. Throws StimulusError naming the stimulus on failure.
    virtual StimulusTexture render(const Stimulus& spec, int width, int height) = 0;
    // Checks, before any window opens, that every stimulus can be provided.
    virtual void check(const Protocol& protocol) const = 0;
    // What each stimulus will be, for the database: resolved values, mesh hash, and for
    // pre-rendered files the manifest check (stimulus_provenance.h). Throws
    // StimulusError.
    virtual std::vector<StimulusProvenance> provenance(
        const Protocol& protocol) const = 0;
};

// Image stimuli from their `image` path; live stimuli from
// `images_dir/<id>.png|.tif|.exr` (e.g. the output of `lucent render --preset thesis
// --out DIR`, which holds every picture of the built-in study, practice included).
// check() refuses a live stimulus without such a file in one line naming what to render
// (`lucent serve` shows files only; LiveOrPrerenderedStimuli renders the others).
class PrerenderedStimuli : public StimulusRenderer {
public:
    explicit PrerenderedStimuli(std::string images_dir)
        : images_dir_(std::move(images_dir)) {}
    StimulusTexture render(const Stimulus& spec, int width, int height) override;
    void check(const Protocol& protocol) const override;
    std::vector<StimulusProvenance> provenance(const Protocol& protocol) const override;
    std::string path_for(const Stimulus& spec) const;  // "" when none exists
    const std::string& images_dir() const { return images_dir_; }

private:
    std::string images_dir_;
};

// The picture into an RGBA8 texture of the current context (row 0 = top). Checked, never
// shown black: a picture larger than GL_MAX_TEXTURE_SIZE, a GL error (an error left
// earlier included) or a texture whose level 0 is not the picture's size throws
// StimulusError "WHAT: the WxH picture cannot be shown: ..." (WHAT names the file or
// stimulus).
StimulusTexture upload_texture(const CpuImage& image, const std::string& what);

}  // namespace lucent::study
