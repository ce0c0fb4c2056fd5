// Provenance in the store (schema 3): one environment row per session segment, resolved
// values fixed per study, merges refused when they differ, and version 2 databases
// exported with a note.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "study/export.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::environment;
using lucent::test::provenance_for;
using lucent::test::small_protocol;

// A session for P1 whose every trial is answered; `albedo` goes into its provenance.
void one_session(const std::string& path, const std::string& albedo) {
    Store store(path);
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study, "P1", &number);
    SessionEnvironment env = environment("lab-a", "GPU A", 60);
    env.stimuli = provenance_for(p, albedo);
    const SessionRow s =
        store.create_session(study, pid, plan_trials(p, 5, number), 5, env);
    for (const TrialRow& t : store.trials(s.id))
        store.record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
    store.set_status(s.id, "completed", true);
}

TEST(Provenance, AResumeAddsAnEnvironmentRowAndKeepsTheFirstMachines) {
    const auto dir = lucent::test::scratch_dir("provenance_segments");
    Store store((dir / "study.db").string());
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study, "P1", &number);
    SessionEnvironment first = environment("lab-a", "GPU A", 60);
    first.stimuli = provenance_for(p, "0.8,0.55,0.35");
    const SessionRow s =
        store.create_session(study, pid, plan_trials(p, 5, number), 5, first);
    const std::vector<TrialRow> trials = store.trials(s.id);
    store.record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));

    // Resumed on another machine, which then measures its refresh.
    SessionEnvironment second = environment("lab-b", "GPU B", 144);
    second.stimuli = first.stimuli;
    EXPECT_EQ(store.begin_segment(s.id, second), 2);
    second.measured_refresh_hz = 143.9;
    store.update_environment(s.id, second);
    store.record_trial(s.id, trials[1].id, lucent::test::outcome_for(p, trials[1]));

    Database& db = store.db();
    Statement g = db.prepare(
        "SELECT segment, machine_id, gl_renderer, display_refresh_hz, "
        "measured_refresh_hz, stimulus_source FROM session_segments "
        "WHERE session_id = ? ORDER BY segment");
    g.bind(1, s.id);
    ASSERT_TRUE(g.step());
    EXPECT_EQ(g.integer(0), 1);
    EXPECT_EQ(g.text(1), "lab-a");
    EXPECT_EQ(g.text(2), "GPU A");
    EXPECT_EQ(g.real(3), 60.0);
    EXPECT_TRUE(g.is_null(4));
    EXPECT_EQ(g.text(5), "live");
    ASSERT_TRUE(g.step());
    EXPECT_EQ(g.integer(0), 2);
    EXPECT_EQ(g.text(1), "lab-b");
    EXPECT_EQ(g.text(2), "GPU B");
    EXPECT_EQ(g.real(4), 143.9);
    EXPECT_FALSE(g.step());
    // The session row keeps where it started; each trial knows its segment.
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM sessions WHERE gl_renderer = 'GPU A' "
                            "AND display_refresh_hz = 60"),
              1);
    Statement t = db.prepare(
        "SELECT g.segment FROM trials t JOIN session_segments g "
        "ON g.id = t.segment_id WHERE t.id IN (?, ?) ORDER BY t.position");
    t.bind(1, trials[0].id).bind(2, trials[1].id);
    ASSERT_TRUE(t.step());
    EXPECT_EQ(t.integer(0), 1);
    ASSERT_TRUE(t.step());
    EXPECT_EQ(t.integer(0), 2);
    // Each segment lists every stimulus it shows.
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM segment_stimuli"),
              2 * static_cast<int64_t>(p.stimuli.size()));
}

