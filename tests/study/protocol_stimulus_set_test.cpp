// A protocol that takes its stimuli from a stimulus set ([study] stimulus_set, issue 51
// item 1): the set's stimuli with their parameters as written and their `varies`, the
// protocol's own entries after them, a stored copy that needs no other file, and a
// one-line refusal for each bad reference.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "study/protocol.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSet = R"toml(name = "pair"
[meshes]
ball = "sphere"
[camera]
fov_y = 60.0
[materials.grey]
albedo = 0.6
[[stimuli]]
id = "r{thickness_exponent}"
technique = "empirical"
material = "grey"
varies = ["thickness_exponent"]
[stimuli.vary]
thickness_exponent = [10.0, 25.0]
)toml";

constexpr const char* kProtocol = R"toml([study]
name = "from_set"
stimulus_set = "sets/pair.toml"
[[questions]]
id = "translucent"
text = "The object looks translucent."
[[stimuli]]
id = "photo"
image = "photo.png"
params = { lighting = "studio" }
[[blocks]]
id = "main"
stimuli = ["r10", "r25", "photo"]
)toml";

void write(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
}

class ProtocolFromSet : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = test::scratch_dir("protocol_from_set");
        write(dir_ / "sets" / "pair.toml", kSet);
        write(dir_ / "study.toml", kProtocol);
    }
    Protocol load() const { return load_protocol_file((dir_ / "study.toml").string()); }
    fs::path dir_;
};

TEST_F(ProtocolFromSet, TakesTheSetsStimuliAsWrittenThenItsOwn) {
    const Protocol p = load();
    EXPECT_EQ(p.stimulus_set, "sets/pair.toml");
    ASSERT_EQ(p.stimuli.size(), 3u);
    EXPECT_EQ(p.stimuli[0].id, "r10");
    EXPECT_EQ(p.stimuli[1].id, "r25");
    EXPECT_EQ(p.stimuli[2].id, "photo");
    // The material's grey stays one number, 60.0 and 25.0 are written as the database
    // holds numbers; the keys are those the entry sets, not every knob of the technique.
    const std::map<std::string, std::string> r25 = {
        {"albedo", "0.6"}, {"fov_y", "60"}, {"thickness_exponent", "25"}};
    EXPECT_EQ(p.stimuli[1].parameters, r25);
    EXPECT_EQ(p.stimuli[1].technique, "empirical");
    EXPECT_EQ(p.stimuli[1].mesh, "sphere");
    EXPECT_EQ(p.stimuli[1].mesh_name, "ball");
    EXPECT_EQ(p.stimuli[1].varies, std::vector<std::string>{"thickness_exponent"});
    EXPECT_EQ(p.stimuli[1].values.scalar("thickness_exponent"), 25.0);
    EXPECT_EQ(p.stimuli[2].parameters.at("lighting"), "studio");
    EXPECT_EQ(p.stimuli[2].image, (dir_ / "photo.png").string());
    const std::map<std::string, std::string> levels = {
        {"r10", "10"}, {"r25", "25"}, {"photo", ""}};
    EXPECT_EQ(p.levels_of("thickness_exponent"), levels);
}

TEST_F(ProtocolFromSet, TheStoredTextNeedsNoOtherFileAndChangesWithTheSet) {
    const Protocol first = load();
    EXPECT_NE(first.text.find("[embedded_stimulus_set]"), std::string::npos);
    fs::remove(dir_ / "sets" / "pair.toml");
    // As a database's stored protocol is read back: no directory, the file gone.
    const Protocol stored = parse_protocol(first.text, "stored", "");
    EXPECT_EQ(stored.text, first.text);  // not embedded twice: the same hash
    ASSERT_EQ(stored.stimuli.size(), first.stimuli.size());
    for (std::size_t i = 0; i < stored.stimuli.size(); ++i) {
        EXPECT_EQ(stored.stimuli[i].id, first.stimuli[i].id);
        EXPECT_EQ(stored.stimuli[i].parameters, first.stimuli[i].parameters);
        EXPECT_EQ(stored.stimuli[i].varies, first.stimuli[i].varies);
    }
    std::string changed = kSet;
    changed.replace(changed.find("albedo = 0.6"), 12, "albedo = 0.7");
    write(dir_ / "sets" / "pair.toml", changed);
    EXPECT_NE(protocol_hash(load().text), protocol_hash(first.text));
}

