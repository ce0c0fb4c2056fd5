// The built-in `heterogeneous` set: htsm stimuli in three interior structures at two
// transport distances, each Td one factor series.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

#include "core/density_volume.h"
#include "stimulus_set.h"
#include "test_paths.h"

namespace lucent::stimuli {
namespace {

TEST(HeterogeneousPreset, EmbeddedTextIsTheCommittedFile) {
    std::ifstream in(test::source_dir() / "stimuli/presets/heterogeneous.toml",
                     std::ios::binary);
    std::ostringstream file;
    file << in.rdbuf();
    ASSERT_TRUE(preset_text("heterogeneous").has_value());
    EXPECT_EQ(std::string(*preset_text("heterogeneous")), file.str());
}

TEST(HeterogeneousPreset, ThreeStructuresAtTwoTransportDistances) {
    const auto set = load_preset("heterogeneous", default_catalog());
    ASSERT_EQ(set.stimuli.size(), 6u);
    std::set<std::string> hashes;
    for (const Stimulus& s : set.stimuli) {
        EXPECT_EQ(s.technique, "htsm") << s.id;
        const double td = s.parameters.scalar("transport_distance");
        EXPECT_EQ(s.series, td == 0.25 ? "td_0.25" : "td_0.5") << s.id;
        const auto volume = density_from_knobs(s.parameters);
        ASSERT_NE(volume, nullptr);
        // The homogeneous control is the planner's constant-density case; the others
        // are structured.
        EXPECT_EQ(volume->constant(), s.id.rfind("homogeneous", 0) == 0) << s.id;
        hashes.insert(volume->content_hash);
    }
    EXPECT_EQ(hashes.size(), 3u);  // one volume per structure, shared across Td
}

}  // namespace
}  // namespace lucent::stimuli