TEST(Provenance, ALaterSessionThatWouldShowOtherValuesIsRefused) {
    const auto dir = lucent::test::scratch_dir("provenance_refuse_later");
    const std::string path = (dir / "study.db").string();
    one_session(path, "0.8,0.55,0.35");
    Store store(path);
    const Protocol p = small_protocol();
    try {
        store.check_stimulus_values(provenance_for(p, "0.7,0.55,0.35"));
        FAIL() << "different resolved values accepted";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("stimulus 'a'"), std::string::npos) << what;
        EXPECT_NE(what.find("'albedo'"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_NO_THROW(store.check_stimulus_values(provenance_for(p, "0.8,0.55,0.35")));
}

TEST(Provenance, MergeRefusesStimuliWhoseResolvedValuesDifferNamingTheParameter) {
    const auto dir = lucent::test::scratch_dir("provenance_merge_refused");
    const std::string a = (dir / "a.db").string(), b = (dir / "b.db").string();
    one_session(a, "0.8,0.55,0.35");
    one_session(b, "0.7,0.55,0.35");
    const std::string out = (dir / "all.db").string();
    try {
        merge_databases({a, b}, out);
        FAIL() << "merge accepted different pictures under one stimulus id";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("stimulus 'a'"), std::string::npos) << what;
        EXPECT_NE(what.find("'albedo'"), std::string::npos) << what;
        EXPECT_NE(what.find("0.7,0.55,0.35"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(Provenance, MergeCarriesSegmentsAndWhatEachShowed) {
    const auto dir = lucent::test::scratch_dir("provenance_merge_copies");
    const std::string a = (dir / "a.db").string(), out = (dir / "all.db").string();
    one_session(a, "0.8,0.55,0.35");
    merge_databases({a}, out);
    Database db(out, SQLITE_OPEN_READONLY);
    const Protocol p = small_protocol();
    EXPECT_EQ(
        db.scalar_int("SELECT count(*) FROM session_segments WHERE machine_id = 'lab-a' "
                      "AND gl_renderer = 'GPU A'"),
        1);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM segment_stimuli"),
              static_cast<int64_t>(p.stimuli.size()));
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM trials WHERE segment_id IS NULL"), 0);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM stimulus_values v JOIN stimuli s ON "
                            "s.id = v.stimulus_id WHERE s.stimulus_key = 'a' AND "
                            "v.name = 'albedo' AND v.value = '0.8,0.55,0.35'"),
              1);
    std::ostringstream csv;
    std::vector<std::string> notes;
    export_csv(out, ExportFormat::Long, csv, &notes);
    EXPECT_TRUE(notes.empty()) << notes.front();
}

// A served session of `code` whose segment names a set of series pictures (issue 44,
// item 6): pictures a@k=0.1..0.3, the second with content hash `second_hash`.
void served_session(const std::string& path, const std::string& code,
                    const std::string& second_hash) {
    Store store(path);
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study, code, &number);
    SessionEnvironment env = environment("web", "agent", 60);
    env.stimuli = provenance_for(p, "0.8,0.55,0.35");
    for (const std::string& hash : {std::string("h1"), second_hash, std::string("h3")}) {
        StimulusProvenance picture;
        picture.stimulus = "a@k=0." + std::to_string(env.series_pictures.size() + 1);
        picture.source = "images";
        picture.file = picture.stimulus + ".png";
        picture.content_hash = hash;
        picture.software_version = "9.9.9";
        picture.build_hash = "test";
        env.series_pictures.push_back(picture);
    }
    const SessionRow s =
        store.create_session(study, pid, plan_trials(p, 5, number), 5, env);
    for (const TrialRow& t : store.trials(s.id))
        store.record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
}

TEST(Provenance, MergeCarriesSeriesPicturesOncePerSet) {
    const auto dir = lucent::test::scratch_dir("provenance_merge_series");
    const std::string a = (dir / "a.db").string(), b = (dir / "b.db").string(),
                      c = (dir / "c.db").string(), out = (dir / "all.db").string();
    served_session(a, "P1", "h2");
    served_session(b, "P2", "h2");      // the same set as a's
    served_session(c, "P3", "h2-new");  // another
    merge_databases({a, b, c}, out);
    Database db(out, SQLITE_OPEN_READONLY);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM series_pictures"), 6);
    EXPECT_EQ(db.scalar_int("SELECT count(DISTINCT series_set) FROM session_segments"),
              2);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM session_segments g JOIN "
                            "series_pictures x ON x.set_hash = g.series_set"),
              9);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM series_pictures WHERE picture = "
                            "'a@k=0.2' AND content_hash = 'h2-new'"),
              1);
}

TEST(Provenance, AVersion2DatabaseStillExportsWithANoteAndStaysVersion2) {
    const auto dir = lucent::test::scratch_dir("provenance_v2_export");
    const std::string path = (dir / "old.db").string();
    {
        Database db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        migrate(db, 2);
        db.exec(R"sql(
INSERT INTO studies VALUES (1, 'small', 'x', 'h', 'then');
INSERT INTO stimuli VALUES (1, 1, 'a', 'empirical', 'sphere', '', 'thickness_exponent');
INSERT INTO stimulus_parameters VALUES (1, 'thickness_exponent', '18');
INSERT INTO participants VALUES (1, 1, 'P1', 1, 'then');
INSERT INTO sessions (id, uuid, study_id, participant_id, machine_id, seed, cell,
    block_order, status, started_utc, software_version, build_hash, gl_renderer)
    VALUES (1, 'u-1', 1, 1, 'old-lab', '1', 0, 'main', 'completed', 'then', '0.1', 'b',
            'Old GPU');
INSERT INTO trials (id, session_id, position, block, stimulus_id, practice, catch,
    break_before) VALUES (1, 1, 1, 'main', 1, 0, 0, 0);
INSERT INTO responses VALUES (1, 1, 1, 'translucent', 5, 800, 0, 1, 2);
)sql");
    }
    std::ostringstream csv;
    std::vector<std::string> notes;
    EXPECT_EQ(export_csv(path, ExportFormat::Long, csv, &notes), 1);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("1 of 1 ratings"), std::string::npos) << notes[0];
    EXPECT_NE(notes[0].find("schema 3"), std::string::npos) << notes[0];
    // The rating and the protocol's own value are there; what was not stored is empty.
    std::istringstream lines(csv.str());
    std::string header, row;
    std::getline(lines, header);
    std::getline(lines, row);
    EXPECT_EQ(
        header.rfind("participant,session,trial_position,block,stimulus,technique,mesh,"
                     "thickness_exponent,mesh_hash,stimulus_source,",
                     0),
        0u)
        << header;
    EXPECT_EQ(row.rfind("P1,u-1,1,main,a,empirical,sphere,18,,,,,,,translucent,5,", 0),
              0u)
        << row;
    EXPECT_EQ(Database(path, SQLITE_OPEN_READONLY).scalar_int("PRAGMA user_version"), 2);

    // Opened for writing it migrates: the old session becomes its first segment.
    {
        Store store(path);
        EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM session_segments WHERE "
                                        "segment = 1 AND machine_id = 'old-lab' AND "
                                        "gl_renderer = 'Old GPU'"),
                  1);
    }
    notes.clear();
    export_csv(path, ExportFormat::Long, csv, &notes);
    EXPECT_EQ(notes.size(), 1u);
}

}  // namespace
}  // namespace lucent::study
