// The stimulus-set TOML loader: expansion, precedence, and errors naming file, line, key.
#include "renderer/core/stimulus_set.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "tests/support/test_paths.h"

namespace lucent {
namespace {

// Two small fake techniques, so these tests pin the loader, not the real knob lists.
SetCatalog fake_catalog() {
    const std::vector<Knob> shared = {
        {"light_direction", "", KnobKind::vec3, -10, 10, glm::dvec3(0, 0, 1), {}},
        {"light_diffuse", "", KnobKind::rgb, 0, 100, glm::dvec3(1), {}},
        {"fov_y", "", KnobKind::scalar, 1, 170, 60.0, {}},
        {"albedo", "", KnobKind::rgb, 0, 1, glm::dvec3(0.5), {}},
    };
    auto alpha = shared, beta = shared;
    alpha.push_back({"weight", "", KnobKind::scalar, 0, 10, 1.0, {}});
    alpha.push_back({"rays", "", KnobKind::integer, 1, 4096, 320, {}});
    beta.push_back({"roughness", "", KnobKind::scalar, 0, 1, 0.2, {}});
    SetCatalog catalog;
    catalog.technique_names = {"alpha", "beta"};
    catalog.builtin_meshes = {"sphere", "torus"};
    catalog.knobs_of = [alpha,
                        beta](std::string_view name) -> std::optional<std::vector<Knob>> {
        if (name == "alpha") return alpha;
        if (name == "beta") return beta;
        return std::nullopt;
    };
    return catalog;
}

StimulusSet parse(const std::string& text) {
    return parse_stimulus_set(text, "set.toml", ".", fake_catalog());
}

// The message of the StimulusSetError `text` raises ("" when it parses).
std::string error_of(const std::string& text) {
    try {
        parse(text);
    } catch (const StimulusSetError& e) {
        return e.what();
    }
    return "";
}

const std::string kHeader = "[meshes]\nball = \"sphere:2k\"\n";

TEST(StimulusSet, MinimalSetTakesDefaults) {
    const auto set = parse(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n");
    ASSERT_EQ(set.stimuli.size(), 1u);
    const auto& s = set.stimuli[0];
    EXPECT_EQ(s.id, "a");
    EXPECT_EQ(s.technique, "alpha");
    EXPECT_EQ(s.mesh, "sphere:2k");
    EXPECT_EQ(s.values.scalar("weight"), 1.0);
    EXPECT_EQ(s.values.integer("rays"), 320);
    EXPECT_EQ(set.width, 512);
    EXPECT_EQ(set.name, "set");  // unnamed sets take the file's stem
    EXPECT_EQ(set.formats, std::vector<ImageFormat>{ImageFormat::png});
}

TEST(StimulusSet, PrecedenceDefaultsCameraLightMaterialOwn) {
    const auto set = parse(
        "resolution = [64, 32]\nformats = [\"exr\", \"png\"]\n" + kHeader +
        "[defaults]\nweight = 2.0\nfov_y = 40\n"
        "[camera]\nfov_y = 30\n"
        "[lights.side]\nlight_direction = [1, 0, 0]\nlight_diffuse = \"0.5,0.4,0.3\"\n"
        "[materials.red]\nalbedo = [0.9, 0.1, 0.1]\nroughness = 0.7\nweight = 3\n"
        "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nlight = \"side\"\nmaterial = "
        "\"red\"\nweight = 4\n"
        "[[stimuli]]\nid = \"b\"\ntechnique = \"beta\"\nmaterial = \"red\"\n");
    EXPECT_EQ(set.width, 64);
    EXPECT_EQ(set.height, 32);
    ASSERT_EQ(set.formats.size(), 2u);
    const auto& a = set.stimuli[0].values;
    EXPECT_EQ(a.scalar("fov_y"), 30.0);                         // camera over defaults
    EXPECT_EQ(a.vec3("light_direction"), glm::dvec3(1, 0, 0));  // light
    EXPECT_EQ(a.vec3("light_diffuse"), glm::dvec3(0.5, 0.4, 0.3));  // rgb as text
    EXPECT_EQ(a.vec3("albedo"), glm::dvec3(0.9, 0.1, 0.1));         // material
    EXPECT_EQ(a.scalar("weight"), 4.0);                             // own over material
    const auto& b = set.stimuli[1].values;
    EXPECT_EQ(b.scalar("roughness"), 0.7);  // beta takes the material's roughness ...
    EXPECT_FALSE(b.contains("weight"));     // ... and ignores keys it lacks
    EXPECT_EQ(b.vec3("light_direction"), glm::dvec3(0, 0, 1));  // no light named: default
}

// The parameters an entry sets, in the form written, are the stimulus's factor levels
// (a protocol taking its stimuli from the set analyses them): the winner of the
// precedence for each key set anywhere, a grey one number, 40.0 as "40", never a default.
TEST(StimulusSet, EachStimulusKeepsTheParametersItsEntrySetsAsWritten) {
    const auto set = parse(
        kHeader +
        "[defaults]\nweight = 2.0\nfov_y = 40.0\n"
        "[lights.side]\nlight_direction = [1, 0, 0]\nlight_diffuse = \"0.5,0.4,0.3\"\n"
        "[materials.red]\nalbedo = 0.25\nroughness = 0.7\n"
        "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nlight = \"side\"\n"
        "material = \"red\"\nvaries = [\"rays\", \"series:look\"]\n"
        "[stimuli.vary]\nrays = [16, 32]\n"
        "[[stimuli]]\nid = \"b\"\ntechnique = \"beta\"\nmaterial = \"red\"\n");
    ASSERT_EQ(set.stimuli.size(), 3u);
    const std::map<std::string, std::string> a_2 = {
        {"albedo", "0.25"},           {"fov_y", "40"}, {"light_diffuse", "0.5,0.4,0.3"},
        {"light_direction", "1,0,0"}, {"rays", "32"},  {"weight", "2"}};
    EXPECT_EQ(set.stimuli[1].parameters, a_2);
    EXPECT_EQ(set.stimuli[1].varies, (std::vector<std::string>{"rays", "series:look"}));
    const std::map<std::string, std::string> b = {
        {"albedo", "0.25"}, {"fov_y", "40"}, {"roughness", "0.7"}};
    EXPECT_EQ(set.stimuli[2].parameters, b);
    EXPECT_TRUE(set.stimuli[2].varies.empty());
    EXPECT_EQ(set.stimuli[2].source_line, 20);
}

TEST(StimulusSet, VariesNamesWhatTheEntrySets) {
    EXPECT_EQ(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "varies = [\"weight\"]\n"),
              "set.toml:6:11: stimuli[0].varies: 'weight' is not a parameter or factor "
              "the entry sets (nor technique or series:NAME)");
    EXPECT_NE(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "varies = \"weight\"\n")
                  .find("stimuli[0].varies: expected a list of names"),
              std::string::npos);
    EXPECT_EQ(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "varies = [\"technique\", \"series:x\"]\n"),
              "");
}

