// The built-in `thesis` set: Table 4.3 of the thesis and the ward / contrast_reversed
// pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"
#include "tests/support/test_paths.h"

namespace lucent::stimuli {
namespace {

const Stimulus& find(const StimulusSet& set, const std::string& id) {
    for (const auto& s : set.stimuli)
        if (s.id == id) return s;
    throw std::runtime_error("no stimulus " + id);
}

TEST(ThesisPreset, EmbeddedTextIsTheCommittedExampleFile) {
    std::ifstream in(test::source_dir() / "renderer/core/presets/thesis.toml",
                     std::ios::binary);
    std::ostringstream file;
    file << in.rdbuf();
    ASSERT_TRUE(set_preset_text("thesis").has_value());
    EXPECT_EQ(std::string(*set_preset_text("thesis")), file.str());
    EXPECT_FALSE(set_preset_text("nope").has_value());
    EXPECT_THROW(load_set_preset("nope", default_set_catalog()), StimulusSetError);
}

TEST(ThesisPreset, NineEmpiricalRendersOfTable43) {
    const auto set = load_set_preset("thesis", default_set_catalog());
    EXPECT_EQ(set.width, 512);
    EXPECT_EQ(set.height, 512);
    // 18 rated pictures and the study's two practice pictures, outside every series.
    ASSERT_EQ(set.stimuli.size(), 20u);
    EXPECT_EQ(find(set, "practice_a").series, "");
    EXPECT_EQ(find(set, "practice_b").series, "");
    // Table 4.3 (seeds.md, section A): r / wb / Kb per row.
    const double table[9][3] = {{25, 1.2, 0.2}, {18, 1.2, 0.2}, {30, 1.2, 0.2},
                                {25, 1.2, 0.2}, {25, 0.8, 0.2}, {25, 1.6, 0.2},
                                {25, 1.2, 0.2}, {25, 1.2, 0.0}, {25, 1.2, 0.5}};
    for (int row = 0; row < 9; ++row) {
        const auto& s = find(set, "empirical_row_" + std::to_string(row + 1));
        EXPECT_EQ(s.technique, "empirical");
        EXPECT_EQ(s.mesh.substr(0, s.mesh.find(':')),
                  "torus_knot");  // built-in
        EXPECT_DOUBLE_EQ(s.values.scalar("thickness_exponent"), table[row][0]) << row;
        EXPECT_DOUBLE_EQ(s.values.scalar("backlight"), table[row][1]) << row;
        EXPECT_DOUBLE_EQ(s.values.scalar("diffuse_weight"), table[row][2]) << row;
    }
}

TEST(ThesisPreset, EachSeriesIsOneColourAndRows147DifferOnlyInColour) {
    // "the first row (purple) ... the second row (green) ... the third row (blue)"
    // (thesis Sec. 4.2): saturated albedos, one per factor series.
    const auto set = load_set_preset("thesis", default_set_catalog());
    const char* series[3] = {"thickness_exponent", "backlight", "diffuse_weight"};
    for (int row = 0; row < 9; ++row) {
        const auto& s = find(set, "empirical_row_" + std::to_string(row + 1));
        EXPECT_EQ(s.series, series[row / 3]) << row;
        const glm::dvec3 c = s.values.vec3("albedo");
        if (row / 3 == 0) EXPECT_TRUE(c.r > 2 * c.g && c.b > 2 * c.g) << "purple " << row;
        if (row / 3 == 1) EXPECT_TRUE(c.g > 2 * c.r && c.g > 2 * c.b) << "green " << row;
        if (row / 3 == 2) EXPECT_TRUE(c.b > 2 * c.r && c.b > 2 * c.g) << "blue " << row;
        EXPECT_EQ(format_knob_value(s.values.get("albedo")),
                  format_knob_value(
                      find(set, "empirical_row_" + std::to_string(row / 3 * 3 + 1))
                          .values.get("albedo")))
            << "one colour per series, row " << row;
    }
    const auto& one = find(set, "empirical_row_1");
    for (const char* other : {"empirical_row_4", "empirical_row_7"}) {
        const auto& s = find(set, other);
        EXPECT_NE(format_knob_value(s.values.get("albedo")),
                  format_knob_value(one.values.get("albedo")));
        for (const auto& [name, value] : one.values.all())
            if (name != "albedo")
                EXPECT_EQ(format_knob_value(value), format_knob_value(s.values.get(name)))
                    << other << " " << name;
    }
}

TEST(ThesisPreset, WardAndContrastReversedPairsShareEveryParameter) {
    const auto set = load_set_preset("thesis", default_set_catalog());
    for (const char* material : {"jade", "wax", "jade_strong"}) {
        const auto& ward = find(set, std::string("ward_") + material);
        const auto& reversed = find(set, std::string("contrast_reversed_") + material);
        EXPECT_EQ(ward.technique, "ward");
        EXPECT_EQ(reversed.technique, "contrast_reversed");
        EXPECT_EQ(ward.mesh, reversed.mesh);
        EXPECT_EQ(ward.values.scalar("diffuse_reflectance"),
                  reversed.values.scalar("reversed_diffuse"));
        for (const auto& [name, value] : ward.values.all()) {
            if (name == "diffuse_reflectance") continue;
            ASSERT_TRUE(reversed.values.contains(name)) << name;
            EXPECT_EQ(format_knob_value(value),
                      format_knob_value(reversed.values.get(name)))
                << material << " " << name;
        }
    }
    // Jade and wax differ only in roughness (Domon et al. Figs. 3a / 4b) ...
    const auto& jade = find(set, "ward_jade");
    const auto& wax = find(set, "ward_wax");
    for (const auto& [name, value] : jade.values.all())
        if (name != "roughness")
            EXPECT_EQ(format_knob_value(value), format_knob_value(wax.values.get(name)))
                << name;
    EXPECT_LT(jade.values.scalar("roughness"), wax.values.scalar("roughness"));
    // ... and the strong pair has a higher reversed-diffuse weight (Fig. 4a).
    EXPECT_GT(
        find(set, "contrast_reversed_jade_strong").values.scalar("reversed_diffuse"),
        find(set, "contrast_reversed_jade").values.scalar("reversed_diffuse"));
}

TEST(ThesisPreset, RealCatalogRejectsUnknownTechniqueAndKeys) {
    const auto catalog = default_set_catalog();
    const std::string head = "[meshes]\nm = \"sphere\"\n[[stimuli]]\nid = \"a\"\n";
    try {
        parse_stimulus_set(head + "technique = \"phong\"\n", "x.toml", ".", catalog);
        FAIL() << "no error";
    } catch (const StimulusSetError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "x.toml:5:13: stimuli[0].technique: unknown technique "
                      "'phong' (valid: empirical, ward, contrast_reversed, dipole, htsm, "
                      "thick_texture, path)"),
                  std::string::npos)
            << e.what();
    }
    // reversed_diffuse belongs to contrast_reversed, not ward.
    EXPECT_THROW(
        parse_stimulus_set(head + "technique = \"ward\"\nreversed_diffuse = 0.5\n",
                           "x.toml", ".", catalog),
        StimulusSetError);
    EXPECT_NO_THROW(parse_stimulus_set(
        head + "technique = \"contrast_reversed\"\nreversed_diffuse = 0.5\n", "x.toml",
        ".", catalog));
}

}  // namespace
}  // namespace lucent::stimuli

