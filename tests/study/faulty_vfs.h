#pragma once
// An SQLite VFS that forwards to the default one and fails the Nth xWrite, after the
// style of SQLite's own test_vfs.c fault injection.
#include <sqlite3.h>

namespace lucent::test {

class FaultyVfs {
public:
    static constexpr const char* kName = "lucent-faulty";
    // Registers the VFS once (not as default).
    static void install();
    // Fail the Nth write from now (1-based); 0 disarms.
    static void fail_write(int n) {
        countdown_ = n;
        writes_ = 0;
    }
    static int writes() { return writes_; }
    static bool fired() { return fired_; }
    static void reset() {
        countdown_ = 0;
        writes_ = 0;
        fired_ = false;
    }

private:
    friend int faulty_write(sqlite3_file*, const void*, int, sqlite3_int64);
    static inline int countdown_ = 0;
    static inline int writes_ = 0;
    static inline bool fired_ = false;
};

}  // namespace lucent::test
