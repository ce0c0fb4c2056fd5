// Output path checks and atomic writes (see output_file.h).
#include "common/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>

namespace lucent::common {
namespace {

namespace fs = std::filesystem;

// SQLite's side files of a database: writing over one corrupts the database.
constexpr const char* kSideFileSuffixes[] = {"-wal", "-shm", "-journal"};

fs::path folder_of(const fs::path& path) {
    const fs::path parent = fs::absolute(path).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

// Flushes a file or folder to disk; best effort where the file system cannot.
void sync_path(const fs::path& path, int flags) {
    const int fd = ::open(path.c_str(), flags);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

}  // namespace

bool is_sqlite_database(const fs::path& path) {
    std::error_code error;
    if (!fs::is_regular_file(path, error)) return false;
    char magic[16] = {};
    std::ifstream in(path, std::ios::binary);
    in.read(magic, sizeof magic);
    return in.gcount() == 16 &&
           std::string(magic, 16) == std::string("SQLite format 3\0", 16);
}

void check_output_file(const fs::path& out, const std::vector<fs::path>& inputs,
                       bool overwrite, const std::string& overwrite_flag) {
    std::error_code error;
    const std::string name = out.string();
    if (out.empty()) throw OutputError("output path is empty");
    const fs::file_status status = fs::status(out, error);  // follows symlinks
    const bool exists = fs::exists(status);
    if (fs::is_directory(status))
        throw OutputError(name + ": is a directory; give a file name");
    if (!fs::is_directory(folder_of(out), error))
        throw OutputError(name + ": folder " + folder_of(out).string() +
                          " does not exist");
    const fs::path target = fs::weakly_canonical(fs::absolute(out), error);
    for (const fs::path& input : inputs) {
        if (exists && fs::exists(input, error) && fs::equivalent(out, input, error))
            throw OutputError(name + ": is the input " + input.string() +
                              "; refusing to overwrite it");
        const fs::path canonical_input = fs::weakly_canonical(fs::absolute(input), error);
        for (const char* suffix : kSideFileSuffixes) {
            const fs::path side = canonical_input.string() + suffix;
            if (target == side ||
                (exists && fs::exists(side, error) && fs::equivalent(out, side, error)))
                throw OutputError(name + ": is a side file of the database " +
                                  input.string() + "; refusing to write it");
        }
    }
    if (!exists) return;
    if (is_sqlite_database(out))
        throw OutputError(name +
                          ": is an SQLite database; refusing to overwrite it "
                          "(choose another output file)");
    if (!overwrite)
        throw OutputError(
            name + ": already exists; refusing to overwrite it" +
            (overwrite_flag.empty() ? "" : " (" + overwrite_flag + " replaces it)"));
}

PendingOutput::PendingOutput(fs::path out, bool overwrite)
    : out_(std::move(out)), overwrite_(overwrite) {
    std::random_device entropy;
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "%d-%08x%08x", static_cast<int>(::getpid()),
                  entropy(), entropy());
    temporary_ =
        folder_of(out_) / ("." + out_.filename().string() + ".partial-" + suffix);
}

PendingOutput::~PendingOutput() {
    if (committed_) return;
    std::error_code ignored;
    fs::remove(temporary_, ignored);
    for (const char* suffix : kSideFileSuffixes)
        fs::remove(temporary_.string() + suffix, ignored);
}

void PendingOutput::commit() {
    const std::string name = out_.string();
    // A database must be closed (its log checkpointed into the file) before it moves:
    // a non-empty side file holds data the renamed file would lack.
    for (const char* suffix : kSideFileSuffixes) {
        const fs::path side = temporary_.string() + suffix;
        std::error_code error;
        if (!fs::exists(side, error)) continue;
        if (fs::file_size(side, error) > 0)
            throw OutputError(name + ": the database written is still open (" +
                              side.filename().string() +
                              " is not empty); not moved into place");
        fs::remove(side, error);
    }
    sync_path(temporary_, O_RDONLY);
    if (overwrite_) {
        if (std::rename(temporary_.c_str(), out_.c_str()) != 0)
            throw OutputError(name + ": cannot move the finished file into place: " +
                              std::strerror(errno));
    } else if (::link(temporary_.c_str(), out_.c_str()) == 0) {
        ::unlink(temporary_.c_str());  // the new name holds the file now
    } else if (errno == EEXIST) {
        throw OutputError(name + ": appeared while it was being written; left as it is");
    } else {
        // No hard links on this file system: check, then rename (a narrow race).
        std::error_code error;
        if (fs::exists(fs::symlink_status(out_, error)))
            throw OutputError(name +
                              ": appeared while it was being written; left as it is");
        if (std::rename(temporary_.c_str(), out_.c_str()) != 0)
            throw OutputError(name + ": cannot move the finished file into place: " +
                              std::strerror(errno));
    }
    committed_ = true;
    sync_path(folder_of(out_), O_RDONLY | O_DIRECTORY);
}

void write_file_atomically(const fs::path& out, bool overwrite,
                           const std::function<void(std::ostream&)>& write) {
    PendingOutput pending(out, overwrite);
    {
        std::ofstream file(pending.temporary(), std::ios::binary | std::ios::trunc);
        if (!file)
            throw OutputError(out.string() + ": cannot write in " +
                              folder_of(out).string());
        write(file);
        file.close();
        if (!file) throw OutputError(out.string() + ": write failed (disk full?)");
    }
    pending.commit();
}

}  // namespace lucent::common
