// Binary textures of the thick_texture technique: procedural patterns (no files needed)
// and image files through OpenImageIO (alpha < 0.5 = hole).
#include <cmath>
#include <filesystem>

#include "common/number_text.h"
#include "common/srgb.h"
#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

[[noreturn]] void fail(const std::string& spec, const std::string& why) {
    throw KnobError(
        "texture: '" + spec + "' " + why +
        " (accepted: net:H,W, stripes:H,W, checker, random:P,SEED, weave:T,G, "
        "curtain:SEED, or an image file)");
}

// "a,b" after the colon as numbers; `count` of them.
std::vector<double> arguments(const std::string& spec, const std::string& text,
                              std::size_t count) {
    std::vector<double> values;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string part = text.substr(start, comma - start);
        const auto value = common::parse_finite(part);
        if (!value) fail(spec, "has '" + part + "', not a number");
        values.push_back(*value);
        start = comma + 1;
    }
    if (values.size() != count)
        fail(spec, "needs " + std::to_string(count) + " comma-separated numbers");
    return values;
}

int whole(const std::string& spec, double value, int lo, int hi, const char* what) {
    if (value != std::floor(value) || value < lo || value > hi)
        fail(spec, std::string(what) + " must be a whole number in [" +
                       std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(value);
}

// Side of a square tile holding whole periods: period * 2^k >= 256.
int tile_side(int period) {
    int side = period;
    while (side < 256) side *= 2;
    return side;
}

TexelGrid blank(int side, glm::vec3 colour) {
    TexelGrid grid;
    grid.width = grid.height = side;
    grid.opaque.assign(std::size_t(side) * side, 0);
    grid.colour.assign(std::size_t(side) * side, colour);
    return grid;
}

// A small integer hash (splitmix64), for random textures that are the same everywhere.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}
double uniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
    return double(mix(seed * 0x100000001b3ull ^ mix(a * 73856093ull ^ mix(b))) >> 11) *
           0x1.0p-53;
}

TexelGrid from_file(const std::string& spec) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(spec, error))
        fail(spec, "is not a pattern name and no such image file exists");
    Image image;
    try {
        image = read_image(spec);
    } catch (const std::exception& e) {
        fail(spec, std::string("cannot be read: ") + e.what());
    }
    if (image.width < 1 || image.height < 1 || image.width > 8192 || image.height > 8192)
        fail(spec, "must be 1 to 8192 pixels on each side");
    const std::string ext = std::filesystem::path(spec).extension().string();
    const bool linear = ext == ".exr" || ext == ".EXR" || ext == ".hdr";
    TexelGrid grid = blank(0, glm::vec3(0.0f));
    grid.width = image.width;
    grid.height = image.height;
    grid.opaque.assign(std::size_t(image.width) * image.height, 0);
    grid.colour.assign(grid.opaque.size(), glm::vec3(0.0f));
    grid.coloured = true;
    for (int j = 0; j < image.height; ++j)
        for (int i = 0; i < image.width; ++i) {
            // Image rows are top first; texel row j = 0 is v = 0 (the bottom).
            const glm::vec4 c = image.at(i, image.height - 1 - j);
            if (!std::isfinite(c.r + c.g + c.b + c.a))
                fail(spec, "has a non-finite pixel");
            const std::size_t k = std::size_t(j) * image.width + i;
            grid.opaque[k] = c.a >= 0.5f ? 1 : 0;
            grid.colour[k] =
                linear ? glm::clamp(glm::vec3(c), 0.0f, 1.0f)
                       : glm::vec3(common::srgb_decode(c.r), common::srgb_decode(c.g),
                                   common::srgb_decode(c.b));
        }
    return grid;
}

}  // namespace

glm::vec3 TexelGrid::colour_at(int i, int j) const {
    i %= width, j %= height;
    if (i < 0) i += width;
    if (j < 0) j += height;
    return colour[std::size_t(j) * width + i];
}

double TexelGrid::hole_fraction() const {
    std::size_t holes = 0;
    for (std::uint8_t o : opaque) holes += o == 0;
    return opaque.empty() ? 0.0 : double(holes) / double(opaque.size());
}

