#include "app/level_thumbnail.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "renderer/core/image.h"
#include "stimuli/set_report/contact_sheet.h"

namespace lucent::app {

std::string level_thumbnail_png(const std::filesystem::path& picture) {
    constexpr int kThumbnailSide = 128;  // the width the report shows it at
    const Image image = read_image(picture);
    if (image.width <= 0 || image.height <= 0)
        throw std::runtime_error(picture.string() + ": empty image");
    // PNG values as stored are the displayed (sRGB-encoded) ones: filter those, as the
    // stimulus set's contact sheet does.
    std::vector<float> rgb(std::size_t(image.width) * image.height * 3);
    for (std::size_t i = 0, n = std::size_t(image.width) * image.height; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            const float v = image.rgba[i * 4 + c];
            rgb[i * 3 + c] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
        }
    return stimuli::thumbnail_png(
        stimuli::make_thumbnail(rgb, image.width, image.height, kThumbnailSide));
}

}  // namespace lucent::app