namespace lucent::stimuli {
namespace {

// The built-in `fabrics` set (issue 14 section 6): a net and a weave, two thicknesses,
// three tilts, on the wavy curtain; four factor series whose levels are the tilts.
TEST(FabricsPreset, TwoFabricsTwoThicknessesThreeAnglesInFourSeries) {
    std::ifstream in(test::source_dir() / "renderer/core/presets/fabrics.toml",
                     std::ios::binary);
    std::ostringstream file;
    file << in.rdbuf();
    ASSERT_TRUE(set_preset_text("fabrics").has_value());
    EXPECT_EQ(std::string(*set_preset_text("fabrics")), file.str());
    const auto set = load_set_preset("fabrics", default_set_catalog());
    ASSERT_EQ(set.stimuli.size(), 12u + 2u);  // and the study's two practice pictures
    std::map<std::string, std::vector<double>> tilts;
    for (const auto& s : set.stimuli) {
        if (s.id == "practice_a" || s.id == "practice_b") {
            EXPECT_EQ(s.series, "");  // outside every factor series
            continue;
        }
        EXPECT_EQ(s.technique, "thick_texture");
        EXPECT_EQ(s.mesh, "wave:12800");
        const std::string texture = s.values.choice("texture");
        EXPECT_TRUE(texture == "net:5,1" || texture == "weave:2,2") << texture;
        const double h = s.values.scalar("thickness");
        EXPECT_TRUE(h == 0.5 || h == 1.5);
        EXPECT_EQ(s.series, (texture[0] == 'n' ? "net_h" : "weave_h") +
                                std::string(h == 0.5 ? "0.5" : "1.5"));
        tilts[s.series].push_back(s.values.scalar("tilt"));
    }
    ASSERT_EQ(tilts.size(), 4u);
    for (const auto& [series, values] : tilts)
        EXPECT_EQ(values, (std::vector<double>{0.0, 45.0, 70.0})) << series;
}

}  // namespace
}  // namespace lucent::stimuli