TexelGrid make_texel_grid(const std::string& spec, glm::vec3 knob_colour) {
    const std::size_t colon = spec.find(':');
    const std::string name = spec.substr(0, colon);
    const std::string rest = colon == std::string::npos ? "" : spec.substr(colon + 1);
    const auto args = [&](std::size_t count) {
        if (colon == std::string::npos) fail(spec, "needs arguments after ':'");
        return arguments(spec, rest, count);
    };
    if (name == "net" || name == "stripes") {
        const auto a = args(2);
        const int hole = whole(spec, a[0], 0, 64, "the hole width H");
        const int wall = whole(spec, a[1], 0, 64, "the wall width W");
        if (hole + wall == 0) fail(spec, "has H + W = 0");
        const int period = hole + wall;
        TexelGrid grid = blank(tile_side(period), knob_colour);
        for (int j = 0; j < grid.height; ++j)
            for (int i = 0; i < grid.width; ++i) {
                const bool hole_x = i % period < hole, hole_y = j % period < hole;
                grid.opaque[std::size_t(j) * grid.width + i] =
                    name == "net" ? !(hole_x && hole_y) : !hole_x;
            }
        return grid;
    }
    if (name == "checker") {
        if (colon != std::string::npos) fail(spec, "takes no arguments");
        TexelGrid grid = blank(256, knob_colour);
        for (int j = 0; j < grid.height; ++j)
            for (int i = 0; i < grid.width; ++i)
                grid.opaque[std::size_t(j) * grid.width + i] = (i + j) % 2;
        return grid;
    }
    if (name == "random") {
        const auto a = args(2);
        if (a[0] < 0.0 || a[0] > 1.0)
            fail(spec, "P (the hole probability) must be in [0, 1]");
        const int seed = whole(spec, a[1], 0, 1 << 30, "SEED");
        TexelGrid grid = blank(256, knob_colour);
        for (int j = 0; j < grid.height; ++j)
            for (int i = 0; i < grid.width; ++i)
                grid.opaque[std::size_t(j) * grid.width + i] =
                    uniform(std::uint64_t(seed), std::uint64_t(i), std::uint64_t(j)) >=
                    a[0];
        return grid;
    }
    if (name == "weave") {
        // Plain weave: warp threads (columns) and weft threads (rows) of width T with
        // gaps of G; at each crossing the thread on top alternates (checkerwise), and
        // the top colour is that thread's (warp: the knob colour, weft: a darker one).
        const auto a = args(2);
        const int thread = whole(spec, a[0], 1, 64, "the thread width T");
        const int gap = whole(spec, a[1], 0, 64, "the gap G");
        const int period = thread + gap;
        TexelGrid grid = blank(tile_side(2 * period), knob_colour);
        grid.coloured = true;
        const glm::vec3 weft = knob_colour * glm::vec3(0.55f, 0.6f, 0.8f);
        for (int j = 0; j < grid.height; ++j)
            for (int i = 0; i < grid.width; ++i) {
                const bool on_warp = i % period < thread, on_weft = j % period < thread;
                const std::size_t k = std::size_t(j) * grid.width + i;
                grid.opaque[k] = on_warp || on_weft;
                const bool warp_on_top =
                    on_warp && (!on_weft || ((i / period + j / period) % 2 == 0));
                grid.colour[k] = warp_on_top ? knob_colour : weft;
            }
        return grid;
    }
    if (name == "curtain") {
        // Irregular coloured holes: cells of 6 texels, each with a hole of 1 to 4 texels
        // per side at a random offset (some cells closed), and colour bands along u.
        const auto a = args(1);
        const int seed = whole(spec, a[0], 0, 1 << 30, "SEED");
        TexelGrid grid = blank(384, knob_colour);
        grid.coloured = true;
        std::fill(grid.opaque.begin(), grid.opaque.end(), std::uint8_t(1));
        const int cell = 6, cells = grid.width / cell;
        for (int cj = 0; cj < cells; ++cj)
            for (int ci = 0; ci < cells; ++ci) {
                const auto s = std::uint64_t(seed);
                if (uniform(s, ci, cj + 7777) < 0.15) continue;  // a closed cell
                const int w = 1 + int(uniform(s, ci, cj) * 4.0);
                const int h = 1 + int(uniform(s, cj + 31, ci) * 4.0);
                const int ox = int(uniform(s, ci + 101, cj) * (cell - w));
                const int oy = int(uniform(s, ci, cj + 211) * (cell - h));
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        grid.opaque[std::size_t(cj * cell + oy + y) * grid.width +
                                    ci * cell + ox + x] = 0;
            }
        for (int j = 0; j < grid.height; ++j)
            for (int i = 0; i < grid.width; ++i) {
                const double band =
                    0.5 + 0.5 * std::sin(2.0 * 3.14159265358979 * i / 96.0);
                grid.colour[std::size_t(j) * grid.width + i] =
                    knob_colour * glm::vec3(float(0.6 + 0.4 * band),
                                            float(0.5 + 0.3 * band),
                                            float(0.9 - 0.5 * band));
            }
        return grid;
    }
    return from_file(spec);
}

}  // namespace lucent::thick_texture
