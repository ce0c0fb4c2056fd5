// Interrupted batch renders (a throw after N stimuli, a SIGKILL mid-set): the manifest
// on disk always describes exactly the files it lists, and the next run renders only the
// rest. Also: NaN produced by a shader is counted in the manifest and fails the command.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "common/content_hash.h"
#include "renderer/core/image.h"
#include "renderer/core/mesh.h"
#include "renderer/gl/program.h"
#include "stimuli/batch_render.h"
#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

constexpr std::size_t kStimuli = 8;

// Eight tiny ward stimuli (a vary list); `scale` changes every stimulus's parameters.
StimulusSet eight_stimuli(const std::string& scale = "1") {
    const std::string config =
        "name = \"eight\"\nresolution = [24, 20]\nformats = [\"png\", \"exr\"]\n"
        "[meshes]\nball = \"sphere:1k\"\n"
        "[defaults]\nao_rays = 8\nspecular_reflectance = 0.05\n"
        "[[stimuli]]\nid = \"w_{roughness}\"\ntechnique = \"ward\"\n"
        "diffuse_reflectance = " +
        scale +
        "\n"
        "[stimuli.vary]\nroughness = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]\n";
    return parse_stimulus_set(config, "eight.toml", ".", default_set_catalog());
}

BatchOptions options_for(const std::filesystem::path& dir, int jobs = 1) {
    BatchOptions options;
    options.out_dir = dir;
    options.jobs = jobs;
    options.progress = false;
    return options;
}

std::vector<std::string> split_files(const std::string& files) {
    std::vector<std::string> names;
    std::stringstream in(files);
    for (std::string name; std::getline(in, name, ';');) names.push_back(name);
    return names;
}

// Every manifest row's content hash, recomputed from the files on disk, and its input
// hash against `set`'s; returns the number of rows (ADD_FAILURE for each mismatch).
std::size_t check_manifest_matches_files(const std::filesystem::path& dir,
                                         const StimulusSet& set) {
    const auto rows = read_manifest_csv(dir);
    const Mesh mesh = load_mesh("sphere:1k");
    for (const auto& [id, row] : rows) {
        common::ContentHash files;
        for (const auto& name : split_files(row.at("files")))
            files.field(common::hash_file(dir / name));
        EXPECT_EQ(row.at("content_hash"), files.hex()) << id << " in " << dir;
        const auto stimulus =
            std::find_if(set.stimuli.begin(), set.stimuli.end(),
                         [&id = id](const Stimulus& s) { return s.id == id; });
        if (stimulus == set.stimuli.end()) {
            ADD_FAILURE() << id << " is not a stimulus of the set";
            continue;
        }
        EXPECT_EQ(row.at("input_hash"), input_hash(set, *stimulus, mesh.content_hash))
            << id << " describes another run's inputs";
    }
    return rows.size();
}

struct Interrupted : std::runtime_error {
    using std::runtime_error::runtime_error;
};

TEST(BatchRenderCrash, InterruptedRenderKeepsFinishedStimuliAndResumesAfterThem) {
    const auto dir = test::scratch_dir("batch_crash_throw");
    const auto set = eight_stimuli();
    auto options = options_for(dir);
    options.after_stimulus = [&](const std::string&, std::size_t finished) {
        // After every stimulus, the manifest on disk lists exactly the finished ones.
        EXPECT_EQ(check_manifest_matches_files(dir, set), finished);
        if (finished == 3) throw Interrupted("interrupted after 3");
    };
    EXPECT_THROW(render_stimulus_set(set, options), std::runtime_error);
    EXPECT_EQ(check_manifest_matches_files(dir, set), 3u);

    const auto resumed = render_stimulus_set(set, options_for(dir));
    EXPECT_EQ(resumed.reused, 3u);
    EXPECT_EQ(resumed.rendered, kStimuli - 3);
    EXPECT_EQ(check_manifest_matches_files(dir, set), kStimuli);
}

// A real kill: the child process renders with two workers and SIGKILLs itself once four
// stimuli are finished (no unwinding, no destructors, as a power cut or `kill -9`).
TEST(BatchRenderCrash, KilledRenderResumesWhereItStopped) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const auto dir = test::binary_dir() / "test-scratch" / "batch_crash_kill";
    const auto set = eight_stimuli();
    const auto render_and_die = [&] {
        std::filesystem::remove_all(dir);
        auto options = options_for(dir, /*jobs=*/2);
        options.after_stimulus = [](const std::string&, std::size_t finished) {
            if (finished == 4) raise(SIGKILL);
        };
        render_stimulus_set(set, options);
    };
    EXPECT_EXIT(render_and_die(), testing::KilledBySignal(SIGKILL), "");

    // Four finished, perhaps a fifth from the other worker: all listed and intact.
    const std::size_t kept = check_manifest_matches_files(dir, set);
    EXPECT_GE(kept, 4u);
    EXPECT_LE(kept, 5u);
    const auto resumed = render_stimulus_set(set, options_for(dir));
    EXPECT_EQ(resumed.reused, kept);
    EXPECT_EQ(resumed.rendered, kStimuli - kept);
    EXPECT_EQ(check_manifest_matches_files(dir, set), kStimuli);
}

