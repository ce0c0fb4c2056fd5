// Knob parsing and validation: values, grey shorthand, and one-line errors that name the
// key and the accepted range.
#include "renderer/core/knobs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>

#include "renderer/core/common_knobs.h"
#include "renderer/techniques/registry.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

const Knob kScalar{"shininess", "n", KnobKind::scalar, 0.0, 1000.0, 64.0};
const Knob kRgb{"albedo", "Kd", KnobKind::rgb, 0.0, 1.0, glm::dvec3(0.5)};
const Knob kVec{"light_direction", "L", KnobKind::vec3, -10.0, 10.0, glm::dvec3(0, 0, 1)};
const Knob kInt{"ao_rays", "rays", KnobKind::integer, 1.0, 4096.0, 320};
const Knob kChoice{"blur_kernel",  "k", KnobKind::choice, 1, 5, std::string("5"),
                   {"1", "3", "5"}};

std::string error_of(const Knob& knob, const std::string& text) {
    try {
        parse_knob_value(knob, text);
    } catch (const KnobError& e) {
        return e.what();
    }
    return "";
}

TEST(Knobs, ParsesEachKind) {
    EXPECT_EQ(std::get<double>(parse_knob_value(kScalar, "12.5")), 12.5);
    EXPECT_EQ(std::get<glm::dvec3>(parse_knob_value(kRgb, "0.1,0.2,0.3")),
              glm::dvec3(0.1, 0.2, 0.3));
    EXPECT_EQ(std::get<glm::dvec3>(parse_knob_value(kRgb, "0.25")), glm::dvec3(0.25));
    EXPECT_EQ(std::get<glm::dvec3>(parse_knob_value(kVec, "-1, 2 ,3")),
              glm::dvec3(-1, 2, 3));
    EXPECT_EQ(std::get<int>(parse_knob_value(kInt, "64")), 64);
    EXPECT_EQ(std::get<std::string>(parse_knob_value(kChoice, "3")), "3");
}

TEST(Knobs, ErrorsNameTheKeyAndTheRange) {
    EXPECT_EQ(error_of(kScalar, "abc"),
              "shininess: 'abc' is not a number (accepted: a number in [0, 1000])");
    EXPECT_EQ(error_of(kScalar, "1001"),
              "shininess: '1001' is out of range (accepted: a number in [0, 1000])");
    EXPECT_NE(error_of(kScalar, "nan").find("shininess: 'nan' is not a number"),
              std::string::npos);
    EXPECT_NE(error_of(kScalar, "inf").find("is not a number"), std::string::npos);
    EXPECT_NE(error_of(kRgb, "0.1,0.2").find("albedo: '0.1,0.2' needs 3"),
              std::string::npos);
    EXPECT_NE(error_of(kRgb, "0.1,2,0.3")
                  .find("accepted: r,g,b (or one grey value) with each in [0, 1]"),
              std::string::npos);
    EXPECT_NE(error_of(kVec, "0.5").find("light_direction"), std::string::npos);
    EXPECT_NE(error_of(kVec, "0,0,0").find("zero vector"), std::string::npos);
    EXPECT_NE(error_of(kInt, "3.5").find("ao_rays: '3.5' is not an integer"),
              std::string::npos);
    EXPECT_NE(error_of(kInt, "0").find("accepted: an integer in [1, 4096]"),
              std::string::npos);
    EXPECT_EQ(error_of(kChoice, "4"),
              "blur_kernel: '4' is not a valid choice (accepted: one of 1, 3, 5)");
    for (const auto* text : {"abc", "1001", "0.1,0.2"})
        EXPECT_EQ(error_of(kScalar, text).find('\n'), std::string::npos) << "one line";
}

TEST(Knobs, ResolveAppliesDefaultsThenAssignmentsAndRejectsUnknownKeys) {
    const std::vector<Knob> knobs = {kScalar, kRgb};
    const std::vector<KnobAssignment> set = {{"albedo", "0.5,0.25,0"},
                                             {"shininess", "3"}};
    const KnobValues values = resolve_knob_values(knobs, set);
    EXPECT_EQ(values.scalar("shininess"), 3.0);
    EXPECT_EQ(values.vec3("albedo"), glm::dvec3(0.5, 0.25, 0.0));
    const KnobValues defaults = resolve_knob_values(knobs, {});
    EXPECT_EQ(defaults.scalar("shininess"), 64.0);
    const std::vector<KnobAssignment> bad = {{"shinyness", "3"}};
    try {
        resolve_knob_values(knobs, bad);
        FAIL() << "unknown key accepted";
    } catch (const KnobError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "shinyness: unknown parameter (valid: shininess, albedo)");
    }
}

