// A server's one snapshot is read from a temporary file; what is said about it names the
// server as given (issue 44, item 6): `lucent export` and `lucent analyze` notes.
#include <gtest/gtest.h>

#include "study/export.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"

namespace lucent::study {
namespace {

TEST(ReadableStudyFile, NotesAboutASnapshotNameTheServerNotTheTemporaryFile) {
    const std::string uri = lucent::test::new_postgres_database("readable_note");
    init_study_store(uri);
    const ReadableStudyFile source(uri);
    ASSERT_NE(source.path(), uri);
    const std::string note =
        "sessions of " + source.path() + ": none completed (" + source.path() + ")";
    const std::string said = source.as_given(note);
    EXPECT_EQ(said, "sessions of " + uri + ": none completed (" + uri + ")");
    EXPECT_EQ(said.find("lucent-snapshot"), std::string::npos) << said;
    // The analysis export's own note, as lucent export prints it.
    const std::string csv = source.path() + ".csv";
    const ExportFileResult r = export_file(source.path(), "analysis", csv, true);
    for (const std::string& n : r.notes)
        EXPECT_EQ(source.as_given(n).find("lucent-snapshot"), std::string::npos)
            << source.as_given(n);
    // A file is read as itself: nothing to rename.
    EXPECT_EQ(ReadableStudyFile(source.path()).as_given(note), note);
}

}  // namespace
}  // namespace lucent::study
