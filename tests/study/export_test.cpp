// Data out: CSV exports, the analysis long table, and merging databases.
#include "study/export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "study/observations.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using lucent::test::small_protocol;

// Minimal CSV reader (quotes, doubled quotes), independent of common/csv.h.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
    std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
    bool quoted = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"' && i + 1 < text.size() && text[i + 1] == '"')
                rows.back().back() += '"', ++i;
            else if (c == '"')
                quoted = false;
            else
                rows.back().back() += c;
        } else if (c == '"')
            quoted = true;
        else if (c == ',')
            rows.back().emplace_back();
        else if (c == '\n')
            rows.emplace_back(1);
        else
            rows.back().back() += c;
    }
    if (rows.back().size() == 1 && rows.back()[0].empty()) rows.pop_back();
    return rows;
}

int column(const std::vector<std::string>& header, const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i)
        if (header[i] == name) return static_cast<int>(i);
    ADD_FAILURE() << "no column " << name;
    return 0;
}

class ExportTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = lucent::test::scratch_dir(
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        path_ = (dir_ / "study.db").string();
        Store store(path_);
        lucent::test::run_full_session(store, p_, "P1", 11);
        lucent::test::run_full_session(store, p_, "P2", 12,
                                       /*catch_rating=*/2);  // fails catch
    }
    std::string export_text(ExportFormat f) {
        std::ostringstream out;
        export_csv(path_, f, out);
        return out.str();
    }
    Protocol p_ = small_protocol();
    fs::path dir_;
    std::string path_;
};

TEST_F(ExportTest, LongHasOneRowPerRatingWithParametersAndFlags) {
    const auto rows = parse_csv(export_text(ExportFormat::Long));
    ASSERT_FALSE(rows.empty());
    const auto& h = rows[0];
    // 2 participants x (1 practice + 3 rated + 1 catch) trials x 2 questions.
    ASSERT_EQ(rows.size(), 1u + 2 * 5 * 2);
    const int stimulus = column(h, "stimulus"), r = column(h, "thickness_exponent"),
              rough = column(h, "roughness"), rating = column(h, "rating"),
              pos = column(h, "trial_position"), q = column(h, "question"),
              practice = column(h, "practice"), is_catch = column(h, "catch"),
              passed = column(h, "catch_passed");
    const std::map<std::string, std::string> r_of = {
        {"a", "18"}, {"b", "25"}, {"c", "30"}, {"p", ""}};
    for (size_t i = 1; i < rows.size(); ++i) {
        const auto& row = rows[i];
        ASSERT_EQ(row.size(), h.size());
        EXPECT_EQ(row[r], r_of.at(row[stimulus]));
        EXPECT_EQ(row[rough], row[stimulus] == "p" ? "0.2" : "");
        EXPECT_EQ(row[practice], row[stimulus] == "p" ? "1" : "0");
        const int question = row[q] == "translucent" ? 0 : 1;
        if (row[is_catch] == "0")
            EXPECT_EQ(std::stoi(row[rating]),
                      lucent::test::rating_for(std::stoi(row[pos]), question));
        else
            EXPECT_EQ(row[passed], row[0] == "P1" ? "1" : "0");
        for (const std::string& cell : row) EXPECT_EQ(cell.find('{'), std::string::npos);
    }
}

TEST_F(ExportTest, WideHasOneRowPerParticipantWithEachRating) {
    const auto rows = parse_csv(export_text(ExportFormat::Wide));
    ASSERT_EQ(rows.size(), 3u);
    const auto& h = rows[0];
    EXPECT_EQ(h.size(), 3u + 3 * 2);  // participant, sessions, catch_failed, a/b/c x 2
    // Recompute P1's ratings from the plan the session used (seed 11, participant 1).
    const TrialPlan plan = plan_trials(p_, 11, 1);
    for (const PlannedTrial& t : plan.trials) {
        if (t.practice || t.is_catch) continue;
        for (int q = 0; q < 2; ++q) {
            const int c = column(h, t.stimulus + "." + p_.questions[q].id);
            EXPECT_EQ(rows[1][c],
                      std::to_string(lucent::test::rating_for(t.position, q)));
        }
    }
    EXPECT_EQ(rows[1][column(h, "catch_failed")], "0");
    EXPECT_EQ(rows[2][column(h, "catch_failed")], "1");
}

