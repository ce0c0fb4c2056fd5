// Issue 51 item 3: one table from a study to the statistics. `lucent analyze` reads a
// study database and the same study exported as its table of observations (`lucent
// export --format observations`) through the same views, so every statistic it writes
// is the same, byte for byte, whichever it was given.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_main.h"
#include "app/commands.h"
#include "study/export.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::app {
namespace {

namespace fs = std::filesystem;

int analyze(std::vector<std::string> args) {
    args.insert(args.begin(), {"lucent", "analyze"});
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    return run_cli(static_cast<int>(argv.size()), argv.data(), {register_analyze});
}

std::string read(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// Analyses `db` and its exported observations alike; every named report file must be
// written by both and be the same.
void expect_same_statistics(const std::string& name, const study::Protocol& protocol,
                            const std::vector<std::string>& files) {
    const fs::path dir = lucent::test::scratch_dir("observation_roundtrip_" + name);
    const std::string db = (dir / "study.db").string();
    {
        study::Store store(db);
        for (int i = 1; i <= 4; ++i)
            lucent::test::run_full_session(store, protocol, "P" + std::to_string(i),
                                           10 + i);
    }
    const std::string csv = (dir / "observations.csv").string();
    ASSERT_GT(study::export_file(db, "observations", csv, false).rows, 0);
    const std::vector<std::string> options = {
        "--design",    "within", "--model",     "anova,clmm,lmm",
        "--bootstrap", "0",      "--six-point", "0"};
    for (const auto& [input, out] :
         {std::pair{db, dir / "from_db"}, {csv, dir / "from_csv"}}) {
        std::vector<std::string> args = {input, "--out", out.string()};
        args.insert(args.end(), options.begin(), options.end());
        ASSERT_EQ(analyze(args), kExitOk) << input;
    }
    for (const std::string& file : files) {
        const std::string from_db = read(dir / "from_db" / file);
        EXPECT_FALSE(from_db.empty()) << file;
        EXPECT_EQ(from_db, read(dir / "from_csv" / file)) << file;
    }
}

TEST(ObservationRoundTrip, RatingsGiveTheSameStatisticsFromTheDatabaseAndItsExport) {
    expect_same_statistics(
        "ratings", lucent::test::small_protocol(),
        {"descriptives.csv", "anova.csv", "tukey.csv", "kruskal.csv", "welch.csv",
         "rm_anova.csv", "mixed_tests.csv", "mixed_effects.csv"});
}

TEST(ObservationRoundTrip, ForcedChoicesGiveTheSameScales) {
    expect_same_statistics("choices", lucent::test::choice_protocol(), {"scaling.csv"});
}

}  // namespace
}  // namespace lucent::app
