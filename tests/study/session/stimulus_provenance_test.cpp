// What a session shows, resolved before it starts: every knob value of a stimulus's
// technique (defaults from the knob registry), pre-rendered files checked against their
// stimulus set's manifest, and each built-in protocol agreeing with its stimulus set.
#include "study/session/stimulus_provenance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "renderer/core/density_volume.h"
#include "renderer/core/mesh.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "stimuli/batch_render.h"
#include "study/export.h"
#include "study/session/live_stimuli.h"
#include "study/session/stimulus_source.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

// One empirical stimulus that sets one parameter.
const char* kOneParameter = R"toml(
[study]
name = "one"
[[questions]]
id = "translucent"
text = "The object looks translucent."
[[stimuli]]
id = "e"
technique = "empirical"
mesh = "sphere:1k"
params = { backlight = 1.5 }
[[blocks]]
id = "main"
stimuli = ["e"]
)toml";

std::map<std::string, std::string> values_of(const StimulusProvenance& p) {
    return {p.values.begin(), p.values.end()};
}

// Runs one answered session on `stimuli` into `path`.
void store_session(const std::string& path, const Protocol& p,
                   const std::vector<StimulusProvenance>& stimuli) {
    Store store(path);
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study, "P1", &number);
    SessionEnvironment env;
    env.stimuli = stimuli;
    const SessionRow s =
        store.create_session(study, pid, plan_trials(p, 1, number), 1, env);
    for (const TrialRow& t : store.trials(s.id)) {
        TrialOutcome o;
        o.responses.push_back({"translucent", 4, 700.0, 0, 1, 2});
        store.record_trial(s.id, t.id, o);
    }
}

// The registry with one default changed, as a later build might.
SetCatalog catalog_with_albedo_default(glm::dvec3 albedo) {
    SetCatalog catalog = default_set_catalog();
    auto registry = catalog.knobs_of;
    catalog.knobs_of = [registry, albedo](std::string_view name) {
        auto knobs = registry(name);
        if (knobs)
            for (Knob& k : *knobs)
                if (k.name == "albedo") k.default_value = albedo;
        return knobs;
    };
    return catalog;
}

TEST(ResolveStimuli, AProtocolSettingOneParameterStoresEveryParameterOfTheTechnique) {
    const Protocol p = parse_protocol(kOneParameter, "one.toml");
    const std::vector<StimulusProvenance> resolved = resolve_stimuli(p, "");
    ASSERT_EQ(resolved.size(), 1u);
    // The parameter table (docs/parameters.md): the scene knobs and empirical's own,
    // with defaults.
    const std::map<std::string, std::string> expected = {{"light_ambient", "0.6,0.6,0.6"},
                                                         {"light_diffuse", "1,1,1"},
                                                         {"light_specular", "1,1,1"},
                                                         {"light_direction", "0.4,0.6,1"},
                                                         {"fov_y", "60"},
                                                         {"background", "0,0,0"},
                                                         {"albedo", "0.8,0.55,0.35"},
                                                         {"ambient", "0.3"},
                                                         {"specular", "0.5"},
                                                         {"shininess", "64"},
                                                         {"diffuse_contribution", "0.6"},
                                                         {"specular_contribution", "1"},
                                                         {"backlight", "1.5"},
                                                         {"thickness_exponent", "25"},
                                                         {"diffuse_weight", "0.2"},
                                                         {"ao_rays", "320"},
                                                         {"blur_kernel", "5"},
                                                         {"depth_precision", "32f"},
                                                         {"layer_method", "auto"}};
    EXPECT_EQ(values_of(resolved[0]), expected);
    EXPECT_EQ(resolved[0].source, "live");
    EXPECT_EQ(resolved[0].mesh_hash, load_mesh("sphere:1k").content_hash);

    // Stored and exported: one column per parameter, every cell filled.
    const auto dir = lucent::test::scratch_dir("provenance_one_parameter");
    const std::string db = (dir / "study.db").string();
    store_session(db, p, resolved);
    std::ostringstream csv;
    std::vector<std::string> notes;
    ASSERT_EQ(export_csv(db, ExportFormat::Long, csv, &notes), 1);
    EXPECT_TRUE(notes.empty());
    std::istringstream lines(csv.str());
    std::string header_line, row_line;
    std::getline(lines, header_line);
    std::getline(lines, row_line);
    std::map<std::string, std::string> cells;
    std::istringstream header(header_line), row(row_line);
    std::vector<std::string> names;
    for (std::string h; std::getline(header, h, ',');) names.push_back(h);
    // rgb values are quoted ("0.8,0.55,0.35"): split on commas outside quotes.
    std::vector<std::string> values(1);
    bool quoted = false;
    for (char c : row_line) {
        if (c == '"')
            quoted = !quoted;
        else if (c == ',' && !quoted)
            values.emplace_back();
        else
            values.back() += c;
    }
    ASSERT_EQ(values.size(), names.size()) << header_line << "\n" << row_line;
    for (size_t i = 0; i < names.size(); ++i) cells[names[i]] = values[i];
    for (const auto& [name, value] : expected) EXPECT_EQ(cells[name], value) << name;
    EXPECT_EQ(cells["mesh_hash"], resolved[0].mesh_hash);
    EXPECT_EQ(cells["stimulus_source"], "live");
}

