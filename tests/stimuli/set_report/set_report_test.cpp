// The stimulus-set report on a small hand-made set: a series with an identical pair and
// a pair whose Delta E00 has a closed form (grey vs white discs), plus one stimulus of
// no series; refusals of sets that are not Lucent sets or whose files changed; the page
// in a real browser (headless chromium) with its pictures drawn.
#include "stimuli/set_report/set_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <set>

#include "common/content_hash.h"
#include "renderer/core/image.h"
#include "stimuli/image_statistics.h"
#include "stimuli/manifest.h"
#include "tests/support/browser.h"
#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

namespace fs = std::filesystem;
constexpr int kSide = 64;

float srgb_decode(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// A disc of linear colour `rgb` (radius 20) on a black background, alpha 1 inside.
Image disc(float r, float g, float b) {
    Image image(kSide, kSide);
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x) {
            const double dx = x + 0.5 - kSide / 2.0, dy = y + 0.5 - kSide / 2.0;
            if (dx * dx + dy * dy < 400.0) image.set(x, y, {r, g, b, 1.0f});
        }
    return image;
}

// Writes DIR/ID.png and returns its manifest row (the batch renderer's layout).
ManifestRow stimulus(const fs::path& dir, const std::string& id,
                     const std::string& series, double albedo, const Image& image) {
    write_image(dir / (id + ".png"), image);
    ManifestRow row = {{"id", id, false},
                       {"file", id + ".png", false},
                       {"files", id + ".png", false},
                       {"technique", "ward", false},
                       {"series", series, false},
                       {"mesh", "sphere", false},
                       {"mesh_faces", "100", true},
                       {"mesh_hash", "0", false},
                       {"width", std::to_string(kSide), true},
                       {"height", std::to_string(kSide), true},
                       {"background", "0,0,0", false},
                       {"albedo", std::to_string(albedo), true}};
    const auto stats = compute_image_statistics(
        FloatImageView{image.width, image.height, 4, image.rgba});
    for (const auto& field : statistics_fields(stats)) row.push_back(field);
    row.push_back({"non_finite_pixels", "0", true});
    row.push_back({"software_version", "test", false});
    row.push_back({"build_hash", "test", false});
    row.push_back({"input_hash", "0", false});
    row.push_back(
        {"content_hash",
         common::ContentHash().field(common::hash_file(dir / (id + ".png"))).hex(),
         false});
    return row;
}

class SmallSet : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = test::scratch_dir(
            "set_report_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        const float grey = srgb_decode(128.0f / 255.0f);  // PNG code 128 exactly
        std::vector<ManifestRow> rows = {
            stimulus(dir_, "a", "grey", 0.5, disc(grey, grey, grey)),
            stimulus(dir_, "white", "grey", 1.0, disc(1, 1, 1)),
            stimulus(dir_, "b", "grey", 0.5,
                     disc(grey, grey, grey)),  // the same picture as a
            stimulus(dir_, "green", "", 0.0, disc(0, 1, 0)),
        };
        write_manifest(dir_, "small", rows);
    }
    bool wrote_anything() const {
        return fs::exists(dir_ / "report.html") || fs::exists(dir_ / "contact-sheet.png");
    }
    std::string refusal() {
        try {
            (void)measure_stimulus_set(dir_);
        } catch (const SetReportError& e) {
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
            return e.what();
        }
        ADD_FAILURE() << "no error";
        return {};
    }
    fs::path dir_;
};

const PairDifference& pair_of(const SetReport& r, const std::string& a,
                              const std::string& b) {
    for (const auto& p : r.pairs)
        if (r.stimuli[p.first].id == a && r.stimuli[p.second].id == b) return p;
    throw std::runtime_error("no pair " + a + " / " + b);
}

