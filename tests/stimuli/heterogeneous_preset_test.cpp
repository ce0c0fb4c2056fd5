// The built-in `heterogeneous` set: htsm stimuli in three interior structures at two
// transport distances, each Td one factor series.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "renderer/core/density_volume.h"
#include "renderer/core/stimulus_set.h"
#include "stimuli/batch_render.h"
#include "stimuli/manifest.h"
#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

TEST(HeterogeneousPreset, EmbeddedTextIsTheCommittedFile) {
    std::ifstream in(test::source_dir() / "renderer/core/presets/heterogeneous.toml",
                     std::ios::binary);
    std::ostringstream file;
    file << in.rdbuf();
    ASSERT_TRUE(set_preset_text("heterogeneous").has_value());
    EXPECT_EQ(std::string(*set_preset_text("heterogeneous")), file.str());
}

TEST(HeterogeneousPreset, ThreeStructuresAtTwoTransportDistances) {
    const auto set = load_set_preset("heterogeneous", default_set_catalog());
    ASSERT_EQ(set.stimuli.size(), 6u);
    std::set<std::string> hashes;
    for (const Stimulus& s : set.stimuli) {
        EXPECT_EQ(s.technique, "htsm") << s.id;
        const double td = s.values.scalar("transport_distance");
        EXPECT_EQ(s.series, td == 0.25 ? "td_0.25" : "td_0.5") << s.id;
        const auto volume = density_from_knobs(s.values);
        ASSERT_NE(volume, nullptr);
        // The homogeneous control is the planner's constant-density case; the others
        // are structured.
        EXPECT_EQ(volume->constant(), s.id.rfind("homogeneous", 0) == 0) << s.id;
        hashes.insert(volume->content_hash);
    }
    EXPECT_EQ(hashes.size(), 3u);  // one volume per structure, shared across Td
}

// The volume's content hash travels like the mesh hash: a manifest column beside the
// spec, and part of the input hash, so a density file changed under the same path is
// rendered again, even with its size and modification time unchanged (rewritten within
// a coarse timestamp's tick; here the old time is put back).
TEST(HeterogeneousPreset, ManifestCarriesTheDensityHashAndAChangedFileRerenders) {
    const auto dir = test::scratch_dir("htsm_density_manifest");
    const std::string volume_path = (dir / "volume.nrrd").string();
    const std::filesystem::path out = dir / "out";
    write_density_nrrd(*make_density_volume("cube", 8, 1.0), volume_path);
    const std::string config =
        "name = \"d\"\nresolution = [24, 24]\n[meshes]\nball = "
        "\"sphere:1k\"\n[[stimuli]]\nid = \"h\"\ntechnique = "
        "\"htsm\"\ndensity = \"" +
        volume_path + "\"\n";
    const auto set = parse_stimulus_set(config, "d.toml", dir, default_set_catalog());
    BatchOptions options;
    options.out_dir = out;
    options.progress = false;
    EXPECT_EQ(render_stimulus_set(set, options).rendered, 1u);
    auto rows = read_manifest_csv(out);
    const std::string first = rows.at("h").at("density_hash");
    EXPECT_EQ(first, make_density_volume("cube", 8, 1.0)->content_hash);
    EXPECT_EQ(rows.at("h").at("density"), volume_path);
    // Unchanged: reused. Changed file, same spec: rendered again with the new hash.
    EXPECT_EQ(render_stimulus_set(set, options).rendered, 0u);
    const auto size = std::filesystem::file_size(volume_path);
    const auto written = std::filesystem::last_write_time(volume_path);
    write_density_nrrd(*make_density_volume("spheres", 8, 1.0), volume_path);
    std::filesystem::last_write_time(volume_path, written);
    ASSERT_EQ(std::filesystem::file_size(volume_path), size);
    EXPECT_EQ(render_stimulus_set(set, options).rendered, 1u);
    rows = read_manifest_csv(out);
    EXPECT_EQ(rows.at("h").at("density_hash"),
              make_density_volume("spheres", 8, 1.0)->content_hash);
    EXPECT_NE(rows.at("h").at("density_hash"), first);
}

}  // namespace
}  // namespace lucent::stimuli
