// Data out: CSV exports, the analysis long table, and merging databases.
#include "export.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "store.h"
#include "study_fixtures.h"
#include "test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using lucent::test::small_protocol;

// Minimal CSV reader (quotes, doubled quotes), independent of csv_cell.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
    std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
    bool quoted = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') rows.back().back() += '"', ++i;
            else if (c == '"') quoted = false;
            else rows.back().back() += c;
        } else if (c == '"') quoted = true;
        else if (c == ',') rows.back().emplace_back();
        else if (c == '\n') rows.emplace_back(1);
        else rows.back().back() += c;
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

TEST(CsvCell, QuotesOnlyWhenNeeded) {
    EXPECT_EQ(csv_cell("plain"), "plain");
    EXPECT_EQ(csv_cell("a,b"), "\"a,b\"");
    EXPECT_EQ(csv_cell("say \"hi\""), "\"say \"\"hi\"\"\"");
    EXPECT_EQ(parse_csv(csv_cell("x,\"y\"\nz") + "\n")[0][0], "x,\"y\"\nz");
}

class ExportTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = lucent::test::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        path_ = (dir_ / "study.db").string();
        Store store(path_);
        lucent::test::run_full_session(store, p_, "P1", 11);
        lucent::test::run_full_session(store, p_, "P2", 12, /*catch_rating=*/2);  // fails catch
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
    const std::map<std::string, std::string> r_of = {{"a", "18"}, {"b", "25"}, {"c", "30"}, {"p", ""}};
    for (size_t i = 1; i < rows.size(); ++i) {
        const auto& row = rows[i];
        ASSERT_EQ(row.size(), h.size());
        EXPECT_EQ(row[r], r_of.at(row[stimulus]));
        EXPECT_EQ(row[rough], row[stimulus] == "p" ? "0.2" : "");
        EXPECT_EQ(row[practice], row[stimulus] == "p" ? "1" : "0");
        const int question = row[q] == "translucent" ? 0 : 1;
        if (row[is_catch] == "0")
            EXPECT_EQ(std::stoi(row[rating]), lucent::test::rating_for(std::stoi(row[pos]), question));
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
            EXPECT_EQ(rows[1][c], std::to_string(lucent::test::rating_for(t.position, q)));
        }
    }
    EXPECT_EQ(rows[1][column(h, "catch_failed")], "0");
    EXPECT_EQ(rows[2][column(h, "catch_failed")], "1");
}

TEST_F(ExportTest, AnalysisLongTableExcludesPracticeCatchAndFailedParticipants) {
    const LongTable table = analysis_long_table(path_);
    ASSERT_EQ(table.excluded_participants.size(), 1u);
    EXPECT_EQ(table.excluded_participants[0].rfind("P2", 0), 0u);
    // P1: 3 rated stimuli x 2 questions x 1 factor (each varies thickness_exponent only).
    ASSERT_EQ(table.rows.size(), 6u);
    for (const LongRow& r : table.rows) {
        EXPECT_EQ(r.participant, "P1");
        EXPECT_EQ(r.factor, "thickness_exponent");
        EXPECT_EQ(r.level, p_.find_stimulus(r.stimulus)->parameters.at("thickness_exponent"));
        EXPECT_NE(r.stimulus, "p");
    }
    const LongTable all = analysis_long_table(path_, {.exclude_failed_catch = false});
    EXPECT_EQ(all.rows.size(), 12u);
    std::ostringstream csv;
    write_long_table_csv(table, csv);
    EXPECT_EQ(csv.str().substr(0, csv.str().find('\n')),
              "participant,stimulus,factor,level,question,rating");
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
        EXPECT_NE(std::string(e.what()).find("refusing to merge"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace lucent::study
