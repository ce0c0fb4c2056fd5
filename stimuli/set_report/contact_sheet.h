#pragma once
// The contact sheet of a stimulus set as one PNG: a heading per group (factor series),
// then its stimuli as thumbnails in level order, each labelled with its id, technique
// and the parameters that vary in its series. Text is drawn with OpenImageIO's
// render_text and the DejaVu Sans font (Debian's fonts-dejavu-core).
#include <filesystem>
#include <string>
#include <vector>

namespace lucent::stimuli {

// Displayed (sRGB-encoded) RGB values, 3 per pixel, row-major.
struct Thumbnail {
    int width = 0, height = 0;
    std::vector<float> rgb;
};

// Box-filters `rgb` (width x height, 3 values per pixel) to fit in max_side x max_side.
Thumbnail make_thumbnail(const std::vector<float>& rgb, int width, int height,
                         int max_side);

struct ContactSheetCell {
    const Thumbnail* thumbnail = nullptr;
    std::vector<std::string> label;  // lines under the thumbnail
};
struct ContactSheetGroup {
    std::string heading;
    std::vector<ContactSheetCell> cells;
};

// The font file render_text uses; empty when it is not installed.
std::filesystem::path contact_sheet_font();

// Writes the sheet (atomically, via write_image). Throws std::runtime_error naming the
// file when the font is missing or the text or file cannot be written.
void write_contact_sheet(const std::filesystem::path& file,
                         const std::vector<ContactSheetGroup>& groups);

// A thumbnail as PNG file bytes (for embedding in HTML).
std::string thumbnail_png(const Thumbnail& thumbnail);

}  // namespace lucent::stimuli
