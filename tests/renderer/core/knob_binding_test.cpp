// One bind() over a Params makes both the knob list (defaults from a default Params) and
// the reading of resolved values into the members.
#include "renderer/core/knob_binding.h"

#include <gtest/gtest.h>

namespace lucent {
namespace {

struct Params {
    double roughness = 0.25;
    glm::dvec3 albedo{0.1, 0.2, 0.3};
    int rays = 7;
    int kernel = 3;  // a choice of whole numbers
    bool mips = true;
    std::string method = "peel";
    bool operator==(const Params&) const = default;
};

void bind(Params& p, KnobBinder& b) {
    b.knob(p.roughness, {"roughness", "alpha", KnobKind::scalar, 0.0, 1.0});
    b.knob(p.albedo, {"albedo", "Kd", KnobKind::rgb, 0.0, 1.0});
    b.knob(p.rays, {"rays", "per vertex", KnobKind::integer, 1.0, 64.0});
    b.choice(p.kernel, "kernel", "width", {"1", "3", "5"});
    b.choice(p.mips, "mips", "mip levels", {"off", "on"});
    b.choice(p.method, "method", "layers", {"auto", "peel"});
    b.scene_input(
        {"volume", "read by the scene", KnobKind::text, 0.0, 0.0, std::string("marble")});
}

TEST(KnobBinding, ListsEachKnobInOrderWithTheDefaultOfADefaultParams) {
    const std::vector<Knob> knobs = list_knobs<Params>(bind);
    ASSERT_EQ(knobs.size(), 7u);
    const char* names[] = {"roughness", "albedo", "rays",  "kernel",
                           "mips",      "method", "volume"};
    for (std::size_t i = 0; i < knobs.size(); ++i) EXPECT_EQ(knobs[i].name, names[i]);
    EXPECT_EQ(knobs[0].default_value, KnobValue(0.25));
    EXPECT_EQ(knobs[1].default_value, KnobValue(glm::dvec3(0.1, 0.2, 0.3)));
    EXPECT_EQ(knobs[2].default_value, KnobValue(7));
    EXPECT_EQ(knobs[3].default_value, KnobValue(std::string("3")));
    EXPECT_EQ(knobs[4].default_value, KnobValue(std::string("on")));
    EXPECT_EQ(knobs[5].default_value, KnobValue(std::string("peel")));
    EXPECT_EQ(knobs[6].default_value, KnobValue(std::string("marble")));
    EXPECT_EQ(knobs[3].kind, KnobKind::choice);
    EXPECT_EQ(knobs[3].choices, (std::vector<std::string>{"1", "3", "5"}));
    EXPECT_EQ(knobs[0].max, 1.0);
    EXPECT_EQ(knobs[2].description, "per vertex");
}

TEST(KnobBinding, ReadsEveryMemberFromTheValues) {
    KnobValues values;
    values.set("roughness", 0.5);
    values.set("albedo", glm::dvec3(0.4, 0.5, 0.6));
    values.set("rays", 12);
    values.set("kernel", std::string("5"));
    values.set("mips", std::string("off"));
    values.set("method", std::string("auto"));
    values.set("volume", std::string("cube"));
    const Params p = read_knobs<Params>(values, bind);
    EXPECT_EQ(p.roughness, 0.5);
    EXPECT_EQ(p.albedo, glm::dvec3(0.4, 0.5, 0.6));
    EXPECT_EQ(p.rays, 12);
    EXPECT_EQ(p.kernel, 5);
    EXPECT_FALSE(p.mips);
    EXPECT_EQ(p.method, "auto");
}

TEST(KnobBinding, TheListedDefaultsReadBackToADefaultParams) {
    const std::vector<Knob> knobs = list_knobs<Params>(bind);
    EXPECT_EQ(read_knobs<Params>(resolve_knob_values(knobs, {}), bind), Params{});
}

TEST(KnobBinding, AMemberOfAnotherTypeThanItsKnobIsALogicError) {
    const auto scalar_as_text = [](Params& p, KnobBinder& b) {
        b.knob(p.method, {"method", "layers", KnobKind::scalar, 0.0, 1.0});
    };
    EXPECT_THROW(list_knobs<Params>(scalar_as_text), std::logic_error);
}

}  // namespace
}  // namespace lucent