// A station resolves a protocol once, and a second protocol anew: its rows are never the
// first protocol's (the old cache ignored which protocol it was asked about).
TEST(ResolveStimuli, AnotherProtocolIsResolvedAnew) {
    LiveOrPrerenderedStimuli stimuli("");
    stimuli.check(parse_protocol(kOneParameter, "one.toml"));
    std::string text = kOneParameter;
    text.replace(text.find("backlight = 1.5"), 15, "backlight = 0.75");
    const std::vector<StimulusProvenance> rows =
        stimuli.provenance(parse_protocol(text, "other.toml"));
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_EQ(values_of(rows[0]).at("backlight"), "0.75");
    EXPECT_EQ(values_of(stimuli.provenance(parse_protocol(kOneParameter, "one.toml"))[0])
                  .at("backlight"),
              "1.5");
}

TEST(ResolveStimuli, AChangedDefaultChangesTheStoredValuesAndMergeRefusesThem) {
    const Protocol p = parse_protocol(kOneParameter, "one.toml");
    const auto today = resolve_stimuli(p, "");
    const auto later =
        resolve_stimuli(p, "", catalog_with_albedo_default(glm::dvec3(0.5, 0.25, 0.125)));
    EXPECT_EQ(values_of(later[0]).at("albedo"), "0.5,0.25,0.125");
    EXPECT_EQ(values_of(later[0]).at("backlight"), "1.5");

    const auto dir = lucent::test::scratch_dir("provenance_changed_default");
    const std::string a = (dir / "a.db").string(), b = (dir / "b.db").string();
    store_session(a, p, today);
    store_session(b, p, later);
    EXPECT_EQ(
        Database(b, SQLITE_OPEN_READONLY)
            .scalar_int("SELECT count(*) FROM stimulus_values WHERE name = 'albedo' "
                        "AND value = '0.5,0.25,0.125'"),
        1);
    try {
        merge_databases({a, b}, (dir / "all.db").string());
        FAIL() << "merge joined two pictures under stimulus 'e'";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("stimulus 'e'"), std::string::npos) << what;
        EXPECT_NE(what.find("parameter 'albedo'"), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(dir / "all.db"));
}

