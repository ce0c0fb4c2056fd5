// `lucent analyze --images` end to end: the real executable (the dispatcher hands it to
// lucent-full, which makes the thumbnails) writes one self-contained report.html that a
// real browser (headless chromium) draws offline: every plot and every level's picture.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "renderer/core/image.h"
#include "tests/support/browser.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

// RFC 4648 decoding, written here independently of the report's encoder.
std::string base64_decode(const std::string& text) {
    std::string out;
    int bits = 0, value = 0;
    for (const char c : text) {
        int v;
        if (c >= 'A' && c <= 'Z')
            v = c - 'A';
        else if (c >= 'a' && c <= 'z')
            v = c - 'a' + 26;
        else if (c >= '0' && c <= '9')
            v = c - '0' + 52;
        else if (c == '+')
            v = 62;
        else if (c == '/')
            v = 63;
        else
            break;  // '=' padding or the closing quote
        value = (value << 6) | v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += static_cast<char>((value >> bits) & 0xff);
        }
    }
    return out;
}

// Width and height from a PNG's IHDR chunk (bytes 16..23, big-endian).
std::pair<int, int> png_size(const std::string& png) {
    if (png.size() < 24 || png.compare(1, 3, "PNG") != 0) return {0, 0};
    auto be32 = [&](std::size_t at) {
        return (int(static_cast<unsigned char>(png[at])) << 24) |
               (int(static_cast<unsigned char>(png[at + 1])) << 16) |
               (int(static_cast<unsigned char>(png[at + 2])) << 8) |
               int(static_cast<unsigned char>(png[at + 3]));
    };
    return {be32(16), be32(20)};
}

TEST(AnalysisReportInBrowser, PlotsAndLevelThumbnailsAreDrawn) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "analysis_report_browser";
    fs::remove_all(dir);
    fs::create_directories(dir / "stimuli");
    // Three levels, each with a 256x256 picture of its own saturated colour, so the
    // screenshot shows whether the thumbnails were drawn (and the report's pixels alone
    // cannot contain them: its plots are black, grey, white and blue).
    const float colours[3][3] = {
        {0.9f, 0.05f, 0.9f}, {0.05f, 0.8f, 0.1f}, {0.95f, 0.5f, 0.0f}};
    const char* levels[3] = {"18", "25", "30"};
    for (int l = 0; l < 3; ++l) {
        Image image(256, 256);
        for (int i = 0; i < 256 * 256; ++i) {
            for (int c = 0; c < 3; ++c) image.rgba[i * 4 + c] = colours[l][c];
            image.rgba[i * 4 + 3] = 1.0f;
        }
        write_image(dir / "stimuli" / (std::string("s") + levels[l] + ".png"), image);
    }
    {
        std::ofstream csv(dir / "ratings.csv");
        csv << "participant,stimulus,factor,level,question,rating\n";
        for (int p = 1; p <= 8; ++p)
            for (int l = 0; l < 3; ++l)
                for (const char* q : {"translucent", "realistic"})
                    csv << 'p' << p << ",s" << levels[l] << ",thickness_exponent,"
                        << levels[l] << ',' << q << ',' << 1 + (p + 2 * l) % 7 << '\n';
    }
    const std::string command = std::string("'") + LUCENT_EXECUTABLE + "' analyze '" +
                                (dir / "ratings.csv").string() + "' --out '" +
                                (dir / "report").string() + "' --format html --images '" +
                                (dir / "stimuli").string() + "' > '" +
                                (dir / "analyze.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << read_file(dir / "analyze.log");

    const std::string html = read_file(dir / "report" / "report.html");
    ASSERT_FALSE(html.empty());
    EXPECT_EQ(html.find("src=\"http"), std::string::npos);  // self-contained: offline
    // Each level's picture is embedded as a thumbnail of at most 128 pixels a side.
    int thumbnails = 0;
    for (std::size_t at = html.find("data:image/png;base64,"); at != std::string::npos;
         at = html.find("data:image/png;base64,", at + 1)) {
        const auto [w, h] = png_size(base64_decode(html.substr(at + 22, 64 * 1024)));
        EXPECT_EQ(w, 128);
        EXPECT_EQ(h, 128);
        ++thumbnails;
    }
    EXPECT_GE(thumbnails, 3);

    const test::BrowserPage page = test::open_in_browser(
        dir / "report" / "report.html", dir / "screenshot.png", 1280, 4000);
    ASSERT_TRUE(page.ok) << page.error;
    EXPECT_EQ(page.images_drawn,
              std::to_string(thumbnails) + "/" + std::to_string(thumbnails));
    // The plots are inline SVG: one figure per factor and one per question ~ factor.
    std::size_t svgs = 0;
    for (std::size_t at = page.dom.find("<svg"); at != std::string::npos;
         at = page.dom.find("<svg", at + 1))
        ++svgs;
    EXPECT_GE(svgs, 3u);
    // Drawn, not only present: the plots' blue means and each thumbnail's colour.
    const auto near = [](float a, float b) { return std::abs(a - b) < 0.08f; };
    EXPECT_GT(page.count_pixels([&](float r, float g, float b) {
        return near(r, 0x1f / 255.0f) && near(g, 0x77 / 255.0f) && near(b, 0xb4 / 255.0f);
    }),
              50u);
    // write_image stores linear values sRGB-encoded (IEC 61966-2-1): the page shows
    // those.
    const auto encoded = [](float c) {
        return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    };
    for (const auto& colour : colours)
        EXPECT_GT(page.count_pixels([&](float r, float g, float b) {
            return near(r, encoded(colour[0])) && near(g, encoded(colour[1])) &&
                   near(b, encoded(colour[2]));
        }),
                  1000u)  // a 128x128 thumbnail is 16,384 pixels
            << colour[0] << "," << colour[1] << "," << colour[2];
}