TEST_F(SmallSet, MeasuresTheIdenticalAndTheDifferentPair) {
    const SetReport r = measure_stimulus_set(dir_);
    EXPECT_EQ(r.set_name, "small");
    ASSERT_EQ(r.series.size(), 1u);
    EXPECT_EQ(r.series[0].name, "grey");
    EXPECT_EQ(r.series[0].varying, std::vector<std::string>{"albedo"});
    // Level order by albedo (stable among equals): a, b, then white.
    ASSERT_EQ(r.series[0].members.size(), 3u);
    EXPECT_EQ(r.stimuli[r.series[0].members[0]].id, "a");
    EXPECT_EQ(r.stimuli[r.series[0].members[1]].id, "b");
    EXPECT_EQ(r.stimuli[r.series[0].members[2]].id, "white");
    EXPECT_EQ(r.stimuli[r.series[0].members[2]].level, "albedo=1.000000");
    ASSERT_EQ(r.pairs.size(), 3u);

    const auto& same = pair_of(r, "a", "b");
    EXPECT_TRUE(same.identical);
    EXPECT_TRUE(same.adjacent);
    EXPECT_EQ(same.delta_e.mean, 0.0);
    EXPECT_NEAR(same.ssim, 1.0, 1e-12);

    // Grey (L* of PNG code 128) against white (L* = 100), achromatic: every disc pixel
    // differs by |Delta L| / S_L (CIEDE2000 with a = b = 0).
    const double y = srgb_decode(128.0f / 255.0f);
    const double l = 116.0 * std::cbrt(y) - 16.0;
    const double lbar = (l + 100.0) / 2.0, d = (lbar - 50) * (lbar - 50);
    const double expected = (100.0 - l) / (1 + 0.015 * d / std::sqrt(20 + d));
    const auto& different = pair_of(r, "a", "white");
    EXPECT_FALSE(different.identical);
    EXPECT_FALSE(different.adjacent);
    EXPECT_NEAR(different.delta_e.mean, expected, 0.02);
    EXPECT_NEAR(different.delta_e.percentile_95, expected, 0.02);
    EXPECT_DOUBLE_EQ(different.delta_e.share_above_1, 1.0);
    EXPECT_GT(different.delta_e.pixels, 1200u);  // pi 20^2 = 1257 disc pixels
    EXPECT_LT(different.delta_e.pixels, 1320u);
    EXPECT_LT(different.ssim, 0.999);
    EXPECT_TRUE(pair_of(r, "b", "white").adjacent);

    // Exactly two warnings: the pair below the threshold and the identical pictures.
    ASSERT_EQ(r.warnings.size(), 2u) << ::testing::PrintToString(r.warnings);
    EXPECT_EQ(
        r.warnings[0],
        "series 'grey': a vs b: mean Delta E00 0.00 is below 3.00 (adjacent levels)");
    EXPECT_EQ(r.warnings[1],
              "a and b are identical images (separate stimuli, meant to differ)");

    // A higher threshold flags the different pair too.
    SetReportOptions strict;
    strict.min_delta_e = expected + 1.0;
    EXPECT_EQ(measure_stimulus_set(dir_, strict).warnings.size(), 4u);
}

TEST_F(SmallSet, WritesTheReportAndTheContactSheet) {
    const auto files = write_set_report(measure_stimulus_set(dir_));
    ASSERT_EQ(files.size(), 2u);
    std::ifstream in(dir_ / "report.html");
    const std::string html((std::istreambuf_iterator<char>(in)),
                           std::istreambuf_iterator<char>());
    std::size_t images = 0;
    for (auto at = html.find("<img"); at != std::string::npos;
         at = html.find("<img", at + 1))
        ++images;
    EXPECT_EQ(images, 4u);
    EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
    EXPECT_EQ(html.find("src=\"a.png\""), std::string::npos) << "not self-contained";
    EXPECT_NE(html.find("a and b are identical images"), std::string::npos);
    EXPECT_NE(html.find("<svg"), std::string::npos);

    const Image sheet = read_image(dir_ / "contact-sheet.png");
    EXPECT_GT(sheet.width, 3 * kSide);
    // The green disc is drawn (only its thumbnail has that colour), and the labels (light
    // text on the dark sheet).
    std::size_t green = 0, text = 0;
    for (int y = 0; y < sheet.height; ++y)
        for (int x = 0; x < sheet.width; ++x) {
            const auto p = sheet.at(x, y);
            green += p.g > 0.9f && p.r < 0.05f && p.b < 0.05f;
            text += p.r > 0.5f && std::fabs(p.r - p.g) < 0.01f &&
                    std::fabs(p.r - p.b) < 0.01f && p.r < 0.95f;
        }
    EXPECT_GT(green, 1200u);
    EXPECT_GT(text, 100u);
}

