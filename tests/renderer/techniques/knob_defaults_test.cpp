// Every registered technique's knob defaults, read back through its params(), are a
// default Params: the knob list and the reading agree on each default.
#include <gtest/gtest.h>

#include <functional>
#include <map>

#include "renderer/core/scene.h"
#include "renderer/techniques/dipole/dipole.h"
#include "renderer/techniques/empirical/knobs.h"
#include "renderer/techniques/htsm/htsm.h"
#include "renderer/techniques/path/path.h"
#include "renderer/techniques/registry.h"
#include "renderer/techniques/thick_texture/thick_texture.h"
#include "renderer/techniques/ward/ward.h"

namespace lucent {
namespace {

// Whether params() of a scene at the knobs' defaults is a default Params, by technique.
const std::map<std::string, std::function<bool(const Scene&)>, std::less<>>
    kReadsDefaults = {
        {"empirical",
         [](const Scene& s) { return empirical::params(s) == empirical::Params{}; }},
        {"ward",
         [](const Scene& s) {
             return ward::params(s, ward::Variant::ward) == ward::Params{};
         }},
        {"contrast_reversed",
         [](const Scene& s) {
             return ward::params(s, ward::Variant::contrast_reversed) == ward::Params{};
         }},
        {"dipole", [](const Scene& s) { return dipole::params(s) == dipole::Params{}; }},
        {"htsm", [](const Scene& s) { return htsm::params(s) == htsm::Params{}; }},
        {"thick_texture",
         [](const Scene& s) {
             return thick_texture::params(s) == thick_texture::Params{};
         }},
        {"path", [](const Scene& s) { return path::params(s) == path::Params{}; }},
};

TEST(KnobDefaults, EveryTechniqueReadsItsDefaultsBackToADefaultParams) {
    for (const Technique* technique : all_techniques()) {
        SCOPED_TRACE(technique->name());
        const auto reads_defaults = kReadsDefaults.find(technique->name());
        ASSERT_NE(reads_defaults, kReadsDefaults.end()) << "a technique without a check";
        Scene scene;
        scene.values = resolve_knob_values(knobs_for(*technique), {});
        EXPECT_TRUE(reads_defaults->second(scene));
    }
}

}  // namespace
}  // namespace lucent