TEST_F(ProtocolFromSet, AnIdInTheSetAndTheProtocolIsRefused) {
    std::string text = kProtocol;
    text.replace(text.find("sets/pair.toml"), 14, (dir_ / "sets" / "pair.toml").string());
    text.replace(text.find("id = \"photo\""), 12, "id = \"r10\"");
    const std::string e = test::protocol_error_of(text);
    EXPECT_NE(e.find("duplicate stimulus id 'r10'"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(ProtocolFromSetErrors, EachIsOneLineNamingTheKeyOrTheSetsOwnLine) {
    const fs::path dir = test::scratch_dir("protocol_from_set_errors");
    std::string bad_set = kSet;
    bad_set.replace(bad_set.find("material = \"grey\""), 17, "sparkle = 2");
    write(dir / "bad-set.toml", bad_set);
    struct Case {
        std::string stimulus_set;
        std::vector<std::string> expect;
    };
    const Case cases[] = {
        {"preset:nope",
         {"bad.toml:3:", "study.stimulus_set", "unknown preset 'nope'", "thesis"}},
        {(dir / "missing.toml").string(),
         {"bad.toml:3:", "study.stimulus_set", "cannot read the stimulus set",
          "missing.toml"}},
        // The set's own error: its file, line and key (sparkle is on line 11).
        {(dir / "bad-set.toml").string(),
         {"bad.toml: study.stimulus_set: ", (dir / "bad-set.toml").string() + ":11:",
          "stimuli[0].sparkle"}},
    };
    for (const Case& c : cases) {
        std::string text = kProtocol;
        text.replace(text.find("sets/pair.toml"), 14, c.stimulus_set);
        const std::string e = test::protocol_error_of(text);
        for (const std::string& part : c.expect)
            EXPECT_NE(e.find(part), std::string::npos) << "want " << part << " in: " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

// A protocol entry's own factor may not take a knob's name, set or not: it would be two
// columns of one name, or a knob no renderer would see.
TEST(ProtocolOwnFactors, AKnobsNameIsRefusedInOneLine) {
    for (const auto& [factor, expect] :
         {std::pair{"backlight", "'backlight' is a parameter of stimulus 'a'"},
          std::pair{"albedo", "'albedo' is a parameter of stimulus 'a'"},
          std::pair{"technique", "'technique' is not a factor name"}}) {
        std::string text = test::kSmallProtocol;
        const std::string varies = "varies = [\"thickness_exponent\"]";
        text.replace(text.find(varies), varies.size(),
                     std::string("factors = { ") + factor + " = \"x\" }");
        const std::string e = test::protocol_error_of(text);
        EXPECT_NE(e.find(std::string("stimuli.factors.") + factor), std::string::npos)
            << e;
        EXPECT_NE(e.find(expect), std::string::npos) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    std::string text = test::kSmallProtocol;
    const std::string varies = "varies = [\"thickness_exponent\"]";
    text.replace(text.find(varies), varies.size(),
                 "factors = { lighting = \"front\" }\nvaries = [\"lighting\"]");
    EXPECT_EQ(test::protocol_error_of(text), "");
}

TEST(ProtocolFromSetErrors, AnEmbeddedSetOfAnotherNameIsRefused) {
    const Protocol p = builtin_protocol("jnd");
    std::string text = p.text;
    text.replace(text.find("stimulus_set = \"preset:jnd\""), 27,
                 "stimulus_set = \"preset:scaling\"");
    const std::string e = test::protocol_error_of(text);
    EXPECT_NE(e.find("embedded_stimulus_set.source"), std::string::npos) << e;
    EXPECT_NE(e.find("'preset:jnd', not the [study] stimulus_set 'preset:scaling'"),
              std::string::npos)
        << e;
}

}  // namespace
}  // namespace lucent::study
