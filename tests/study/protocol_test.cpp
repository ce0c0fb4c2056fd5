// Protocol parsing: the thesis preset's content, and errors naming file, line and key.
#include "study/protocol.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "study/sha256.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

TEST(Sha256, MatchesFipsVectors) {
    EXPECT_EQ(sha256_hex(""),
              "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(sha256_hex("abc"),
              "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(ThesisPreset, HasTheNineStimuliOfTable43) {
    const Protocol p = builtin_protocol("thesis");
    // Table 4.3 of the thesis: r, wb, Kb per image.
    const double table[9][3] = {{25, 1.2, 0.2}, {18, 1.2, 0.2}, {30, 1.2, 0.2},
                                {25, 1.2, 0.2}, {25, 0.8, 0.2}, {25, 1.6, 0.2},
                                {25, 1.2, 0.2}, {25, 1.2, 0.0}, {25, 1.2, 0.5}};
    const char* varies[3] = {"thickness_exponent", "backlight", "diffuse_weight"};
    for (int i = 0; i < 9; ++i) {
        const Stimulus* s = p.find_stimulus("empirical_row_" + std::to_string(i + 1));
        ASSERT_NE(s, nullptr) << i;
        EXPECT_EQ(s->technique, "empirical");
        EXPECT_DOUBLE_EQ(std::stod(s->parameters.at("thickness_exponent")), table[i][0]);
        EXPECT_DOUBLE_EQ(std::stod(s->parameters.at("backlight")), table[i][1]);
        EXPECT_DOUBLE_EQ(std::stod(s->parameters.at("diffuse_weight")), table[i][2]);
        // Row 1 also joins the physically based comparison series (section 8 of issue
        // 11).
        ASSERT_EQ(s->varies.size(), i == 0 ? 2u : 1u);
        EXPECT_EQ(s->varies[0], varies[i / 3]);
        if (i == 0) EXPECT_EQ(s->varies[1], "series:physically_based");
    }
}

TEST(ThesisPreset, PhysicallyBasedSeriesIsTheBestEmpiricalImageAndThreeDipoles) {
    const Protocol p = builtin_protocol("thesis");
    std::vector<std::string> series;
    for (const Stimulus& s : p.stimuli)
        if (std::find(s.varies.begin(), s.varies.end(), "series:physically_based") !=
            s.varies.end())
            series.push_back(s.id);
    EXPECT_EQ(series, (std::vector<std::string>{"empirical_row_1", "dipole_skin1",
                                                "dipole_marble", "dipole_skimmilk"}));
    for (const char* material : {"skin1", "marble", "skimmilk"}) {
        const Stimulus* s = p.find_stimulus(std::string("dipole_") + material);
        ASSERT_NE(s, nullptr) << material;
        EXPECT_EQ(s->technique, "dipole");
        EXPECT_EQ(s->parameters.at("material"), material);
        EXPECT_EQ(s->parameters.at("hybrid"), "on");
        EXPECT_EQ(p.level_of(*s, "series:physically_based"), s->id);
    }
}

TEST(ThesisPreset, ContrastReversedStimuliHaveWardCounterparts) {
    const Protocol p = builtin_protocol("thesis");
    int pairs = 0;
    for (const Stimulus& s : p.stimuli) {
        if (s.technique != "contrast_reversed" || s.id.rfind("practice", 0) == 0)
            continue;
        for (const char* key : {"reversed_diffuse", "specular_reflectance", "roughness"})
            EXPECT_TRUE(s.parameters.count(key)) << s.id << " lacks " << key;
        const Stimulus* ward = p.find_stimulus("ward_" + s.id.substr(18));
        ASSERT_NE(ward, nullptr) << s.id;
        EXPECT_EQ(ward->technique, "ward");
        // The same material: ward's diffuse_reflectance is contrast_reversed's weight.
        auto expected = s.parameters;
        expected["diffuse_reflectance"] = expected.at("reversed_diffuse");
        expected.erase("reversed_diffuse");
        EXPECT_EQ(ward->parameters, expected);
        ++pairs;
    }
    EXPECT_GE(pairs, 3);
}

TEST(ThesisPreset, AsksTheThreeStatementsOnSevenPoints) {
    const Protocol p = builtin_protocol("thesis");
    ASSERT_EQ(p.questions.size(), 3u);
    EXPECT_EQ(p.questions[0].id, "translucent");
    EXPECT_EQ(p.questions[1].id, "realistic");
    EXPECT_EQ(p.questions[2].id, "varnished");
    for (const Question& q : p.questions) {
        EXPECT_EQ(q.points(), 7);
        EXPECT_EQ(q.labels.front(), "completely disagree");
        EXPECT_EQ(q.labels.back(), "completely agree");
    }
    EXPECT_FALSE(p.practice.empty());
    EXPECT_FALSE(p.catch_trials.empty());
    EXPECT_GT(p.break_every, 0);
    EXPECT_FALSE(p.screens.consent.empty());
    EXPECT_FALSE(p.screens.debrief.empty());
}

// The built-in `fabrics` protocol (issue 14 section 6): the 12 pictures of the `fabrics`
// stimulus set, with tilt, thickness and texture as factors of 3, 2 and 2 levels.
TEST(FabricsPreset, TwelveThickTextureStimuliWithThreeFactors) {
    const Protocol p = builtin_protocol("fabrics");
    EXPECT_EQ(p.stimuli.size(), 14u);  // 12 rated + 2 practice
    std::set<std::string> tilts, thicknesses, textures;
    int rated = 0;
    for (const Stimulus& s : p.stimuli) {
        EXPECT_EQ(s.technique, "thick_texture");
        if (s.varies.empty()) continue;  // practice
        ++rated;
        EXPECT_EQ(s.varies, (std::vector<std::string>{"tilt", "thickness", "texture"}));
        tilts.insert(p.level_of(s, "tilt"));
        thicknesses.insert(p.level_of(s, "thickness"));
        textures.insert(p.level_of(s, "texture"));
    }
    EXPECT_EQ(rated, 12);
    EXPECT_EQ(tilts.size(), 3u);
    EXPECT_EQ(thicknesses.size(), 2u);
    EXPECT_EQ(textures, (std::set<std::string>{"net:5,1", "weave:2,2"}));
    EXPECT_EQ(p.questions.size(), 3u);
}

TEST(BuiltinProtocol, UnknownNameListsValidOnes) {
    try {
        builtin_protocol("nope");
        FAIL();
    } catch (const ProtocolError& e) {
        EXPECT_NE(std::string(e.what()).find("thesis"), std::string::npos);
    }
}

TEST(ProtocolErrors, UnknownKeyNamesFileLineAndKey) {
    std::string text = lucent::test::kSmallProtocol;
    text.replace(text.find("break_every = 2"), 15, "break_every = 2\ncolour = 3");
    const std::string e = test::protocol_error_of(text);
    // kSmallProtocol starts with a newline: [study] is line 2, colour line 5.
    EXPECT_NE(e.find("bad.toml:5:"), std::string::npos) << e;
    EXPECT_NE(e.find("study.colour"), std::string::npos) << e;
    EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
}

TEST(ProtocolErrors, EachKindIsOneLineNamingTheKey) {
    struct Case {
        std::string from, to, expect;
    };
    const Case cases[] = {
        {"break_every = 2", "break_every = \"two\"", "study.break_every"},
        {"break_every = 2", "break_every = -1", "must lie in"},
        {"stimuli = [\"a\", \"b\", \"c\"]", "stimuli = [\"a\", \"zz\"]",
         "no stimulus with id 'zz'"},
        {"technique = \"ward\"", "technique = \"raytraced\"", "unknown technique"},
        {"expected = 7", "expected = 9", "catch_trials.expected"},
        {"varies = [\"thickness_exponent\"]\n\n[[stimuli]]\nid = \"b\"",
         "varies = [\"roughness\"]\n\n[[stimuli]]\nid = \"b\"", "stimuli.varies"},
        {"name = \"small\"", "name = \"small", "bad.toml:3:"},  // parse error position
    };
    for (const Case& c : cases) {
        std::string text = lucent::test::kSmallProtocol;
        const size_t at = text.find(c.from);
        ASSERT_NE(at, std::string::npos) << c.from;
        text.replace(at, c.from.size(), c.to);
        const std::string e = test::protocol_error_of(text);
        EXPECT_NE(e.find(c.expect), std::string::npos) << "got: " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
        EXPECT_EQ(e.rfind("bad.toml:", 0), 0u) << e;
    }
}

// Issue 27 item 1: a live stimulus's parameters are read as stimulus sets read them and
// held to its technique's knobs when the protocol is read, at the value's line, not
// later when a session resolves them.
TEST(ProtocolParameters, AreHeldToTheTechniquesKnobsAtTheirLine) {
    struct Case {
        std::string to;
        std::vector<std::string> expect;
    };
    // kSmallProtocol starts with a newline: stimulus 'p''s params are on line 39.
    const Case cases[] = {
        {"roughness = -3",
         {"bad.toml:39:", "stimuli.params.roughness", "stimulus 'p'",
          "accepted: a number in ["}},
        {"roughness = \"rough\"", {"bad.toml:39:", "wrong type: expected a number"}},
        {"sparkle = 3",
         {"bad.toml:39:", "stimuli.params.sparkle",
          "'sparkle' is not a parameter of technique 'ward'", "roughness"}},
    };
    for (const Case& c : cases) {
        std::string text = lucent::test::kSmallProtocol;
        text.replace(text.find("roughness = 0.2"), 15, c.to);
        const std::string e = test::protocol_error_of(text);
        for (const std::string& part : c.expect)
            EXPECT_NE(e.find(part), std::string::npos) << c.to << " got: " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

TEST(ProtocolParameters, KeepEveryDigitOfTheValue) {
    std::string text = lucent::test::kSmallProtocol;
    text.replace(text.find("roughness = 0.2"), 15, "roughness = 0.123456789012345678");
    const Protocol p = parse_protocol(text, "digits.toml");
    const std::string& kept = p.find_stimulus("p")->parameters.at("roughness");
    // The double nearest 0.123456789012345678, as TOML and C++ both read it; 12 digits
    // (0.123456789012) would be a different double.
    EXPECT_EQ(std::stod(kept), 0.123456789012345678) << kept;
}

TEST(ProtocolParameters, AStoredProtocolWhoseKnobIsGoneStillReads) {
    // A study run by a build whose ward had a 'sparkle' knob: its stored protocol must
    // still give its questions and factor levels to the store and the export.
    std::string text = lucent::test::kSmallProtocol;
    text.replace(text.find("roughness = 0.2"), 15, "roughness = 0.25, sparkle = 3");
    EXPECT_THROW(parse_protocol(text, "stored"), ProtocolError);
    const Protocol stored = parse_protocol(text, "stored", "", KnobCheck::lenient);
    EXPECT_EQ(stored.find_stimulus("p")->parameters.at("sparkle"), "3");
    EXPECT_EQ(stored.find_stimulus("p")->parameters.at("roughness"), "0.25");
}

TEST(Protocol, AnalysisPlanNamesThePrimaryDesign) {
    EXPECT_EQ(
        parse_protocol(lucent::test::kSmallProtocol, "p.toml").analysis.primary_design,
        "within");  // every participant sees every stimulus
    std::string text = lucent::test::kSmallProtocol;
    text += "\n[analysis]\nprimary_design = \"between\"\n";
    EXPECT_EQ(parse_protocol(text, "p.toml").analysis.primary_design, "between");
    EXPECT_EQ(builtin_protocol("thesis").analysis.primary_design, "within");
    const std::string e =
        test::protocol_error_of(std::string(lucent::test::kSmallProtocol) +
                                "\n[analysis]\nprimary_design = \"mixed\"\n");
    EXPECT_NE(e.find("analysis.primary_design"), std::string::npos) << e;
    EXPECT_NE(e.find("'mixed'"), std::string::npos) << e;
    EXPECT_EQ(e.rfind("bad.toml:", 0), 0u) << e;
}

TEST(Protocol, AnalysisPlanNamesThePrimaryModel) {
    EXPECT_EQ(
        parse_protocol(lucent::test::kSmallProtocol, "p.toml").analysis.primary_model,
        "anova");  // the thesis's analysis leads unless the plan says otherwise
    std::string text = lucent::test::kSmallProtocol;
    text += "\n[analysis]\nprimary_model = \"clmm\"\n";
    EXPECT_EQ(parse_protocol(text, "p.toml").analysis.primary_model, "clmm");
    // Whether a name is a registered model is the analysis's to say (app/analysis_plan.h,
    // tests/analysis/models/registered_model_test.cpp); what cannot be a name is refused
    // here, naming the file, line and key.
    const std::string bad = std::string(lucent::test::kSmallProtocol) +
                            "\n[analysis]\nprimary_model = \"G LMM\"\n";
    const std::string line = std::to_string(
        1 + std::count(bad.begin(), bad.begin() + bad.find("primary_model ="), '\n'));
    const std::string e = test::protocol_error_of(bad);
    EXPECT_NE(e.find("analysis.primary_model"), std::string::npos) << e;
    EXPECT_NE(e.find("'G LMM'"), std::string::npos) << e;
    EXPECT_EQ(e.rfind("bad.toml:" + line + ":", 0), 0u) << e;
    text = std::string(lucent::test::kSmallProtocol) +
           "\n[analysis]\nprimary_model = \"glmm\"\n";
    EXPECT_EQ(
        parse_protocol(text, "p.toml").analysis.primary_model_at.rfind("p.toml:", 0), 0u);
}

TEST(ProtocolErrors, ImpossibleRandomisationIsReportedWhenPlanning) {
    std::string text = lucent::test::kSmallProtocol;
    text += "\n[randomisation]\nfactor = \"backlight\"\nmax_repeat = 1\n";
    const Protocol p = parse_protocol(text, "bad.toml");
    EXPECT_THROW(plan_trials(p, 1, 1), PlanError);
}

TEST(Protocol, StimulusLevelIsThePictureNotTheId) {
    // Two ids with the same technique, mesh and parameters are one picture.
    const Protocol twins = parse_protocol(R"toml(
[study]
name = "twins"
[[questions]]
id = "q"
text = "Q"
[[stimuli]]
id = "a"
technique = "empirical"
params = { backlight = 1.2, albedo = [0.5, 0.1, 0.7] }
[[stimuli]]
id = "b"
technique = "empirical"
params = { backlight = 1.2, albedo = [0.5, 0.1, 0.7] }
[[stimuli]]
id = "c"
technique = "empirical"
params = { backlight = 1.2, albedo = [0.1, 0.6, 0.15] }
[[blocks]]
id = "main"
stimuli = ["a", "b", "c"]
)toml",
                                          "twins.toml");
    EXPECT_EQ(twins.level_of(*twins.find_stimulus("b"), "stimulus"), "a");
    EXPECT_EQ(twins.level_of(*twins.find_stimulus("c"), "stimulus"), "c");  // its colour
    // The thesis's rows 1, 4 and 7 share Table 4.3's r, wb and Kb but each series has its
    // colour (purple, green, blue): three pictures, as every stimulus of the protocol.
    const Protocol p = builtin_protocol("thesis");
    for (const char* id : {"empirical_row_1", "empirical_row_4", "empirical_row_7",
                           "empirical_row_2", "ward_jade", "contrast_reversed_jade"})
        EXPECT_EQ(p.level_of(*p.find_stimulus(id), "stimulus"), id);
    EXPECT_EQ(p.levels_of("stimulus").size(), p.stimuli.size());
}

TEST(Protocol, PreRenderedStimuliAreTheSamePictureWhenTheirBytesAre) {
    const auto dir = lucent::test::scratch_dir("picture_identity");
    auto write = [&](const char* name, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << bytes;
    };
    write("one.png", "same pixels");
    write("copy.png", "same pixels");
    write("other.png", "other pixels");
    const Protocol p = parse_protocol(R"toml(
[study]
name = "images"
[[questions]]
id = "q"
text = "Q"
[[stimuli]]
id = "one"
image = "one.png"
[[stimuli]]
id = "copy"
image = "copy.png"
[[stimuli]]
id = "other"
image = "other.png"
[[blocks]]
id = "main"
stimuli = ["one", "copy", "other"]
)toml",
                                      "images.toml", dir.string());
    EXPECT_EQ(p.level_of(*p.find_stimulus("copy"), "stimulus"), "one");
    EXPECT_EQ(p.level_of(*p.find_stimulus("other"), "stimulus"), "other");
}

TEST(Protocol, LevelsAreCanonicalNumbers) {
    const Protocol p = builtin_protocol("thesis");
    EXPECT_EQ(p.level_of(*p.find_stimulus("empirical_row_8"), "diffuse_weight"), "0");
    EXPECT_EQ(p.level_of(*p.find_stimulus("empirical_row_9"), "diffuse_weight"), "0.5");
    EXPECT_EQ(p.level_of(*p.find_stimulus("empirical_row_2"), "thickness_exponent"),
              "18");
    EXPECT_EQ(p.level_of(*p.find_stimulus("contrast_reversed_jade"), "technique"),
              "contrast_reversed");
}

TEST(OnlineSettings, CompletionCodeAndUrlAreReadAndCheckedInOneLine) {
    const std::string base = lucent::test::kSmallProtocol;
    const Protocol none = parse_protocol(base, "web.toml");
    EXPECT_EQ(none.online.completion_code, "");
    EXPECT_EQ(none.online.completion_url, "");
    const Protocol p = parse_protocol(
        base +
            "\n[online]\ncompletion_code = \"C0DE42\"\n"
            "completion_url = "
            "\"https://app.prolific.com/submissions/complete?cc=C0DE42\"\n",
        "web.toml");
    EXPECT_EQ(p.online.completion_code, "C0DE42");
    EXPECT_EQ(p.online.completion_url,
              "https://app.prolific.com/submissions/complete?cc=C0DE42");
    for (const char* bad : {"completion_url = \"javascript:alert(1)\"",
                            "completion_code = \"<b>\"", "completion_link = \"x\""}) {
        try {
            parse_protocol(base + "\n[online]\n" + bad + "\n", "web.toml");
            ADD_FAILURE() << bad;
        } catch (const ProtocolError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind("web.toml:", 0), 0u) << what;
            EXPECT_NE(what.find("key 'online."), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos);
        }
    }
}

}  // namespace
}  // namespace lucent::study