// The scales of forced choices (issue 30) in the same report: a choices CSV of a 9-level
// series (MLDS triads and paired comparisons of 6 observers with a square-root scale and
// noise from a fixed linear congruential sequence), each level's picture its own hue.
TEST(AnalysisReportInBrowser, ScalingPlotsAndTheSeriesPicturesAreDrawn) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "scaling_report_browser";
    fs::remove_all(dir);
    fs::create_directories(dir / "stimuli");
    const double values[9] = {1, 4, 7, 10, 14, 19, 25, 36, 64};
    for (int l = 0; l < 9; ++l) {
        Image image(128, 128);
        for (int i = 0; i < 128 * 128; ++i) {
            image.rgba[i * 4 + 0] = l / 8.0f;
            image.rgba[i * 4 + 1] = 0.2f;
            image.rgba[i * 4 + 2] = 1.0f - l / 8.0f;
            image.rgba[i * 4 + 3] = 1.0f;
        }
        write_image(dir / "stimuli" / ("r_" + std::to_string(int(values[l])) + ".png"),
                    image);
    }
    uint64_t state = 12345;
    auto noise = [&] {  // roughly N(0, 0.15^2): a sum of 4 uniforms
        double sum = 0;
        for (int k = 0; k < 4; ++k) {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            sum += static_cast<double>(state >> 11) * 0x1p-53 - 0.5;
        }
        return sum * 0.15 * std::sqrt(3.0);
    };
    auto psi = [&](int l) { return std::sqrt((values[l] - 1) / 63); };
    auto id = [&](int l) { return "r_" + std::to_string(int(values[l])); };
    auto value = [&](int l) { return std::to_string(int(values[l])); };
    {
        std::ofstream csv(dir / "choices.csv");
        csv << "participant,session,trial,block,task,question,practice,catch,expected,"
               "shown_1,shown_2,shown_3,shown_4,value_1,value_2,value_3,value_4,choice,"
               "rt_ms\n";
        for (int p = 1; p <= 6; ++p) {
            int trial = 0;
            for (int a = 0; a < 9; ++a)
                for (int b = a + 1; b < 9; ++b)
                    for (int c = b + 1; c < 9; ++c) {
                        const double d = psi(b) - psi(a) - (psi(c) - psi(b)) + noise();
                        csv << 'P' << p << ",s" << p << ',' << trial++
                            << ",mlds,triad,differs_more,0,0,," << id(a) << ',' << id(b)
                            << ',' << id(c) << ",," << value(a) << ',' << value(b) << ','
                            << value(c) << ",," << (d > 0 ? 1 : 2) << ",900\n";
                    }
            for (int a = 0; a < 9; ++a)
                for (int b = 0; b < 9; ++b) {
                    if (a == b) continue;
                    const double d = psi(a) - psi(b) + noise();
                    csv << 'P' << p << ",s" << p << ',' << trial++
                        << ",pairs,pair,more_translucent,0,0,," << id(a) << ',' << id(b)
                        << ",,," << value(a) << ',' << value(b) << ",,,"
                        << (d > 0 ? 1 : 2) << ",700\n";
                }
        }
    }
    const std::string command = std::string("'") + LUCENT_EXECUTABLE + "' analyze '" +
                                (dir / "choices.csv").string() + "' --out '" +
                                (dir / "report").string() + "' --images '" +
                                (dir / "stimuli").string() +
                                "' --bootstrap 100 --six-point 50 > '" +
                                (dir / "analyze.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << read_file(dir / "analyze.log");
    const std::string html = read_file(dir / "report" / "report.html");
    for (const char* words : {"Perceptual scales", "MLDS", "Bradley-Terry", "Thurstone"})
        EXPECT_NE(html.find(words), std::string::npos) << words;
    EXPECT_TRUE(fs::exists(dir / "report" / "scaling.csv"));

    const test::BrowserPage page = test::open_in_browser(
        dir / "report" / "report.html", dir / "screenshot.png", 1280, 4000);
    ASSERT_TRUE(page.ok) << page.error;
    // Both blocks' series pictures, 9 each, decoded.
    EXPECT_EQ(page.images_drawn, "18/18");
    std::size_t svgs = 0;
    for (std::size_t at = page.dom.find("<svg"); at != std::string::npos;
         at = page.dom.find("<svg", at + 1))
        ++svgs;
    EXPECT_GE(svgs, 2u);  // one scale per block
    const auto near = [](float a, float b) { return std::abs(a - b) < 0.08f; };
    EXPECT_GT(page.count_pixels([&](float r, float g, float b) {
        return near(r, 0x1f / 255.0f) && near(g, 0x77 / 255.0f) && near(b, 0xb4 / 255.0f);
    }),
              50u);  // the pooled scale's line and intervals
}

}  // namespace
}  // namespace lucent