// A tiny stimulus set rendered for real, and a protocol naming the same picture.
class ImagesAgainstManifest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = lucent::test::scratch_dir("provenance_images");
        const auto set = parse_stimulus_set(
            "name = \"tiny\"\nresolution = [24, 24]\nformats = [\"png\"]\n"
            "[meshes]\nball = \"sphere:1k\"\n[defaults]\nao_rays = 8\n"
            "[[stimuli]]\nid = \"w\"\ntechnique = \"ward\"\nroughness = 0.2\n",
            "tiny.toml", ".", default_set_catalog());
        stimuli::BatchOptions options;
        options.out_dir = dir_;
        options.progress = false;
        stimuli::render_stimulus_set(set, options);
    }
    Protocol protocol(const std::string& roughness = "0.2") const {
        return parse_protocol(std::string(R"toml(
[study]
name = "tiny"
[[questions]]
id = "translucent"
text = "The object looks translucent."
[[stimuli]]
id = "w"
technique = "ward"
mesh = "sphere:1k"
params = { ao_rays = 8, roughness = )toml") +
                                  roughness + R"toml( }
[[blocks]]
id = "main"
stimuli = ["w"]
)toml",
                              "tiny_protocol.toml");
    }
    // The one-line refusal for `p`, or "" when accepted.
    std::string refusal(const Protocol& p) const {
        try {
            resolve_stimuli(p, dir_.string());
        } catch (const StimulusError& e) {
            return e.what();
        }
        return "";
    }
    fs::path dir_;
};

TEST_F(ImagesAgainstManifest, AMatchingFileIsRecordedWithTheManifestsContentHash) {
    const auto resolved = resolve_stimuli(protocol(), dir_.string());
    ASSERT_EQ(resolved.size(), 1u);
    const auto manifest = stimuli::read_manifest_csv(dir_);
    EXPECT_EQ(resolved[0].source, "images");
    EXPECT_EQ(resolved[0].file, (dir_ / "w.png").string());
    EXPECT_EQ(resolved[0].content_hash, manifest.at("w").at("content_hash"));
    EXPECT_EQ(resolved[0].software_version, manifest.at("w").at("software_version"));
    EXPECT_EQ(values_of(resolved[0]).at("roughness"), "0.2");
    // Without --images the same stimulus renders live, with the same values.
    const auto live = resolve_stimuli(protocol(), "");
    EXPECT_EQ(live[0].source, "live");
    EXPECT_EQ(values_of(live[0]), values_of(resolved[0]));
}

TEST_F(ImagesAgainstManifest, ATamperedImageIsRefusedNamingTheFile) {
    {
        std::ofstream png(dir_ / "w.png", std::ios::binary | std::ios::app);
        png << '\0';  // still a readable PNG, no longer the rendered bytes
    }
    const std::string why = refusal(protocol());
    EXPECT_NE(why.find((dir_ / "w.png").string()), std::string::npos) << why;
    EXPECT_NE(why.find("content hash"), std::string::npos) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
}

TEST_F(ImagesAgainstManifest, AParameterOtherThanTheProtocolsIsRefusedNamingIt) {
    const std::string why = refusal(protocol("0.3"));
    EXPECT_NE(why.find("w.png"), std::string::npos) << why;
    EXPECT_NE(why.find("parameter 'roughness'"), std::string::npos) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
}

TEST_F(ImagesAgainstManifest, AFileWithoutAManifestRowIsRefused) {
    fs::remove(dir_ / "manifest.csv");
    const std::string why = refusal(protocol());
    EXPECT_NE(why.find("w.png"), std::string::npos) << why;
    EXPECT_NE(why.find("manifest.csv"), std::string::npos) << why;
}

// Every built-in study runs from the folder its own `lucent render --preset NAME` writes
// (issue 26 item 9). It takes its stimuli from that set (issue 51), and a session
// resolves each from the text the protocol keeps (the parameters as written) to exactly
// the values the set renders: same technique, mesh and every knob, practice included,
// and nothing else.
TEST(BuiltinPresets, EachStudyShowsExactlyItsStimulusSetsPicturesValueForValue) {
    for (const std::string& name : builtin_protocol_names()) {
        SCOPED_TRACE(name);
        const auto set = load_set_preset(name, default_set_catalog());
        const Protocol study = builtin_protocol(name);
        EXPECT_EQ(study.stimulus_set, "preset:" + name);
        std::map<std::string, StimulusProvenance> by_id;
        for (StimulusProvenance& p : resolve_stimuli(study, "")) by_id[p.stimulus] = p;
        for (const Stimulus& s : set.stimuli) {
            SCOPED_TRACE(s.id);
            ASSERT_TRUE(by_id.count(s.id))
                << "not shown by study/presets/" << name << ".toml";
            const StimulusProvenance& p = by_id.at(s.id);
            EXPECT_EQ(p.technique, s.technique);
            EXPECT_EQ(p.mesh, s.mesh);
            EXPECT_EQ(p.mesh_hash, load_mesh(s.mesh).content_hash);
            std::map<std::string, std::string> set_values;
            for (const auto& [key, value] : s.values.all())
                set_values[key] = format_knob_value(value);
            EXPECT_EQ(values_of(p), set_values);
            by_id.erase(s.id);
        }
        for (const auto& [id, p] : by_id)
            ADD_FAILURE() << id
                          << " is shown by the study but not in renderer/core/presets/"
                          << name << ".toml";
        for (const std::string& id : study.practice)
            EXPECT_NE(std::find_if(set.stimuli.begin(), set.stimuli.end(),
                                   [&](const Stimulus& s) { return s.id == id; }),
                      set.stimuli.end())
                << "practice stimulus " << id;
    }
}