// [stimuli.motion]: a scalar knob as a function of time (issue 51 item 1). No program
// draws it yet, so the default catalog refuses it; one that says it does gets the record.
TEST(StimulusSet, MotionIsReadIntoTheRecordWhereTheProgramDrawsIt) {
    const std::string moving = kHeader +
                               "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                               "[stimuli.motion.weight]\nfrom = 2.0\nto = 6\n"
                               "period_s = 4\nshape = \"loop\"\n";
    EXPECT_NE(
        error_of(moving).find(
            "set.toml:6:1: stimuli[0].motion: lucent does not draw moving stimuli yet"),
        std::string::npos)
        << error_of(moving);
    SetCatalog catalog = fake_catalog();
    catalog.draws_motion = true;
    const auto set = parse_stimulus_set(moving, "set.toml", ".", catalog);
    const Stimulus& s = set.stimuli.at(0);
    ASSERT_EQ(s.motion.size(), 1u);
    EXPECT_EQ(s.motion[0].knob, "weight");
    EXPECT_EQ(s.motion[0].from, 2.0);
    EXPECT_EQ(s.motion[0].to, 6.0);
    EXPECT_EQ(s.motion[0].period_s, 4.0);
    EXPECT_EQ(s.motion[0].shape, KnobMotion::Shape::loop);
    EXPECT_EQ(s.values.scalar("weight"), 2.0);  // the still is t = 0
    EXPECT_EQ(s.parameters.at("weight"), "2");
    EXPECT_EQ(s.values_at(2.0).scalar("weight"), 4.0);

    auto refusal = [&](const std::string& motion_lines) {
        try {
            parse_stimulus_set(kHeader +
                                   "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n" +
                                   motion_lines,
                               "set.toml", ".", catalog);
        } catch (const StimulusSetError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string spec = "from = 1\nto = 2\nperiod_s = 1\n";
    EXPECT_NE(refusal("[stimuli.motion.rays]\n" + spec)
                  .find("only a number parameter can move"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.vary]\nweight = [1, 2]\n[stimuli.motion.weight]\n" + spec)
                  .find("'weight' is in [stimuli.vary] too"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.motion.weight]\nfrom = 1\nto = 2\nperiod_s = 0\n")
                  .find("stimuli[0].motion.weight.period_s: out of range"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.motion.weight]\nfrom = 1\nto = 2\nperiod_s = inf\n")
                  .find("stimuli[0].motion.weight.period_s: out of range"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.motion.weight]\nfrom = 1\nto = 20\nperiod_s = 1\n")
                  .find("stimuli[0].motion.weight.to: "),
              std::string::npos);  // beyond the knob's range [0, 10]
    EXPECT_NE(refusal("[stimuli.motion.weight]\nfrom = 1\nperiod_s = 1\n")
                  .find("stimuli[0].motion.weight.to: missing"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.motion.weight]\n" + spec + "shape = \"sine\"\n")
                  .find("'sine' is out of range (valid: back_and_forth, loop)"),
              std::string::npos);
    EXPECT_NE(refusal("[stimuli.motion.weight]\n" + spec + "speed = 3\n")
                  .find("stimuli[0].motion.weight.speed: unknown key"),
              std::string::npos);
    EXPECT_NE(
        refusal("[stimuli.motion.sparkle]\n" + spec).find("not a parameter of technique"),
        std::string::npos);
}

// An entry's own factors (issue 51 item 1): named levels beside its parameters, never
// a knob's name.
TEST(StimulusSet, OwnFactorsAreNamedLevelsBesideTheParameters) {
    const auto set = parse(kHeader +
                           "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                           "factors = { lighting = \"front\", session = 2 }\n"
                           "varies = [\"lighting\"]\n");
    const Stimulus& s = set.stimuli.at(0);
    const std::map<std::string, std::string> factors = {{"lighting", "front"},
                                                        {"session", "2"}};
    EXPECT_EQ(s.factors, factors);
    EXPECT_TRUE(s.parameters.empty());
    EXPECT_EQ(s.columns(), factors);
    EXPECT_FALSE(s.values.contains("lighting"));  // no renderer sees it
    EXPECT_EQ(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "factors = { weight = 2 }\n"),
              "set.toml:6:13: stimuli[0].factors.weight: 'weight' is a parameter of "
              "technique 'alpha': set it as one, not as a factor");
    EXPECT_NE(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "factors = { technique = \"x\" }\n")
                  .find("'technique' is not a factor name"),
              std::string::npos);
}