TEST(Knobs, AssignmentSplitsAtTheFirstEquals) {
    const KnobAssignment a = parse_assignment("albedo=0.1,0.2,0.3");
    EXPECT_EQ(a.key, "albedo");
    EXPECT_EQ(a.text, "0.1,0.2,0.3");
    EXPECT_THROW(parse_assignment("albedo"), KnobError);
    EXPECT_THROW(parse_assignment("=3"), KnobError);
}

TEST(Knobs, FormattedValuesParseBackToTheSameValue) {
    for (const Technique* technique : all_techniques())
        for (const Knob& knob : knobs_for(*technique)) {
            const std::string text = format_knob_value(knob.default_value);
            EXPECT_EQ(parse_knob_value(knob, text), knob.default_value)
                << knob.name << " = " << text;
        }
}

TEST(Knobs, EveryRegisteredKnobHasAValidDefaultAndADescription) {
    for (const Technique* technique : all_techniques()) {
        std::vector<std::string> names;
        for (const Knob& knob : knobs_for(*technique)) {
            EXPECT_NO_THROW(validate_knob_value(knob, knob.default_value)) << knob.name;
            EXPECT_FALSE(knob.description.empty()) << knob.name;
            EXPECT_EQ(std::count(names.begin(), names.end(), knob.name), 0)
                << "duplicate " << knob.name;
            names.push_back(knob.name);
        }
    }
}

TEST(Knobs, EmpiricalHasTheCanonicalNamesAndThesisDefaults) {
    const auto knobs = knobs_for(find_technique("empirical"));
    for (const char* name :
         {"albedo", "ambient", "specular", "shininess", "diffuse_contribution",
          "specular_contribution", "backlight", "thickness_exponent", "diffuse_weight",
          "light_ambient", "light_diffuse", "light_specular", "light_direction",
          "ao_rays", "blur_kernel", "fov_y", "background"})
        EXPECT_NE(find_knob(knobs, name), nullptr) << name;
    // Thesis Table 4.3, row 1: r = 25, wb = 1.2, Kb = 0.2; 320 AO rays; 5x5 smoothing.
    EXPECT_EQ(std::get<double>(find_knob(knobs, "thickness_exponent")->default_value),
              25.0);
    EXPECT_EQ(std::get<double>(find_knob(knobs, "backlight")->default_value), 1.2);
    EXPECT_EQ(std::get<double>(find_knob(knobs, "diffuse_weight")->default_value), 0.2);
    EXPECT_EQ(std::get<int>(find_knob(knobs, "ao_rays")->default_value), 320);
    EXPECT_EQ(std::get<std::string>(find_knob(knobs, "blur_kernel")->default_value), "5");
    EXPECT_EQ(std::get<glm::dvec3>(find_knob(knobs, "background")->default_value),
              glm::dvec3(0.0));
}

TEST(Registry, UnknownTechniqueListsTheValidNames) {
    try {
        find_technique("marble");
        FAIL();
    } catch (const KnobError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("technique: 'marble' is unknown (valid: ", 0), 0u)
            << message;
        EXPECT_NE(message.find("empirical"), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace lucent

namespace lucent {
namespace {

// The parameter table (docs/parameters.md) is the user's documentation: each knob has a
// row whose default column parses to the knob's default. A knob name two techniques give
// different defaults (density) has a row per technique, its meaning naming the technique
// in backticks.
TEST(Knobs, ReadmeTableListsEveryKnobWithItsDefault) {
    std::ifstream file(test::source_dir() / "docs" / "parameters.md");
    ASSERT_TRUE(file) << "docs/parameters.md not found";
    struct Row {
        std::string meaning, default_text;
    };
    std::map<std::string, std::vector<Row>> rows;
    for (std::string line; std::getline(file, line);) {
        if (line.rfind("| `", 0) != 0) continue;
        const auto name_end = line.find('`', 3);
        const auto last_bar = line.rfind('|', line.size() - 2);
        std::string cell = line.substr(last_bar + 1);
        cell.erase(std::remove(cell.begin(), cell.end(), ' '), cell.end());
        cell.erase(std::remove(cell.begin(), cell.end(), '|'), cell.end());
        rows[line.substr(3, name_end - 3)].push_back({line.substr(name_end), cell});
    }
    for (const Technique* technique : all_techniques())
        for (const Knob& knob : knobs_for(*technique)) {
            ASSERT_TRUE(rows.count(knob.name))
                << knob.name << " missing from docs/parameters.md";
            const std::vector<Row>& candidates = rows[knob.name];
            const Row* row = &candidates.front();
            const std::string marker = "`" + std::string(technique->name()) + "`";
            for (const Row& r : candidates)
                if (r.meaning.find(marker) != std::string::npos) row = &r;
            EXPECT_EQ(parse_knob_value(knob, row->default_text), knob.default_value)
                << knob.name << " of " << technique->name();
        }
}

}  // namespace
}  // namespace lucent
