// Manifests: writing then reading a manifest back.
#include "stimuli/manifest.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

TEST(Manifest, WritesUnionOfColumnsAndReadsBack) {
    const auto dir = test::scratch_dir("manifest_roundtrip");
    const std::vector<ManifestRow> rows = {
        {{"id", "a", false},
         {"albedo", "0.8,0.5,0.3", false},
         {"rms_contrast", "0.25", true}},
        {{"id", "b", false}, {"roughness", "0.1", true}, {"rms_contrast", "0.5", true}},
    };
    write_manifest(dir, "demo", rows);
    std::ifstream csv(dir / "manifest.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header, "id,albedo,rms_contrast,roughness");
    const auto back = read_manifest_csv(dir);
    ASSERT_EQ(back.size(), 2u);
    EXPECT_EQ(back.at("a").at("albedo"), "0.8,0.5,0.3");
    EXPECT_EQ(back.at("a").at("roughness"), "");
    EXPECT_EQ(back.at("b").at("rms_contrast"), "0.5");
    std::ifstream json_in(dir / "manifest.json");
    std::stringstream json;
    json << json_in.rdbuf();
    EXPECT_NE(json.str().find("\"set\": \"demo\""), std::string::npos);
    EXPECT_NE(json.str().find(
                  "{\"id\": \"a\", \"albedo\": \"0.8,0.5,0.3\", \"rms_contrast\": 0.25}"),
              std::string::npos)
        << json.str();
    // No temporary files are left behind.
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        (void)entry, ++files;
    EXPECT_EQ(files, 2);
    // An absent manifest reads as empty (everything is rendered again).
    EXPECT_TRUE(read_manifest_csv(test::scratch_dir("manifest_absent")).empty());
}

TEST(Manifest, StatisticsFieldsNeverHoldNaN) {
    ImageStatistics stats;
    stats.rms_contrast = std::nan("");
    stats.skewness = std::numeric_limits<double>::infinity();
    stats.luminance_histogram.assign(16, 0);
    for (const auto& field : statistics_fields(stats)) {
        EXPECT_EQ(field.text.find("nan"), std::string::npos) << field.column;
        EXPECT_EQ(field.text.find("inf"), std::string::npos) << field.column;
    }
    EXPECT_EQ(statistics_fields(stats).size(), 6u + 16u);
}

}  // namespace
}  // namespace lucent::stimuli