TEST(StimulusSet, GridAndZipExpansion) {
    const auto grid =
        parse(kHeader +
              "[[stimuli]]\nid = \"g_{weight}_{rays}\"\ntechnique = \"alpha\"\n"
              "[stimuli.vary]\nweight = [1, 2, 3]\nrays = [16, 32]\n");
    ASSERT_EQ(grid.stimuli.size(), 6u);
    EXPECT_EQ(grid.stimuli[0].id, "g_1_16");
    EXPECT_EQ(grid.stimuli[5].id, "g_3_32");
    EXPECT_EQ(grid.stimuli[3].values.scalar("weight"), 2.0);
    EXPECT_EQ(grid.stimuli[3].values.integer("rays"), 32);

    const auto zip =
        parse(kHeader +
              "[[stimuli]]\nid = \"z\"\ntechnique = \"alpha\"\nexpand = \"zip\"\n"
              "[stimuli.vary]\nweight = [1, 2, 3]\nrays = [16, 32, 64]\n");
    ASSERT_EQ(zip.stimuli.size(), 3u);
    EXPECT_EQ(zip.stimuli[0].id, "z_1");  // no placeholder: numbered
    EXPECT_EQ(zip.stimuli[2].id, "z_3");
    EXPECT_EQ(zip.stimuli[2].values.scalar("weight"), 3.0);
    EXPECT_EQ(zip.stimuli[2].values.integer("rays"), 64);
}

