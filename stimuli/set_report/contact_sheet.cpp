#include "stimuli/set_report/contact_sheet.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/srgb.h"
#include "renderer/core/image.h"

namespace lucent::stimuli {
namespace {

constexpr int kThumbnailSide = 160;
constexpr int kPadding = 12;
constexpr int kPerRow = 8;
constexpr int kLineHeight = 16;
constexpr int kLabelLines = 4;
constexpr int kHeadingHeight = 30;
constexpr float kSheetGrey = 0.16f;  // sRGB-encoded: dark enough to see black backgrounds

// An RGB ImageBuf of the sheet's grey.
OIIO::ImageBuf grey_buffer(int width, int height) {
    OIIO::ImageBuf buffer(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT));
    const float grey[3] = {kSheetGrey, kSheetGrey, kSheetGrey};
    OIIO::ImageBufAlgo::fill(buffer, grey);
    return buffer;
}

// Draws `text` into a box of the sheet (clipped to the box, so long labels never run
// into the next cell).
void draw_text(OIIO::ImageBuf& sheet, int x, int y, int width, int height,
               const std::string& text, int size, const std::filesystem::path& font) {
    if (text.empty()) return;
    OIIO::ImageBuf box = grey_buffer(width, height);
    const float white[3] = {0.92f, 0.92f, 0.92f};
    if (!OIIO::ImageBufAlgo::render_text(box, 0, height - 4, text, size, font.string(),
                                         white))
        throw std::runtime_error("cannot draw text with font " + font.string() + ": " +
                                 box.geterror());
    OIIO::ImageBufAlgo::paste(sheet, x, y, 0, 0, box);
}

}  // namespace

Thumbnail make_thumbnail(const std::vector<float>& rgb, int width, int height,
                         int max_side) {
    Thumbnail out;
    if (width <= 0 || height <= 0) return out;
    const double scale =
        std::min(1.0, double(max_side) / double(std::max(width, height)));
    out.width = std::max(1, int(std::lround(width * scale)));
    out.height = std::max(1, int(std::lround(height * scale)));
    out.rgb.assign(std::size_t(out.width) * out.height * 3, 0.0f);
    for (int ty = 0; ty < out.height; ++ty)
        for (int tx = 0; tx < out.width; ++tx) {
            // The source pixels this thumbnail pixel covers (at least one).
            const int x0 = tx * width / out.width,
                      x1 = std::max(x0 + 1, (tx + 1) * width / out.width);
            const int y0 = ty * height / out.height,
                      y1 = std::max(y0 + 1, (ty + 1) * height / out.height);
            double sum[3] = {0, 0, 0};
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x)
                    for (int c = 0; c < 3; ++c)
                        sum[c] += rgb[(std::size_t(y) * width + x) * 3 + c];
            const double n = double((x1 - x0) * (y1 - y0));
            for (int c = 0; c < 3; ++c)
                out.rgb[(std::size_t(ty) * out.width + tx) * 3 + c] = float(sum[c] / n);
        }
    return out;
}

std::filesystem::path contact_sheet_font() {
    const std::filesystem::path font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    std::error_code error;
    return std::filesystem::is_regular_file(font, error) ? font : std::filesystem::path();
}

void write_contact_sheet(const std::filesystem::path& file,
                         const std::vector<ContactSheetGroup>& groups) {
    const auto font = contact_sheet_font();
    if (font.empty())
        throw std::runtime_error(
            file.string() +
            ": no font to label the contact sheet "
            "(/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf, Debian "
            "package fonts-dejavu-core)");
    const int cell_w = kThumbnailSide + kPadding;
    const int cell_h = kThumbnailSide + kLabelLines * kLineHeight + kPadding;
    std::size_t widest = 1;
    int height = kPadding;
    for (const auto& group : groups) {
        const std::size_t n = std::max<std::size_t>(group.cells.size(), 1);
        widest = std::max(widest, std::min<std::size_t>(n, kPerRow));
        height += kHeadingHeight + int((n + kPerRow - 1) / kPerRow) * cell_h;
    }
    // Wide enough for the cells and, roughly (10 px a character at size 17), the
    // headings.
    int width = kPadding + int(widest) * cell_w;
    for (const auto& group : groups)
        width = std::max(width, 2 * kPadding + 10 * int(group.heading.size()));
    OIIO::ImageBuf sheet = grey_buffer(width, height);

    int y = kPadding;
    for (const auto& group : groups) {
        draw_text(sheet, kPadding, y, width - 2 * kPadding, kHeadingHeight, group.heading,
                  17, font);
        y += kHeadingHeight;
        for (std::size_t i = 0; i < group.cells.size(); ++i) {
            const int x = kPadding + int(i % kPerRow) * cell_w;
            const int top = y + int(i / kPerRow) * cell_h;
            const auto& cell = group.cells[i];
            if (const Thumbnail* t = cell.thumbnail; t && t->width > 0) {
                const int ox = x + (kThumbnailSide - t->width) / 2;
                const int oy = top + (kThumbnailSide - t->height) / 2;
                for (int ty = 0; ty < t->height; ++ty)
                    for (int tx = 0; tx < t->width; ++tx)
                        sheet.setpixel(ox + tx, oy + ty,
                                       &t->rgb[(std::size_t(ty) * t->width + tx) * 3], 3);
            }
            for (int line = 0; line < kLabelLines && line < int(cell.label.size());
                 ++line)
                draw_text(sheet, x, top + kThumbnailSide + line * kLineHeight,
                          kThumbnailSide, kLineHeight, cell.label[std::size_t(line)], 12,
                          font);
        }
        y += int((std::max<std::size_t>(group.cells.size(), 1) + kPerRow - 1) / kPerRow) *
             cell_h;
    }

    // write_image takes linear values and sRGB-encodes them for the PNG.
    Image image(width, height);
    std::vector<float> pixels(std::size_t(width) * height * 3);
    sheet.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT,
                     pixels.data());
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i) {
        for (int c = 0; c < 3; ++c)
            image.rgba[i * 4 + c] = common::srgb_decode(pixels[i * 3 + c]);
        image.rgba[i * 4 + 3] = 1.0f;
    }
    write_image(file, image);
}

std::string thumbnail_png(const Thumbnail& thumbnail) {
    static std::atomic<int> counter{0};
    const auto file = std::filesystem::temp_directory_path() /
                      ("lucent-thumbnail-" + std::to_string(getpid()) + "-" +
                       std::to_string(counter++) + ".png");
    Image image(thumbnail.width, thumbnail.height);
    for (std::size_t i = 0, n = std::size_t(thumbnail.width) * thumbnail.height; i < n;
         ++i) {
        for (int c = 0; c < 3; ++c)
            image.rgba[i * 4 + c] = common::srgb_decode(thumbnail.rgb[i * 3 + c]);
        image.rgba[i * 4 + 3] = 1.0f;
    }
    write_image(file, image);
    std::ifstream in(file, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
    return bytes.str();
}

}  // namespace lucent::stimuli