TEST_F(ExportTest, AnalysisLongTableExcludesPracticeCatchAndFailedParticipants) {
    const StudyObservations read = read_observations(path_);
    ASSERT_EQ(read.selection.excluded_participants.size(), 1u);
    EXPECT_EQ(read.selection.excluded_participants[0].rfind("P2", 0), 0u);
    // P1: 3 rated stimuli x 2 questions x 1 factor (each varies thickness_exponent only).
    const auto rows = common::factor_ratings(read.table);
    ASSERT_EQ(rows.size(), 6u);
    for (const auto& r : rows) {
        const std::string& stimulus = r.observation->shown.front();
        EXPECT_EQ(r.observation->participant, "P1");
        EXPECT_EQ(*r.factor, "thickness_exponent");
        EXPECT_EQ(*r.level,
                  p_.find_stimulus(stimulus)->parameters.at("thickness_exponent"));
        EXPECT_NE(stimulus, "p");
    }
    const StudyObservations all =
        read_observations(path_, {.exclude_failed_catch = false});
    EXPECT_EQ(common::factor_ratings(all.table).size(), 12u);
    std::ostringstream csv;
    EXPECT_EQ(write_factor_ratings_csv(read.table, csv), 6);
    EXPECT_EQ(csv.str().substr(0, csv.str().find('\n')),
              "participant,stimulus,factor,level,question,rating");
}

// A comparison series (`varies = ["series:NAME"]`): a factor NAME whose levels are the
// stimuli that list it, next to their own parameter factors.
TEST(ExportSeries, ComparisonSeriesLevelsAreTheStimuli) {
    std::string text = lucent::test::kSmallProtocol;
    for (const char* id : {"\"a\"", "\"c\""}) {
        const size_t at = text.find("varies = [\"thickness_exponent\"]",
                                    text.find("id = " + std::string(id)));
        ASSERT_NE(at, std::string::npos);
        text.replace(at, 32, "varies = [\"thickness_exponent\", \"series:pair\"]");
    }
    const Protocol p = parse_protocol(text, "series.toml");
    EXPECT_EQ(p.level_of(*p.find_stimulus("a"), "series:pair"), "a");
    const fs::path dir = lucent::test::scratch_dir("ExportSeriesComparison");
    const std::string path = (dir / "study.db").string();
    {
        Store store(path);
        lucent::test::run_full_session(store, p, "P1", 11);
    }
    const StudyObservations read = read_observations(path);
    std::map<std::string, int> levels;
    int thickness = 0;
    for (const auto& r : common::factor_ratings(read.table)) {
        if (*r.factor == "pair") {
            EXPECT_EQ(*r.level, r.observation->shown.front());
            ++levels[*r.level];
        } else {
            EXPECT_EQ(*r.factor, "thickness_exponent");
            ++thickness;
        }
    }
    // a and c, 2 questions each; every rated stimulus keeps its thickness factor.
    EXPECT_EQ(levels, (std::map<std::string, int>{{"a", 2}, {"c", 2}}));
    EXPECT_EQ(thickness, 6);
    // A misspelt series is still an error.
    std::string bad = text;
    bad.replace(bad.find("series:pair"), 11, "series:");
    EXPECT_THROW(parse_protocol(bad, "bad.toml"), ProtocolError);
}

// Bytes of a file, to show it is untouched.
std::string file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Temporary output files left in a folder (none, once a command has finished).
int temporaries_in(const fs::path& dir) {
    int n = 0;
    for (const auto& entry : fs::directory_iterator(dir))
        n += entry.path().filename().string().find(".partial") != std::string::npos;
    return n;
}

TEST_F(ExportTest, ExportFileNeverReplacesTheDatabaseOrAnyDatabase) {
    const int64_t ratings =
        Store(path_).db().scalar_int("SELECT count(*) FROM responses");
    const std::string before = file_bytes(path_);
    fs::create_symlink(path_, dir_ / "ratings.csv");
    fs::create_directories(dir_ / "sub");
    const fs::path cwd = fs::current_path();
    fs::current_path(dir_ / "sub");
    for (const std::string& out :
         {path_, (dir_ / "ratings.csv").string(),
          (dir_ / "sub" / ".." / "study.db").string(), std::string("../study.db")}) {
        for (const char* format : {"long", "wide", "analysis"}) {
            try {
                export_file(path_, format, out, /*force=*/true);
                ADD_FAILURE() << "exported over " << out;
            } catch (const StoreError& e) {
                EXPECT_NE(std::string(e.what()).find("is the input"), std::string::npos)
                    << e.what();
            }
        }
    }
    fs::current_path(cwd);
    EXPECT_EQ(file_bytes(path_), before);
    EXPECT_EQ(Store(path_).db().scalar_int("SELECT count(*) FROM responses"), ratings);
    // Another study database is refused as well, even with force.
    const std::string other = (dir_ / "other.db").string();
    Store(other).db();
    EXPECT_THROW(export_file(path_, "long", other, true), StoreError);
    EXPECT_EQ(Store(other).db().scalar_int(
                  "SELECT count(*) FROM sqlite_schema WHERE name = 'responses'"),
              1);
}

