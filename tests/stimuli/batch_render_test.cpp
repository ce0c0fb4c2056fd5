// Batch rendering: images + complete manifest, byte-identical re-runs, re-rendering only
// what changed, atomic files, and config errors that write nothing.
#include "stimuli/batch_render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "common/content_hash.h"
#include "lucent/version.h"
#include "renderer/core/image.h"
#include "renderer/core/mesh.h"
#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

std::string read_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

// A small set: two ward roughness values (a vary list) and one contrast_reversed.
std::string small_config(const std::string& reversed_weight = "0.6") {
    return "name = \"small\"\nresolution = [48, 40]\nformats = [\"exr\", \"png\", "
           "\"tif\"]\n"
           "[meshes]\nball = \"sphere:1k\"\n"
           "[defaults]\nao_rays = 8\n"
           "[[stimuli]]\nid = \"w_{roughness}\"\ntechnique = \"ward\"\n"
           "[stimuli.vary]\nroughness = [0.1, 0.3]\n"
           "[[stimuli]]\nid = \"cr\"\ntechnique = "
           "\"contrast_reversed\"\nreversed_diffuse = " +
           reversed_weight + "\n";
}

StimulusSet small_set(const std::string& reversed_weight = "0.6") {
    return parse_stimulus_set(small_config(reversed_weight), "small.toml", ".",
                              default_set_catalog());
}

BatchResult render(const StimulusSet& set, const std::filesystem::path& dir,
                   bool force = false, int jobs = 1) {
    BatchOptions options;
    options.out_dir = dir;
    options.force = force;
    options.jobs = jobs;
    options.progress = false;
    return render_stimulus_set(set, options);
}

TEST(BatchRender, WritesImagesAndACompleteManifest) {
    const auto dir = test::scratch_dir("batch_manifest");
    const auto set = small_set();
    const auto result = render(set, dir);
    EXPECT_EQ(result.rendered, 3u);
    const auto rows = read_manifest_csv(dir);
    ASSERT_EQ(rows.size(), 3u);
    const Mesh mesh = load_mesh("sphere:1k");
    for (const char* id : {"w_0.1", "w_0.3", "cr"}) {
        ASSERT_TRUE(rows.count(id)) << id;
        const auto& row = rows.at(id);
        EXPECT_EQ(row.at("file"), std::string(id) + ".exr");
        EXPECT_EQ(row.at("files"),
                  std::string(id) + ".exr;" + id + ".png;" + id + ".tif");
        EXPECT_EQ(row.at("mesh_hash"), mesh.content_hash);
        EXPECT_EQ(row.at("software_version"), version_string());
        EXPECT_EQ(row.at("ao_rays"), "8");
        EXPECT_EQ(row.at("input_hash").size(), 16u);
        // The content hash covers the files as written.
        common::ContentHash files;
        files.field(common::hash_file(dir / (std::string(id) + ".exr")));
        files.field(common::hash_file(dir / (std::string(id) + ".png")));
        files.field(common::hash_file(dir / (std::string(id) + ".tif")));
        EXPECT_EQ(row.at("content_hash"), files.hex());
        // Statistics agree with the EXR read back (float, lossless).
        const Image image = read_image(dir / (std::string(id) + ".exr"));
        EXPECT_EQ(image.width, 48);
        EXPECT_EQ(image.height, 40);
        const auto stats =
            compute_image_statistics(FloatImageView{48, 40, 4, image.rgba});
        EXPECT_EQ(row.at("object_pixels"), std::to_string(stats.object_pixels));
        EXPECT_NEAR(std::stod(row.at("rms_contrast")), stats.rms_contrast, 1e-6);
        EXPECT_NEAR(std::stod(row.at("mean_luminance")), stats.mean_luminance, 1e-6);
        EXPECT_GT(stats.object_pixels, 300u);
    }
    EXPECT_EQ(rows.at("w_0.1").at("roughness"), "0.1");
    EXPECT_EQ(rows.at("w_0.3").at("roughness"), "0.3");
    EXPECT_EQ(rows.at("cr").at("reversed_diffuse"), "0.6");
    EXPECT_EQ(rows.at("cr").at("diffuse_reflectance"),
              "");  // not a contrast_reversed knob
    // Nothing but the images and the manifest: no temporary files left.
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        (void)entry, ++files;
    EXPECT_EQ(files, 3u * 3u + 2u);
}

TEST(BatchRender, SecondRunReusesForceRerendersByteIdentically) {
    const auto dir = test::scratch_dir("batch_rerun");
    const auto set = small_set();
    render(set, dir);
    const std::string exr = read_bytes(dir / "w_0.3.exr"),
                      png = read_bytes(dir / "cr.png"),
                      tif = read_bytes(dir / "w_0.1.tif");
    const std::string manifest = read_bytes(dir / "manifest.csv");

    const auto again = render(set, dir);
    EXPECT_EQ(again.rendered, 0u);
    EXPECT_EQ(again.reused, 3u);
    EXPECT_EQ(read_bytes(dir / "manifest.csv"), manifest);

    // A later second: encoders that stamp the time would change the bytes.
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    const auto forced = render(set, dir, /*force=*/true, /*jobs=*/2);
    EXPECT_EQ(forced.rendered, 3u);
    EXPECT_EQ(read_bytes(dir / "w_0.3.exr"), exr);  // same inputs, same bytes
    EXPECT_EQ(read_bytes(dir / "cr.png"), png);
    EXPECT_EQ(read_bytes(dir / "w_0.1.tif"), tif);
    EXPECT_EQ(read_bytes(dir / "manifest.csv"), manifest);
}