namespace lucent::stimuli {
namespace {

// The built-in `physical` set (issue 28 section 4): the three materials of the thesis
// survey's physically based comparison, path-traced on the thesis's knot under its key
// light, beside the survey's baseline empirical image, as one factor series; and a
// picture of it renders finite with the object covered (a small size, few paths).
TEST(PhysicalPreset, ThreePathTracedMaterialsBesideTheEmpiricalBaseline) {
    std::ifstream in(test::source_dir() / "renderer/core/presets/physical.toml",
                     std::ios::binary);
    std::ostringstream file;
    file << in.rdbuf();
    ASSERT_TRUE(set_preset_text("physical").has_value());
    EXPECT_EQ(std::string(*set_preset_text("physical")), file.str());
    const auto set = load_set_preset("physical", default_set_catalog());
    ASSERT_EQ(set.stimuli.size(), 4u);
    std::vector<std::string> materials;
    for (const auto& s : set.stimuli) {
        EXPECT_EQ(s.series, "physical") << s.id;
        EXPECT_EQ(s.mesh, "torus_knot:30k");
        if (s.technique == "path") {
            EXPECT_EQ(s.values.vec3("light_direction"), glm::dvec3(0.4, 0.6, 1.0));
            materials.push_back(s.values.choice("material"));
            EXPECT_EQ(s.values.scalar("model_size"), 30.0);
        } else {
            // The thesis set's own baseline picture, value for value.
            EXPECT_EQ(s.id, "empirical_row_1");
            const auto thesis = load_set_preset("thesis", default_set_catalog());
            const auto row_1 =
                std::find_if(thesis.stimuli.begin(), thesis.stimuli.end(),
                             [](const Stimulus& t) { return t.id == "empirical_row_1"; });
            ASSERT_NE(row_1, thesis.stimuli.end());
            for (const Knob& knob : knobs_for(find_technique("empirical")))
                EXPECT_EQ(s.values.get(knob.name), row_1->values.get(knob.name))
                    << knob.name;
        }
    }
    EXPECT_EQ(materials, (std::vector<std::string>{"skin1", "marble", "skimmilk"}));
}

}  // namespace
}  // namespace lucent::stimuli