TEST_F(ExportTest, ExportFileReplacesAnExistingCsvOnlyWithForce) {
    const fs::path out = dir_ / "long.csv";
    std::ofstream(out) << "earlier export\n";
    try {
        export_file(path_, "long", out.string(), false);
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
    }
    EXPECT_EQ(file_bytes(out), "earlier export\n");
    const ExportFileResult r = export_file(path_, "long", out.string(), true);
    EXPECT_EQ(r.rows, 2 * 5 * 2);
    std::ostringstream direct;
    export_csv(path_, ExportFormat::Long, direct);
    EXPECT_EQ(file_bytes(out), direct.str());
    EXPECT_EQ(temporaries_in(dir_), 0);
}

TEST_F(ExportTest, MergeDeduplicatesSessionsByUuid) {
    // Machine B: a copy of this database (same sessions) plus one new participant.
    const std::string b = (dir_ / "b.db").string();
    fs::copy_file(path_, b);
    {
        Store store(b);
        lucent::test::run_full_session(store, p_, "P3", 13);
    }
    const std::string out = (dir_ / "all.db").string();
    const MergeReport report = merge_databases({path_, b}, out);
    EXPECT_EQ(report.sessions_added, 3);
    EXPECT_EQ(report.sessions_already_present, 2);
    Store merged(out);
    Database& db = merged.db();
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM sessions"), 3);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM participants"), 3);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM responses"), 3 * 5 * 2);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM stimulus_parameters"),
              Store(path_).db().scalar_int("SELECT count(*) FROM stimulus_parameters"));
    // The merged long export equals the union of the inputs' rows.
    std::ostringstream merged_csv;
    EXPECT_EQ(export_csv(out, ExportFormat::Long, merged_csv), 3 * 5 * 2);
}

// Every rating with what identifies it, read straight from a database: session UUID,
// trial position, question, participant code and machine, stimulus, then the values.
using RatingRow = std::tuple<std::string, int64_t, std::string, std::string, std::string,
                             std::string, int64_t, double, int64_t, int64_t, int64_t>;
std::vector<RatingRow> rating_rows(const std::string& path) {
    Database db(path, SQLITE_OPEN_READONLY);
    Statement s = db.prepare(
        "SELECT se.uuid, t.position, r.question, p.code, se.machine_id, st.stimulus_key, "
        "r.rating, r.rt_ms, r.changes, r.first_choice_ns, r.final_choice_ns FROM "
        "responses r "
        "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = r.session_id "
        "JOIN participants p ON p.id = se.participant_id "
        "JOIN stimuli st ON st.id = t.stimulus_id");
    std::vector<RatingRow> rows;
    while (s.step())
        rows.emplace_back(s.text(0), s.integer(1), s.text(2), s.text(3), s.text(4),
                          s.text(5), s.integer(6), s.real(7), s.integer(8), s.integer(9),
                          s.integer(10));
    std::sort(rows.begin(), rows.end());
    return rows;
}

// A wide export as participant -> (column -> cell).
std::map<std::string, std::map<std::string, std::string>> wide_rows(
    const std::string& path) {
    std::ostringstream out;
    export_csv(path, ExportFormat::Wide, out);
    const auto rows = parse_csv(out.str());
    std::map<std::string, std::map<std::string, std::string>> by_participant;
    for (size_t r = 1; r < rows.size(); ++r)
        for (size_t c = 1; c < rows[0].size(); ++c)
            by_participant[rows[r][0]][rows[0][c]] = rows[r][c];
    return by_participant;
}

