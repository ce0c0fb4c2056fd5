// Output files: an --out that would replace an input or a database is refused whatever
// path reaches it, existing files only go with overwrite, and writes are atomic.
#include "common/output_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "tests/support/test_paths.h"

namespace lucent::common {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

void write(const fs::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// The SQLite header followed by filler: enough for is_sqlite_database.
const std::string kSqliteBytes =
    std::string("SQLite format 3\0", 16) + std::string(84, 'x');

std::string refusal(const fs::path& out, const std::vector<fs::path>& inputs,
                    bool overwrite) {
    try {
        check_output_file(out, inputs, overwrite);
    } catch (const OutputError& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        return e.what();
    }
    return "";
}

// Files in `dir` other than `keep` (temporary files left behind would show up here).
std::vector<std::string> other_files(const fs::path& dir,
                                     const std::vector<std::string>& keep) {
    std::vector<std::string> out;
    for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (std::find(keep.begin(), keep.end(), name) == keep.end()) out.push_back(name);
    }
    return out;
}

TEST(CheckOutputFile, TheInputItselfIsRefusedThroughAnyPath) {
    const fs::path dir = test::scratch_dir("output_same_file");
    const fs::path db = dir / "study.db";
    write(db, kSqliteBytes);
    fs::create_directories(dir / "sub");
    fs::create_symlink(db, dir / "link.csv");
    fs::create_hard_link(db, dir / "hard.csv");
    for (const fs::path& out :
         {db, dir / "sub" / ".." / "study.db", dir / "link.csv", dir / "hard.csv"}) {
        // Even with overwrite (--force): it is the input.
        EXPECT_NE(refusal(out, {db}, true).find("is the input"), std::string::npos)
            << out;
    }
    // A relative path to the input from the current folder.
    const fs::path cwd = fs::current_path();
    fs::current_path(dir / "sub");
    EXPECT_NE(refusal("../study.db", {db}, true).find("is the input"), std::string::npos);
    EXPECT_NE(refusal("../study.db-wal", {db}, true).find("side file"),
              std::string::npos);
    fs::current_path(cwd);
    EXPECT_EQ(slurp(db), kSqliteBytes);
}

TEST(CheckOutputFile, AnyDatabaseExistingFilesDirectoriesAndMissingFolders) {
    const fs::path dir = test::scratch_dir("output_refusals");
    write(dir / "other.db", kSqliteBytes);
    write(dir / "old.csv", "a,b\n");
    write(dir / "input.csv", "x\n");
    EXPECT_NE(
        refusal(dir / "other.db", {dir / "input.csv"}, true).find("SQLite database"),
        std::string::npos);
    EXPECT_NE(refusal(dir / "old.csv", {dir / "input.csv"}, false).find("already exists"),
              std::string::npos);
    EXPECT_EQ(refusal(dir / "old.csv", {dir / "input.csv"}, true), "");
    EXPECT_EQ(refusal(dir / "new.csv", {dir / "input.csv"}, false), "");
    EXPECT_NE(refusal(dir, {}, true).find("is a directory"), std::string::npos);
    EXPECT_NE(refusal(dir / "no" / "such.csv", {}, true).find("does not exist"),
              std::string::npos);
    EXPECT_TRUE(is_sqlite_database(dir / "other.db"));
    EXPECT_FALSE(is_sqlite_database(dir / "old.csv"));
    EXPECT_FALSE(is_sqlite_database(dir / "absent"));
}

TEST(WriteFileAtomically, ReadersSeeTheOldFileOrTheWholeNewOne) {
    const fs::path dir = test::scratch_dir("output_atomic");
    const fs::path out = dir / "ratings.csv";
    write(out, "old\n");
    write_file_atomically(out, true, [&](std::ostream& stream) {
        stream << "new, first half\n";
        EXPECT_EQ(slurp(out),
                  "old\n");  // mid-write, the real name still holds the old file
        stream << "second half\n";
    });
    EXPECT_EQ(slurp(out), "new, first half\nsecond half\n");
    // A failing writer leaves the old file and no temporary behind.
    EXPECT_THROW(write_file_atomically(out, true,
                                       [](std::ostream& stream) {
                                           stream << "partial";
                                           throw OutputError("writer failed");
                                       }),
                 OutputError);
    EXPECT_EQ(slurp(out), "new, first half\nsecond half\n");
    EXPECT_TRUE(other_files(dir, {"ratings.csv"}).empty());
}

TEST(PendingOutput, WithoutOverwriteAFileThatAppearedMeanwhileIsKept) {
    const fs::path dir = test::scratch_dir("output_pending");
    const fs::path out = dir / "all.db";
    {
        PendingOutput pending(out, false);
        EXPECT_EQ(pending.temporary().parent_path(), fs::absolute(out).parent_path());
        write(pending.temporary(), "merged");
        write(out, "someone else's");  // e.g. a second merge into the same name
        EXPECT_THROW(pending.commit(), OutputError);
    }
    EXPECT_EQ(slurp(out), "someone else's");
    EXPECT_TRUE(other_files(dir, {"all.db"}).empty());
    {
        PendingOutput pending(dir / "fresh.db", false);
        write(pending.temporary(), "merged");
        write(pending.temporary().string() + "-wal", "");  // an empty log left by SQLite
        pending.commit();
    }
    EXPECT_EQ(slurp(dir / "fresh.db"), "merged");
    EXPECT_TRUE(other_files(dir, {"all.db", "fresh.db"}).empty());
    {
        // A log still holding data: moving the file alone would lose it.
        PendingOutput pending(dir / "open.db", false);
        write(pending.temporary(), "merged");
        write(pending.temporary().string() + "-wal", "frames");
        EXPECT_THROW(pending.commit(), OutputError);
    }
    EXPECT_FALSE(fs::exists(dir / "open.db"));
    EXPECT_TRUE(other_files(dir, {"all.db", "fresh.db"}).empty());
}

}  // namespace
}  // namespace lucent::common