// A set rendered once, then changed everywhere and interrupted: the old rows are gone
// before the first file is replaced, so the manifest never claims an overwritten file.
TEST(BatchRenderCrash, ManifestNeverDescribesFilesTheRunOverwrote) {
    const auto dir = test::scratch_dir("batch_crash_overwrite");
    ASSERT_EQ(render_stimulus_set(eight_stimuli("1"), options_for(dir)).rendered,
              kStimuli);
    const auto changed = eight_stimuli("0.5");
    auto options = options_for(dir);
    options.after_stimulus = [&](const std::string&, std::size_t finished) {
        EXPECT_EQ(check_manifest_matches_files(dir, changed), finished);
        if (finished == 2) throw Interrupted("interrupted after 2");
    };
    EXPECT_THROW(render_stimulus_set(changed, options), std::runtime_error);
    EXPECT_EQ(check_manifest_matches_files(dir, changed), 2u);
    const auto resumed = render_stimulus_set(changed, options_for(dir));
    EXPECT_EQ(resumed.rendered, kStimuli - 2);
    EXPECT_EQ(check_manifest_matches_files(dir, changed), kStimuli);
}

// A shader that writes NaN (read from LUCENT_SHADER_DIR, as in developer mode) over the
// object: every object pixel of the clean render is counted, the files stay finite, and
// the command warns per stimulus and exits 1.
TEST(BatchRenderCrash, NanFromAShaderIsCountedInTheManifest) {
    const auto root = test::scratch_dir("batch_nan");
    const auto config = root / "eight.toml";
    {
        std::ofstream out(config);
        out << "name = \"two\"\nresolution = [24, 20]\nformats = [\"exr\"]\n"
               "[meshes]\nball = \"sphere:1k\"\n[defaults]\nao_rays = 8\n"
               "[[stimuli]]\nid = \"w_{roughness}\"\ntechnique = \"ward\"\n"
               "[stimuli.vary]\nroughness = [0.1, 0.3]\n";
    }
    testing::internal::CaptureStderr();
    ASSERT_EQ(
        run_render_set_command(config.string(), "", (root / "clean").string(), 1, false),
        0);
    testing::internal::GetCapturedStderr();
    const auto clean = read_manifest_csv(root / "clean");
    ASSERT_EQ(clean.size(), 2u);
    EXPECT_EQ(clean.at("w_0.1").at("non_finite_pixels"), "0");

    // The shipped shader with a NaN written after its own main().
    const std::string relative = "techniques/ward/shaders/shade.frag";
    std::string source = gl::shader_source(relative);
    const auto at = source.find("void main()");
    ASSERT_NE(at, std::string::npos);
    source.replace(at, 11, "void shade_main()");
    source +=
        "\nvoid main() { shade_main(); out_colour = vec4(uintBitsToFloat(0x7fc00000u)); "
        "}\n";
    const auto shaders = root / "shaders";
    std::filesystem::create_directories((shaders / relative).parent_path());
    std::ofstream(shaders / relative) << source;
    setenv("LUCENT_SHADER_DIR", shaders.c_str(), 1);
    testing::internal::CaptureStderr();
    const int code =
        run_render_set_command(config.string(), "", (root / "nan").string(), 1, false);
    const std::string err = testing::internal::GetCapturedStderr();
    unsetenv("LUCENT_SHADER_DIR");

    EXPECT_EQ(code, 1) << err;
    const auto rows = read_manifest_csv(root / "nan");
    ASSERT_EQ(rows.size(), 2u);
    for (const char* id : {"w_0.1", "w_0.3"}) {
        const std::size_t object = std::stoul(clean.at(id).at("object_pixels"));
        EXPECT_GT(object, 100u);
        EXPECT_EQ(rows.at(id).at("non_finite_pixels"), std::to_string(object)) << id;
        EXPECT_NE(err.find("warning: stimulus '" + std::string(id) + "': " +
                           std::to_string(object) + " pixels had NaN or Inf values"),
                  std::string::npos)
            << err;
        for (float v : read_image(root / "nan" / (std::string(id) + ".exr")).rgba)
            ASSERT_TRUE(std::isfinite(v)) << id;
    }
    // A re-run reuses the files and still reports them.
    setenv("LUCENT_SHADER_DIR", shaders.c_str(), 1);
    testing::internal::CaptureStderr();
    EXPECT_EQ(
        run_render_set_command(config.string(), "", (root / "nan").string(), 1, false),
        1);
    EXPECT_NE(testing::internal::GetCapturedStderr().find("non_finite_pixels"),
              std::string::npos);
    unsetenv("LUCENT_SHADER_DIR");
}

}  // namespace
}  // namespace lucent::stimuli