TEST_F(ExportTest, MergeKeepsOneCodeFromTwoMachinesApartAsTwoPeople) {
    // Two lab machines, both starting at P01 (the normal case).
    const std::string a = (dir_ / "lab_a.db").string(), b = (dir_ / "lab_b.db").string();
    {
        Store store(a);
        lucent::test::run_full_session(store, p_, "P01", 21);
        lucent::test::run_full_session(store, p_, "P02", 22);
        store.db().exec("UPDATE sessions SET machine_id = 'aaaaaaaa11112222'");
    }
    {
        Store store(b);
        lucent::test::run_full_session(store, p_, "P01", 31);
        lucent::test::run_full_session(store, p_, "P03", 32);
        store.db().exec("UPDATE sessions SET machine_id = 'bbbbbbbb33334444'");
        // Different answers from the second P01, so averaging would show.
        store.db().exec(
            "UPDATE responses SET rating = 8 - rating WHERE trial_id IN "
            "(SELECT id FROM trials WHERE catch = 0)");
    }
    const std::string out = (dir_ / "all.db").string();
    const MergeReport report = merge_databases({a, b}, out);
    EXPECT_EQ(report.sessions_added, 4);
    ASSERT_EQ(report.notes.size(), 1u);
    EXPECT_NE(report.notes[0].find("P01@aaaaaaaa P01@bbbbbbbb"), std::string::npos)
        << report.notes[0];
    EXPECT_EQ(report.notes[0].find('\n'), std::string::npos);

    // Row by row: every input rating is in the merge once, under its person's code.
    const std::map<std::pair<std::string, std::string>, std::string> code_of = {
        {{"P01", "aaaaaaaa11112222"}, "P01@aaaaaaaa"},
        {{"P02", "aaaaaaaa11112222"}, "P02"},
        {{"P01", "bbbbbbbb33334444"}, "P01@bbbbbbbb"},
        {{"P03", "bbbbbbbb33334444"}, "P03"}};
    std::vector<RatingRow> expected;
    for (const std::string& input : {a, b})
        for (RatingRow row : rating_rows(input)) {
            std::get<3>(row) = code_of.at({std::get<3>(row), std::get<4>(row)});
            expected.push_back(row);
        }
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(rating_rows(out), expected);

    // The wide export keeps the two people's rows as each machine had them.
    const auto merged_wide = wide_rows(out);
    EXPECT_EQ(merged_wide.size(), 4u);
    EXPECT_EQ(merged_wide.at("P01@aaaaaaaa"), wide_rows(a).at("P01"));
    EXPECT_EQ(merged_wide.at("P01@bbbbbbbb"), wide_rows(b).at("P01"));
    EXPECT_EQ(merged_wide.at("P03"), wide_rows(b).at("P03"));
}

TEST_F(ExportTest, MergeReadsAnOlderSchemaThroughAnUpgradedCopyAndLeavesItAlone) {
    const std::string old_db = (dir_ / "old.db").string();
    {
        Store store(old_db);
        lucent::test::run_full_session(store, p_, "P05", 41);
        // Back to schema 1, as a build of that schema left it.
        lucent::test::downgrade_schema(store.db(), 1);
    }
    ASSERT_EQ(Database(old_db, SQLITE_OPEN_READONLY).scalar_int("PRAGMA user_version"),
              1);
    const std::string before = file_bytes(old_db);
    const std::string out = (dir_ / "all.db").string();
    const MergeReport report = merge_databases({old_db, path_}, out);
    EXPECT_EQ(report.sessions_added, 3);
    ASSERT_EQ(report.notes.size(), 1u);
    EXPECT_NE(report.notes[0].find("schema 1"), std::string::npos) << report.notes[0];
    EXPECT_EQ(file_bytes(old_db), before);
    EXPECT_EQ(Database(old_db, SQLITE_OPEN_READONLY).scalar_int("PRAGMA user_version"),
              1);
    std::vector<RatingRow> expected = rating_rows(old_db);
    for (const RatingRow& row : rating_rows(path_)) expected.push_back(row);
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(rating_rows(out), expected);
    EXPECT_EQ(temporaries_in(dir_), 0);
}

TEST_F(ExportTest, MergeNeverWritesOverAnInputOrAnotherDatabase) {
    const std::string b = (dir_ / "b.db").string();
    fs::copy_file(path_, b);
    const std::string before = file_bytes(path_);
    for (const std::string& out : {path_, (dir_ / "sub" / ".." / "b.db").string()}) {
        fs::create_directories(dir_ / "sub");
        try {
            merge_databases({path_, b}, out);
            ADD_FAILURE() << "merged over " << out;
        } catch (const StoreError& e) {
            EXPECT_NE(std::string(e.what()).find("is the input"), std::string::npos)
                << e.what();
        }
    }
    EXPECT_EQ(file_bytes(path_), before);
}

TEST_F(ExportTest, MergeRefusesDifferentProtocolsAndWritesNothing) {
    const std::string other = (dir_ / "other.db").string();
    {
        Store store(other);
        lucent::test::run_full_session(store, builtin_protocol("thesis"), "P9", 1);
    }
    const std::string out = (dir_ / "all.db").string();
    try {
        merge_databases({path_, other}, out);
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("refusing to merge"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace lucent::study