// An htsm stimulus: the density volume's content hash is recorded beside its spec, and a
// later session whose volume differs (a changed file, a new generator) is refused like a
// changed mesh.
TEST(ResolveStimuli, ADensityVolumesHashIsRecordedAndCheckedLikeTheMeshHash) {
    const std::string text = R"toml(
[study]
name = "dense"
[[questions]]
id = "translucent"
text = "The object looks translucent."
[[stimuli]]
id = "e"
technique = "htsm"
mesh = "sphere:1k"
params = { density = "cube" }
[[blocks]]
id = "main"
stimuli = ["e"]
)toml";
    const Protocol p = parse_protocol(text, "htsm.toml");
    std::vector<StimulusProvenance> resolved = resolve_stimuli(p, "");
    ASSERT_EQ(resolved.size(), 1u);
    const auto values = values_of(resolved[0]);
    EXPECT_EQ(values.at("density"), "cube");
    EXPECT_EQ(values.at("density_hash"),
              make_density_volume("cube", 64, 1.0)->content_hash);
    const auto dir = lucent::test::scratch_dir("provenance_density_hash");
    const std::string db = (dir / "study.db").string();
    store_session(db, p, resolved);
    {
        Database database(db, SQLITE_OPEN_READONLY);
        EXPECT_EQ(read_resolved_stimuli(database).at("e").values.at("density_hash"),
                  values.at("density_hash"));
    }
    for (auto& [name, value] : resolved[0].values)
        if (name == "density_hash") value = "0123456789abcdef";
    Store store(db);
    try {
        store.check_stimulus_values(resolved);
        FAIL() << "a different density volume was accepted";
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("density_hash"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

// Each factor series of Table 4.3 has its colour (issue 13): rows 1, 4 and 7 share r, wb
// and Kb, and a session's database tells them apart by the stored albedo.
TEST(ThesisPresets, TheDatabaseRecordsEachRowsColour) {
    const Protocol study = builtin_protocol("thesis");
    const auto dir = lucent::test::scratch_dir("provenance_thesis_colour");
    const std::string db = (dir / "thesis.db").string();
    {
        // A session as `lucent run --preset thesis` starts it (its stimuli are stored
        // when the session is created).
        Store store(db);
        const int64_t id = store.ensure_study(study);
        int number = 0;
        const int64_t participant = store.ensure_participant(id, "P1", &number);
        SessionEnvironment env;
        env.stimuli = resolve_stimuli(study, "");
        store.create_session(id, participant, plan_trials(study, 1, number), 1, env);
    }
    Database database(db, SQLITE_OPEN_READONLY);
    const auto stored = read_resolved_stimuli(database);
    const std::map<std::string, std::string> colour = {
        {"empirical_row_1", "0.5,0.1,0.7"},  {"empirical_row_2", "0.5,0.1,0.7"},
        {"empirical_row_3", "0.5,0.1,0.7"},  {"empirical_row_4", "0.1,0.6,0.15"},
        {"empirical_row_5", "0.1,0.6,0.15"}, {"empirical_row_6", "0.1,0.6,0.15"},
        {"empirical_row_7", "0.1,0.25,0.8"}, {"empirical_row_8", "0.1,0.25,0.8"},
        {"empirical_row_9", "0.1,0.25,0.8"}};
    for (const auto& [id, albedo] : colour) {
        ASSERT_TRUE(stored.count(id)) << id;
        EXPECT_EQ(stored.at(id).values.at("albedo"), albedo) << id;
    }
    // The rows that share Table 4.3's values differ only in colour.
    auto without_albedo = [&](const std::string& id) {
        auto values = stored.at(id).values;
        values.erase("albedo");
        return values;
    };
    EXPECT_EQ(without_albedo("empirical_row_1"), without_albedo("empirical_row_4"));
    EXPECT_EQ(without_albedo("empirical_row_1"), without_albedo("empirical_row_7"));
}

// Issue 27 item 1: a stimulus is resolved once. Every stimulus of every built-in study is
// rendered as a lab session renders it, and the values the database records are those
// of the scene the renderer received: every knob of the technique (recomputed here from
// the scene's own values, not from the protocol text), the mesh's hash, the technique.
class ResolvedOnce : public lucent::test::HeadlessGlTest {};

TEST_F(ResolvedOnce, TheDatabaseRecordsTheValuesOfTheSceneTheRendererReceived) {
    for (const std::string& name : builtin_protocol_names()) {
        SCOPED_TRACE(name);
        const Protocol study = builtin_protocol(name);
        LiveOrPrerenderedStimuli stimuli("");
        std::map<std::string, Scene> drawn;
        std::string rendering;
        stimuli.on_render = [&](const Scene& scene) { drawn.emplace(rendering, scene); };
        stimuli.check(study);
        const auto dir = lucent::test::scratch_dir("resolved_once_" + name);
        const std::string db = (dir / "study.db").string();
        {
            Store store(db);
            const int64_t id = store.ensure_study(study);
            int number = 0;
            const int64_t participant = store.ensure_participant(id, "P1", &number);
            SessionEnvironment env;
            env.stimuli = stimuli.provenance(study);
            store.create_session(id, participant, plan_trials(study, 1, number), 1, env);
        }
        // Small pictures: the values, not the pixels, are under test here.
        for (const Stimulus& spec : study.stimuli) {
            rendering = spec.id;
            (void)stimuli.render(spec, 24, 16);
        }
        Database database(db, SQLITE_OPEN_READONLY);
        const auto stored = read_resolved_stimuli(database);
        ASSERT_EQ(drawn.size(), study.stimuli.size());
        for (const auto& [id, scene] : drawn) {
            SCOPED_TRACE(id);
            ASSERT_TRUE(stored.count(id));
            const ResolvedStimulus& row = stored.at(id);
            EXPECT_EQ(scene.width, 24);
            EXPECT_EQ(row.technique, scene.technique);
            EXPECT_EQ(row.mesh_hash, scene.mesh->content_hash);
            std::map<std::string, std::string> received;
            for (const Knob& knob : knobs_for(find_technique(scene.technique))) {
                received[knob.name] = format_knob_value(scene.values.get(knob.name));
                if (knob.name == "density")
                    received["density_hash"] = scene.density->content_hash;
            }
            EXPECT_EQ(row.values, received);
            // And the scene is the one `lucent render` builds from the protocol's
            // parameters at that size: the same values, camera and light to the bit.
            const Stimulus& spec = *study.find_stimulus(id);
            RenderRequest request;
            if (!spec.mesh.empty()) request.mesh = spec.mesh;
            request.technique = spec.technique;
            for (const auto& [key, value] : spec.parameters)
                request.settings.push_back({key, value});
            request.width = 24;
            request.height = 16;
            const Scene rendered_alone = build_scene(request);
            for (const Knob& knob : knobs_for(find_technique(scene.technique)))
                EXPECT_EQ(format_knob_value(rendered_alone.values.get(knob.name)),
                          received.at(knob.name))
                    << knob.name;
            EXPECT_EQ(rendered_alone.camera.view(), scene.camera.view());
            EXPECT_EQ(rendered_alone.camera.projection(), scene.camera.projection());
            EXPECT_EQ(rendered_alone.light.direction, scene.light.direction);
        }
    }
}

}  // namespace
}  // namespace lucent::study
