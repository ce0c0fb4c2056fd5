// "Add to stimulus set" without a window: the entry is appended with the file's text and
// comments kept, the stimulus-set loader reads back exactly the explorer's values, a new
// mesh is added under [meshes], and a result that does not load leaves the file as it
// was.
#include "stimuli/explorer/stimulus_entry.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"
#include "tests/support/test_paths.h"

namespace lucent::explorer {
namespace {

const char* kConfig = R"(# A hand-written set; this comment must survive.
name = "hand"
resolution = [96, 64]
formats = ["png"]

[meshes]
knot = "torus_knot:4k"   # the usual knot

[[stimuli]]
id = "first"
technique = "empirical"
backlight = 1.2 # inline comment
)";

std::string read(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void write(const std::filesystem::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

StimulusEntry entry_for(const std::string& technique, const std::string& mesh) {
    StimulusEntry entry;
    entry.id = "explored";
    entry.technique = technique;
    entry.mesh = mesh;
    entry.values = resolve_knob_values(
        knobs_for(find_technique(technique)),
        std::vector<KnobAssignment>{{"albedo", "0.25,0.5,0.75"},
                                    {"light_direction", "-0.3,0.8,0.5"}});
    return entry;
}

const Stimulus& find(const StimulusSet& set, const std::string& id) {
    for (const auto& s : set.stimuli)
        if (s.id == id) return s;
    throw std::runtime_error("no stimulus " + id);
}

TEST(AppendStimulus, KeepsTheFileAndReadsBackTheExactValues) {
    const auto config = test::scratch_dir("explorer_append") / "set.toml";
    write(config, kConfig);
    StimulusEntry entry = entry_for("empirical", "torus_knot:4k");
    entry.values.set("backlight", 3.3);
    entry.values.set("blur_kernel", std::string("3"));
    EXPECT_EQ(append_stimulus(config, entry), "explored");
    const std::string text = read(config);
    EXPECT_EQ(text.substr(0, std::string(kConfig).size()),
              kConfig);  // nothing above changed
    const auto set = load_stimulus_set(config, default_set_catalog());
    ASSERT_EQ(set.stimuli.size(), 2u);
    const auto& added = find(set, "explored");
    EXPECT_EQ(added.mesh_name, "knot");  // the existing entry for the same spec
    EXPECT_EQ(added.values.all(), entry.values.all());
    // A second append of the same id gets a fresh one.
    EXPECT_EQ(append_stimulus(config, entry), "explored_2");
}

TEST(AppendStimulus, AddsANewMeshUnderTheMeshesTable) {
    const auto config = test::scratch_dir("explorer_append_mesh") / "set.toml";
    std::string text = kConfig;
    text.replace(text.find("technique = \"empirical\""), 0, "mesh = \"knot\"\n");
    write(config, text);
    const StimulusEntry entry = entry_for("ward", "sphere:2k");
    append_stimulus(config, entry);
    const auto set = load_stimulus_set(config, default_set_catalog());
    const auto& added = find(set, "explored");
    EXPECT_EQ(added.mesh, "sphere:2k");
    EXPECT_EQ(added.technique, "ward");
    EXPECT_EQ(added.values.all(), entry.values.all());
    EXPECT_NE(read(config).find("# the usual knot"), std::string::npos);
    EXPECT_EQ(find(set, "first").mesh, "torus_knot:4k");
}

TEST(AppendStimulus, RefusesANewMeshThatWouldMakeOtherEntriesAmbiguous) {
    // "first" names no mesh: it uses the only one, which a second mesh would break.
    const auto config = test::scratch_dir("explorer_append_ambiguous") / "set.toml";
    write(config, kConfig);
    try {
        append_stimulus(config, entry_for("ward", "sphere:2k"));
        FAIL() << "expected an error";
    } catch (const StimulusSetError& e) {
        EXPECT_NE(std::string(e.what()).find("set.toml:9: mesh:"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(read(config), kConfig);
}

TEST(AppendStimulus, CreatesAMissingFile) {
    const auto config = test::scratch_dir("explorer_append_new") / "new.toml";
    StimulusEntry entry = entry_for("contrast_reversed", "torus:1k");
    entry.width = 80;
    entry.height = 60;
    append_stimulus(config, entry);
    const auto set = load_stimulus_set(config, default_set_catalog());
    EXPECT_EQ(set.width, 80);
    EXPECT_EQ(set.height, 60);
    ASSERT_EQ(set.stimuli.size(), 1u);
    EXPECT_EQ(set.stimuli[0].values.all(), entry.values.all());
}

TEST(AppendStimulus, RollsBackWhenTheResultDoesNotLoad) {
    const auto config = test::scratch_dir("explorer_append_rollback") / "set.toml";
    write(config, kConfig);
    StimulusEntry entry = entry_for("empirical", "torus_knot:4k");
    entry.id = "not a valid id!";  // the loader rejects it after the append
    EXPECT_THROW(append_stimulus(config, entry), StimulusSetError);
    EXPECT_EQ(read(config), kConfig);
}

TEST(AppendStimulus, RefusesAnInvalidConfigWithoutTouchingIt) {
    const auto config = test::scratch_dir("explorer_append_invalid") / "set.toml";
    const std::string broken = std::string(kConfig) + "unknown_key = 1\n";
    write(config, broken);
    EXPECT_THROW(append_stimulus(config, entry_for("empirical", "torus_knot:4k")),
                 StimulusSetError);
    EXPECT_EQ(read(config), broken);
}

}  // namespace
}  // namespace lucent::explorer