TEST(StimulusSet, ErrorsNameFileLineAndKey) {
    // Unknown key at the top level and inside a stimulus.
    EXPECT_EQ(
        error_of("colour = 1\n" + kHeader),
        "set.toml:1:1: colour: unknown key (valid: name, resolution, formats, meshes, "
        "camera, lights, materials, defaults, stimuli)");
    EXPECT_EQ(
        error_of(kHeader +
                 "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nroughness = 0.1\n"),
        "set.toml:6:1: stimuli[0].roughness: unknown key (not a parameter of technique "
        "'alpha')");
    // Wrong type.
    EXPECT_EQ(
        error_of(kHeader +
                 "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nweight = \"x\"\n"),
        "set.toml:6:10: stimuli[0].weight: wrong type: expected a number (accepted: a "
        "number in [0, 10])");
    EXPECT_NE(
        error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nrays = 1.5\n")
            .find("set.toml:6:8: stimuli[0].rays: wrong type"),
        std::string::npos);
    // Out of range, including inside a vary list and in a material.
    EXPECT_NE(error_of(kHeader +
                       "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nweight = 11\n")
                  .find("set.toml:6:10: stimuli[0].weight: '11' is out of range"),
              std::string::npos);
    EXPECT_NE(error_of(kHeader +
                       "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n[stimuli.vary]\n"
                       "weight = [1, -2]\n")
                  .find("set.toml:7:14: stimuli[0].vary.weight"),
              std::string::npos);
    EXPECT_NE(error_of(kHeader + "[materials.m]\nalbedo = [2, 0, 0]\n")
                  .find("set.toml:4:10: "
                        "materials.m.albedo"),
              std::string::npos);
    EXPECT_NE(error_of("resolution = [0, 10]\n" + kHeader)
                  .find("set.toml:1:14: resolution: out of range"),
              std::string::npos);
    // Missing mesh: an unknown mesh name and a file that does not exist.
    EXPECT_NE(
        error_of(kHeader +
                 "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\nmesh = \"cube\"\n")
            .find("set.toml:6:8: stimuli[0].mesh: missing mesh 'cube'"),
        std::string::npos);
    EXPECT_NE(error_of("[meshes]\nbunny = \"no/such/bunny.obj\"\n")
                  .find("set.toml:2:9: meshes.bunny: missing mesh: 'no/such/bunny.obj'"),
              std::string::npos);
    // Unknown technique.
    EXPECT_EQ(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"phong\"\n"),
              "set.toml:5:13: stimuli[0].technique: unknown technique 'phong' (valid: "
              "alpha, beta)");
    // Duplicate and unsafe ids, unequal zip lists, a syntax error.
    EXPECT_NE(error_of(kHeader + "[[stimuli]]\nid = \"a\"\ntechnique = \"alpha\"\n"
                                 "[[stimuli]]\nid = \"a\"\ntechnique = \"beta\"\n")
                  .find("set.toml:7:6: stimuli[1].id: duplicate id 'a'"),
              std::string::npos);
    EXPECT_NE(error_of(kHeader + "[[stimuli]]\nid = \"../x\"\ntechnique = \"alpha\"\n")
                  .find("not a valid id"),
              std::string::npos);
    EXPECT_NE(
        error_of(kHeader +
                 "[[stimuli]]\nid = \"z\"\ntechnique = \"alpha\"\nexpand = \"zip\"\n"
                 "[stimuli.vary]\nweight = [1, 2]\nrays = [16]\n")
            .find("zip needs lists of equal length"),
        std::string::npos);
    EXPECT_NE(error_of("name = \n").find("set.toml:1:"), std::string::npos);
    EXPECT_NE(error_of(kHeader).find("stimuli: missing"), std::string::npos);
}

TEST(StimulusSet, SeriesAreNamedOrTheIdPatternOfAnExpandingEntry) {
    const auto set =
        parse(kHeader +
              "[[stimuli]]\nid = \"w_{weight}\"\ntechnique = \"alpha\"\n"
              "[stimuli.vary]\nweight = [1, 2]\n"
              "[[stimuli]]\nid = \"one\"\ntechnique = \"alpha\"\n"
              "[[stimuli]]\nid = \"p\"\nseries = \"pair\"\ntechnique = \"alpha\"\n"
              "[[stimuli]]\nid = \"q\"\nseries = \"pair\"\ntechnique = \"beta\"\n");
    ASSERT_EQ(set.stimuli.size(), 5u);
    EXPECT_EQ(set.stimuli[0].series, "w_{weight}");
    EXPECT_EQ(set.stimuli[1].series, "w_{weight}");
    EXPECT_EQ(set.stimuli[2].series, "");  // a single stimulus is no series
    EXPECT_EQ(set.stimuli[3].series, "pair");
    EXPECT_EQ(set.stimuli[4].series, "pair");
    EXPECT_EQ(
        error_of(kHeader +
                 "[[stimuli]]\nid = \"a\"\nseries = \"a b\"\ntechnique = \"alpha\"\n"),
        "set.toml:5:10: stimuli[0].series: 'a b' is not a valid name (letters, digits, _ "
        "- . "
        "only)");
    // The report writes contact-sheet.png beside the images: no stimulus may take it.
    EXPECT_NE(
        error_of(kHeader + "[[stimuli]]\nid = \"contact-sheet\"\ntechnique = \"alpha\"\n")
            .find("stimuli[0].id: 'contact-sheet' is reserved"),
        std::string::npos);
}

TEST(StimulusSet, RelativeMeshPathsResolveAgainstTheConfigFile) {
    const auto dir = test::scratch_dir("stimulus_set_paths");
    std::ofstream(dir / "shape.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir / "set.toml") << "[meshes]\nshape = \"shape.obj\"\n"
                                       "[[stimuli]]\nid = \"a\"\ntechnique = \"beta\"\n";
    const auto set = load_stimulus_set(dir / "set.toml", fake_catalog());
    EXPECT_EQ(std::filesystem::path(set.stimuli[0].mesh),
              (dir / "shape.obj").lexically_normal());
    EXPECT_THROW(load_stimulus_set(dir / "absent.toml", fake_catalog()),
                 StimulusSetError);
}

}  // namespace
}  // namespace lucent
