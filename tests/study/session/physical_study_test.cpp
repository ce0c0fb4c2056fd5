// docs/physical_study.toml, the thesis survey's physically based comparison with Lucent's
// path-traced pictures (issue 28 section 4): its stimuli are the built-in `physical`
// stimulus set's, value for value, so `lucent run docs/physical_study.toml --images DIR`
// accepts the folder `lucent render --preset physical --out DIR` writes.
#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"
#include "study/protocol.h"
#include "study/session/stimulus_provenance.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

TEST(PhysicalStudy, ItsStimuliAreThePhysicalSetsValueForValue) {
    const Protocol protocol = load_protocol_file(
        (test::source_dir() / "docs" / "physical_study.toml").string());
    const auto set = load_set_preset("physical", default_set_catalog());
    const std::vector<ResolvedProtocolStimulus> resolved =
        resolve_protocol_stimuli(protocol, "");
    ASSERT_EQ(resolved.size(), set.stimuli.size());
    for (const ResolvedProtocolStimulus& r : resolved) {
        ASSERT_TRUE(r.scene);
        const auto match = std::find_if(
            set.stimuli.begin(), set.stimuli.end(),
            [&](const Stimulus& s) { return s.id == r.provenance.stimulus; });
        ASSERT_NE(match, set.stimuli.end()) << r.provenance.stimulus;
        EXPECT_EQ(r.scene->technique, match->technique);
        EXPECT_EQ(r.scene->mesh->name, match->mesh) << r.provenance.stimulus;
        for (const Knob& knob : knobs_for(find_technique(match->technique)))
            EXPECT_EQ(r.scene->values.get(knob.name), match->values.get(knob.name))
                << r.provenance.stimulus << " " << knob.name;
    }
    // One factor: the empirical baseline against the three path-traced materials.
    ASSERT_EQ(protocol.blocks.size(), 1u);
    EXPECT_EQ(protocol.blocks[0].stimuli.size(), 4u);
}

}  // namespace
}  // namespace lucent::study
