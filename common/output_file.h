#pragma once
// Output files of commands that read precious inputs (study databases, rating tables):
// the path checks that keep an --out from replacing an input or any database, and the
// atomic write (temporary sibling, fsync, rename) that keeps readers from ever seeing a
// half-written file. GL-free and SQLite-free: one helper for export, merge, analyze and
// simulate.
#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace lucent::common {

// A refused or failed output; what() is one line naming the path.
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// True when `path` is a file starting with the SQLite header (any database, Lucent's
// or another application's, whatever its name).
bool is_sqlite_database(const std::filesystem::path& path);

// Refuses (OutputError) an output path that is a directory, is the same file as one of
// `inputs` (same inode, whether reached through a symlink, a hard link or a relative
// path), is an input's SQLite side file (-wal, -shm, -journal), is an SQLite database,
// or already exists while `overwrite` is false, or whose folder does not exist.
// `overwrite_flag` (e.g. "--force") is named in the refusal of an existing file.
void check_output_file(const std::filesystem::path& out,
                       const std::vector<std::filesystem::path>& inputs, bool overwrite,
                       const std::string& overwrite_flag = "--force");

// An output written by path, e.g. by SQLite: a unique temporary sibling of `out` (same
// folder, so the rename is atomic) that commit() renames onto `out`. Without overwrite,
// commit() never replaces a file that appeared meanwhile. Until committed, the
// destructor removes the temporary file and its SQLite side files.
class PendingOutput {
public:
    PendingOutput(std::filesystem::path out, bool overwrite);
    ~PendingOutput();
    PendingOutput(const PendingOutput&) = delete;
    PendingOutput& operator=(const PendingOutput&) = delete;

    const std::filesystem::path& temporary() const { return temporary_; }
    const std::filesystem::path& target() const { return out_; }
    // Flushes the temporary file to disk and moves it into place.
    void commit();

private:
    std::filesystem::path out_, temporary_;
    bool overwrite_ = false;
    bool committed_ = false;
};

// Writes `out` through a PendingOutput: `write` fills the stream; a stream failure or
// an exception from `write` leaves `out` as it was.
void write_file_atomically(const std::filesystem::path& out, bool overwrite,
                           const std::function<void(std::ostream&)>& write);

}  // namespace lucent::common