TEST_F(SmallSet, TheCommandPrintsEachWarningAndWritesBothFiles) {
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(run_stimuli_report(dir_, {}), 0);  // warnings inform, they do not fail
    const std::string out = ::testing::internal::GetCapturedStdout();
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(
        err,
        "lucent stimuli report: warning: series 'grey': a vs b: mean Delta E00 0.00 is "
        "below 3.00 (adjacent levels)\n"
        "lucent stimuli report: warning: a and b are identical images (separate "
        "stimuli, meant to differ)\n");
    EXPECT_NE(out.find("wrote " + (dir_ / "report.html").string()), std::string::npos)
        << out;
    EXPECT_NE(out.find("wrote " + (dir_ / "contact-sheet.png").string()),
              std::string::npos);
    EXPECT_TRUE(fs::exists(dir_ / "report.html") &&
                fs::exists(dir_ / "contact-sheet.png"));
}

TEST_F(SmallSet, TheReportOpensInABrowserWithItsPicturesDrawn) {
    write_set_report(measure_stimulus_set(dir_));
    const auto page =
        test::open_in_browser(dir_ / "report.html", dir_ / "screenshot.png", 1280, 1400);
    ASSERT_TRUE(page.ok) << page.error;
    EXPECT_EQ(page.images_drawn, "4/4");
    // The green disc's thumbnail is on screen (nothing else on the page is that green).
    const auto green = page.count_pixels(
        [](float r, float g, float b) { return g > 0.9f && r < 0.1f && b < 0.1f; });
    EXPECT_GT(green, 1000u) << "screenshot " << (dir_ / "screenshot.png");
    EXPECT_GT(page.non_background_pixels, 20000u);
}

TEST_F(SmallSet, ADirectoryWithoutAManifestIsRefusedNamingIt) {
    fs::remove(dir_ / "manifest.csv");
    const std::string why = refusal();
    EXPECT_NE(why.find((dir_ / "manifest.csv").string() + ": missing"), std::string::npos)
        << why;
    EXPECT_FALSE(wrote_anything());
}

TEST_F(SmallSet, AForeignCsvIsNotALucentManifest) {
    std::ofstream(dir_ / "manifest.csv") << "name,score\nx,1\n";
    const std::string why = refusal();
    EXPECT_NE(
        why.find("manifest.csv: not a Lucent stimulus-set manifest (no column 'id')"),
        std::string::npos)
        << why;
    EXPECT_FALSE(wrote_anything());
}

TEST_F(SmallSet, AMissingImageIsNamed) {
    fs::remove(dir_ / "white.png");
    const std::string why = refusal();
    EXPECT_NE(why.find((dir_ / "white.png").string() + ": missing (listed in"),
              std::string::npos)
        << why;
    EXPECT_FALSE(wrote_anything());
}

TEST_F(SmallSet, AnImageChangedSinceTheManifestIsNamed) {
    fs::copy_file(dir_ / "a.png", dir_ / "white.png",
                  fs::copy_options::overwrite_existing);
    const std::string why = refusal();
    EXPECT_NE(why.find((dir_ / "white.png").string() + ": changed since"),
              std::string::npos)
        << why;
    EXPECT_FALSE(wrote_anything());
    // The command prints that one line and exits 2.
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(run_stimuli_report(dir_, {}), 2);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(err, "lucent stimuli report: " + why + "\n");
    EXPECT_FALSE(wrote_anything());
}

