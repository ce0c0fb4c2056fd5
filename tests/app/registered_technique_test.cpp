// Issue 27 item 2: a technique that exists only in this test, registered here, is seen by
// every layer that asks the registry, with no other edit: `lucent render` (run in
// process), stimulus sets, protocol validation and the values a study records, and
// `lucent bench accuracy`. (The explorer's panels: explorer_gl_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/full_cli.h"
#include "renderer/core/image.h"
#include "renderer/techniques/registry.h"
#include "stimuli/manifest.h"
#include "study/protocol.h"
#include "study/session/stimulus_provenance.h"
#include "tests/support/flat_test_technique.h"
#include "tests/support/test_paths.h"

namespace lucent::app {
namespace {

using test::FlatTestTechnique;

int run(std::vector<std::string> args) {
    args.insert(args.begin(), "lucent");
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    return run_full_cli(static_cast<int>(argv.size()), argv.data());
}

std::vector<std::map<std::string, std::string>> read_csv(
    const std::filesystem::path& path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> header;
    std::stringstream head(line);
    for (std::string cell; std::getline(head, cell, ',');) header.push_back(cell);
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        std::stringstream cells(line);
        std::map<std::string, std::string> row;
        std::string cell;
        for (std::size_t i = 0; i < header.size() && std::getline(cells, cell, ','); ++i)
            row[header[i]] = cell;
        rows.push_back(row);
    }
    return rows;
}

class RegisteredTechnique : public ::testing::Test {
protected:
    const FlatTestTechnique flat_;
    const TechniqueRegistration registration_{flat_};
};

TEST_F(RegisteredTechnique, LucentRenderRendersIt) {
    const auto out = test::scratch_dir("registered_render") / "flat.exr";
    ASSERT_EQ(run({"render", "--technique", "test_flat", "--mesh", "sphere:200", "--size",
                   "12x8", "--set", "flat_colour=0.2,0.4,0.9", "--set", "levels=3",
                   "--out", out.string()}),
              0);
    const Image image = read_image(out);
    ASSERT_EQ(image.width, 12);
    ASSERT_EQ(image.height, 8);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            // Three levels: 0, 0.5, 1; 0.2 -> 0, 0.4 -> 0.5, 0.9 -> 1.
            EXPECT_EQ(image.at(x, y), glm::vec4(0.0f, 0.5f, 1.0f, 1.0f)) << x << "," << y;
        }
}

TEST_F(RegisteredTechnique, AStimulusSetRendersItAndItsManifestListsItsKnobs) {
    const auto dir = test::scratch_dir("registered_set");
    const auto config = dir / "set.toml";
    std::ofstream(config) << "name = \"flat\"\nresolution = [8, 8]\nformats = [\"exr\"]\n"
                             "[meshes]\nball = \"sphere:200\"\n"
                             "[[stimuli]]\nid = \"grey\"\ntechnique = \"test_flat\"\n"
                             "mesh = \"ball\"\nflat_colour = [0.5, 0.5, 0.5]\n";
    ASSERT_EQ(
        run({"render", config.string(), "--out", (dir / "out").string(), "--force"}), 0);
    const auto manifest = stimuli::read_manifest_csv(dir / "out");
    ASSERT_TRUE(manifest.count("grey"));
    EXPECT_EQ(manifest.at("grey").at("technique"), "test_flat");
    EXPECT_EQ(manifest.at("grey").at("flat_colour"), "0.5,0.5,0.5");
    EXPECT_EQ(manifest.at("grey").at("levels"), "256");
    const Image image = read_image(dir / "out" / "grey.exr");
    EXPECT_EQ(image.at(3, 3).g, FlatTestTechnique::quantised(0.5, 256));
}

TEST_F(RegisteredTechnique, AProtocolNamingItIsValidAndRecordsItsValues) {
    const char* text = R"toml(
[study]
name = "flat"
[[questions]]
id = "translucent"
text = "The object looks translucent."
[[stimuli]]
id = "f"
technique = "test_flat"
mesh = "sphere:200"
params = { levels = 17 }
[[blocks]]
id = "main"
stimuli = ["f"]
)toml";
    const study::Protocol protocol = study::parse_protocol(text, "flat.toml");
    const auto rows = study::resolve_stimuli(protocol, "");
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_EQ(rows[0].technique, "test_flat");
    std::map<std::string, std::string> values(rows[0].values.begin(),
                                              rows[0].values.end());
    EXPECT_EQ(values.at("levels"), "17");
    EXPECT_EQ(values.at("flat_colour"), "0.3,0.5,0.7");
}

TEST_F(RegisteredTechnique, BenchAccuracyMeasuresItsQualityKnobAgainstItsReference) {
    const auto csv = test::scratch_dir("registered_bench") / "accuracy.csv";
    ASSERT_EQ(run({"bench", "accuracy", "--technique", "test_flat", "--mesh",
                   "sphere:200", "--size", "16x16", "--frames", "1", "--csv",
                   csv.string(), "--svg", (csv.parent_path() / "accuracy.svg").string()}),
              0);
    const auto rows = read_csv(csv);
    ASSERT_EQ(rows.size(), 4u);  // levels 2, 5, 17, 257
    for (const auto& row : rows) {
        ASSERT_EQ(row.at("knob"), "levels");
        const int levels = std::stoi(row.at("value"));
        // The closed form: the largest channel error of the quantised default colour.
        double worst = 0.0;
        for (double c : {0.3, 0.5, 0.7})
            worst =
                std::max(worst, std::abs(double(FlatTestTechnique::quantised(c, levels)) -
                                         double(float(c))));
        EXPECT_NEAR(std::stod(row.at("max")), worst, 1e-6) << levels;
    }
}

}  // namespace
}  // namespace lucent::app