// Encoding runs beside rendering: a file that cannot be written (here a directory sits
// where w_0.3.png goes) stops the whole run with an error naming it, on one worker or
// three; the stimulus before it stays finished and listed, nothing after it is.
TEST(BatchRender, AnEncodeFailureStopsTheRunAndKeepsWhatFinished) {
    for (const int jobs : {1, 3}) {
        const auto dir =
            test::scratch_dir("batch_encode_failure_" + std::to_string(jobs));
        std::filesystem::create_directories(dir / "w_0.3.png" / "blocker");
        try {
            render(small_set(), dir, /*force=*/false, jobs);
            ADD_FAILURE() << "the run should fail (" << jobs << " jobs)";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find("w_0.3.png"), std::string::npos)
                << e.what();
        }
        const auto rows = read_manifest_csv(dir);
        EXPECT_FALSE(rows.count("w_0.3"));
        for (const auto& [id, row] : rows)
            for (const char* ext : {".exr", ".png", ".tif"})
                EXPECT_TRUE(std::filesystem::is_regular_file(dir / (id + ext))) << id;
        if (jobs == 1) {  // one encoder, in set order: w_0.1 before, cr after
            EXPECT_TRUE(rows.count("w_0.1"));
            EXPECT_FALSE(rows.count("cr"));
        }
        // Once the obstacle is gone the set completes, reusing what finished.
        std::filesystem::remove_all(dir / "w_0.3.png");
        const auto resumed = render(small_set(), dir, /*force=*/false, jobs);
        EXPECT_EQ(resumed.reused, rows.size());
        EXPECT_EQ(resumed.rendered + resumed.reused, 3u);
        EXPECT_EQ(read_manifest_csv(dir).size(), 3u);
    }
}

TEST(BatchRender, RerendersOnlyChangedOrDamagedStimuli) {
    const auto dir = test::scratch_dir("batch_changed");
    render(small_set("0.6"), dir);
    const std::string untouched = read_bytes(dir / "w_0.1.png");
    const auto changed = render(small_set("0.9"), dir);  // only cr's parameters differ
    EXPECT_EQ(changed.rendered, 1u);
    EXPECT_EQ(changed.reused, 2u);
    EXPECT_EQ(read_manifest_csv(dir).at("cr").at("reversed_diffuse"), "0.9");

    // A truncated image (e.g. from an older, interrupted tool) is detected and redone.
    std::filesystem::resize_file(dir / "w_0.1.png", 10);
    const auto repaired = render(small_set("0.9"), dir);
    EXPECT_EQ(repaired.rendered, 1u);
    EXPECT_EQ(read_bytes(dir / "w_0.1.png"), untouched);
    // A deleted one too.
    std::filesystem::remove(dir / "w_0.3.exr");
    EXPECT_EQ(render(small_set("0.9"), dir).rendered, 1u);
}

TEST(BatchRender, ConfigErrorsExitTwoAndWriteNothing) {
    const auto dir = test::scratch_dir("batch_errors");
    std::ofstream(dir / "bad.toml")
        << small_config() << "roughness = 2\n";  // in cr, out of range
    std::ofstream(dir / "bad_mesh.toml")
        << "[meshes]\nm = \"absent.obj\"\n"
           "[[stimuli]]\nid = \"a\"\ntechnique = \"ward\"\n";
    std::ofstream(dir / "broken_mesh.obj") << "this is not an obj file\n";
    std::ofstream(dir / "broken_mesh.toml")
        << "[meshes]\nm = \"broken_mesh.obj\"\n"
           "[[stimuli]]\nid = \"a\"\ntechnique = \"ward\"\n";
    for (const char* config :
         {"bad.toml", "bad_mesh.toml", "broken_mesh.toml", "absent.toml"}) {
        const auto out = dir / (std::string("out_") + config);
        testing::internal::CaptureStderr();
        const int code =
            run_render_set_command((dir / config).string(), "", out.string(), 1, false);
        const std::string err = testing::internal::GetCapturedStderr();
        EXPECT_EQ(code, 2) << config << ": " << err;
        EXPECT_NE(err.find(config), std::string::npos) << err;          // names the file
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;  // one line
        EXPECT_FALSE(std::filesystem::exists(out)) << config;
    }
    testing::internal::CaptureStderr();
    EXPECT_EQ(run_render_set_command("", "thesis", (dir / "o").string(), 0, false), 2);
    EXPECT_NE(testing::internal::GetCapturedStderr().find("--jobs"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir / "o"));
}

}  // namespace
}  // namespace lucent::stimuli