TEST_F(SmallSet, AnUndecodableImageListedWithItsHashIsNamed) {
    const auto hash = [&] {
        return common::ContentHash().field(common::hash_file(dir_ / "white.png")).hex();
    };
    const std::string before = hash();
    std::ofstream(dir_ / "white.png", std::ios::trunc) << "not a picture";
    std::ifstream in(dir_ / "manifest.csv");
    std::string text((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
    in.close();
    ASSERT_NE(text.find(before), std::string::npos);
    text.replace(text.find(before), before.size(), hash());
    std::ofstream(dir_ / "manifest.csv", std::ios::trunc) << text;
    const std::string why = refusal();
    EXPECT_EQ(why.rfind((dir_ / "white.png").string() + ": ", 0), 0u) << why;
    EXPECT_FALSE(wrote_anything());
}

TEST_F(SmallSet, AFileNameOutsideTheDirectoryIsRefused) {
    std::ifstream in(dir_ / "manifest.csv");
    std::string text((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
    in.close();
    const auto at = text.find(",white.png,white.png,");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 21, ",white.png,../white.png,");
    std::ofstream(dir_ / "manifest.csv") << text;
    const std::string why = refusal();
    EXPECT_NE(why.find("'../white.png' is not a file name inside"), std::string::npos)
        << why;
}

// A grid as `lucent render` writes one: an entry varying two parameters expands into
// one series of a x b stimuli, listed row by row (id g_I_J, albedo = I, roughness = J),
// each a disc of its own colour (red by I, green by J) on `side` pixels.
void write_grid(const fs::path& dir, int side, int rows, int columns) {
    std::vector<ManifestRow> manifest;
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j < columns; ++j) {
            const std::string id = "g_" + std::to_string(i) + "_" + std::to_string(j);
            Image image(side, side);
            const float r = float(i + 1) / float(rows), g = float(j + 1) / float(columns);
            for (int y = 0; y < side; ++y)
                for (int x = 0; x < side; ++x) {
                    const double dx = x + 0.5 - side / 2.0, dy = y + 0.5 - side / 2.0;
                    if (dx * dx + dy * dy < side * side / 9.0)
                        image.set(x, y, {r, g, 0.2f, 1.0f});
                }
            write_image(dir / (id + ".png"), image);
            ManifestRow row = {{"id", id, false},
                               {"file", id + ".png", false},
                               {"files", id + ".png", false},
                               {"technique", "ward", false},
                               {"series", "grid", false},
                               {"mesh", "sphere", false},
                               {"mesh_faces", "100", true},
                               {"mesh_hash", "0", false},
                               {"width", std::to_string(side), true},
                               {"height", std::to_string(side), true},
                               {"background", "0,0,0", false},
                               {"albedo", std::to_string(i), true},
                               {"roughness", std::to_string(j), true}};
            const auto stats = compute_image_statistics(
                FloatImageView{image.width, image.height, 4, image.rgba});
            for (const auto& field : statistics_fields(stats)) row.push_back(field);
            row.push_back({"non_finite_pixels", "0", true});
            row.push_back({"software_version", "test", false});
            row.push_back({"build_hash", "test", false});
            row.push_back({"input_hash", "0", false});
            row.push_back({"content_hash",
                           common::ContentHash()
                               .field(common::hash_file(dir / (id + ".png")))
                               .hex(),
                           false});
            manifest.push_back(std::move(row));
        }
    write_manifest(dir, "grid", manifest);
}

std::pair<int, int> grid_cell(const std::string& id) {
    const auto second = id.find('_', 2);
    return {std::stoi(id.substr(2, second - 2)), std::stoi(id.substr(second + 1))};
}

// Issue 26 item 10: the report after a 400-stimulus grid render compared all 79,800
// pairs of its one series, silently (over 300 s). A series that large is compared on
// neighbouring levels only, with progress: 2 x 20 x 19 = 760 grid neighbours (one step
// of one parameter, the other equal) and the 19 row ends next to the next row's first
// stimulus in level (set) order: 779 pairs.
TEST(SetReportGrid, A400StimulusGridComparesNeighbouringLevelsWithProgress) {
    const fs::path dir = test::scratch_dir("set_report_grid_400");
    write_grid(dir, 16, 20, 20);
    std::size_t calls = 0, last_done = 0, last_total = 0;
    SetReportOptions options;
    options.on_pair = [&](std::size_t done, std::size_t total) {
        ++calls;
        last_done = done;
        last_total = total;
    };
    const SetReport r = measure_stimulus_set(dir, options);
    ASSERT_EQ(r.series.size(), 1u);
    EXPECT_EQ(r.series[0].members.size(), 400u);
    EXPECT_FALSE(r.series[0].all_pairs);
    EXPECT_EQ(r.series[0].pairs_possible, 400u * 399u / 2u);
    EXPECT_EQ(r.series[0].varying, (std::vector<std::string>{"albedo", "roughness"}));
    ASSERT_EQ(r.pairs.size(), 779u);
    EXPECT_EQ(calls, 779u);
    EXPECT_EQ(last_done, 779u);
    EXPECT_EQ(last_total, 779u);
    std::set<std::pair<std::size_t, std::size_t>> seen;
    std::size_t steps = 0, wraps = 0;
    for (const PairDifference& p : r.pairs) {
        EXPECT_TRUE(seen.emplace(p.first, p.second).second) << "listed twice";
        const auto [i1, j1] = grid_cell(r.stimuli[p.first].id);
        const auto [i2, j2] = grid_cell(r.stimuli[p.second].id);
        const bool step =
            (i1 == i2 && std::abs(j1 - j2) == 1) || (j1 == j2 && std::abs(i1 - i2) == 1);
        const bool wrap = i2 == i1 + 1 && j1 == 19 && j2 == 0;
        EXPECT_TRUE(step || wrap)
            << r.stimuli[p.first].id << " vs " << r.stimuli[p.second].id;
        steps += step;
        wraps += wrap;
        EXPECT_TRUE(p.adjacent);
        EXPECT_GT(p.delta_e.pixels, 0u);
    }
    EXPECT_EQ(steps, 760u);
    EXPECT_EQ(wraps, 19u);

    // The command says what it is doing before the long part, and the page says which
    // pairs it compared.
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(run_stimuli_report(dir, {}), 0);
    (void)::testing::internal::GetCapturedStdout();
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(
        err.rfind("lucent stimuli report: report: comparing 779 pairs of levels\n", 0),
        0u)
        << err;
    std::ifstream in(dir / "report.html");
    const std::string html((std::istreambuf_iterator<char>(in)),
                           std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("400 levels: neighbouring levels compared (779 of 79800 pairs)"),
              std::string::npos);
}

// A factor's few levels keep every pair (the thesis's Table 4.3): a 3 x 4 grid of 12 is
// compared on all 66 pairs; lowering all_pairs_up_to below 12 gives its neighbours,
// 3 x 3 + 2 x 4 = 17 grid steps and 2 row ends.
TEST(SetReportGrid, SeriesUpToTwelveLevelsCompareEveryPair) {
    const fs::path dir = test::scratch_dir("set_report_grid_12");
    write_grid(dir, 16, 3, 4);
    const SetReport all = measure_stimulus_set(dir);
    EXPECT_TRUE(all.series.at(0).all_pairs);
    EXPECT_EQ(all.pairs.size(), 66u);
    SetReportOptions neighbours;
    neighbours.all_pairs_up_to = 11;
    EXPECT_EQ(measure_stimulus_set(dir, neighbours).pairs.size(), 19u);
}

// Not a test: writes a 20 x 20 grid of 64-pixel stimuli for timing `lucent stimuli
// report` (run with --gtest_also_run_disabled_tests; the folder is printed).
TEST(SetReportGrid, DISABLED_WriteA400StimulusGridForTiming) {
    const fs::path dir = test::scratch_dir("set_report_grid_timing");
    write_grid(dir, 64, 20, 20);
    std::cout << "grid: " << dir.string() << "\n";
}

}  // namespace
}  // namespace lucent::stimuli
