#include "tests/study/faulty_vfs.h"

namespace lucent::test {
namespace {

struct FaultyFile {
    sqlite3_file base;
    sqlite3_file* real;  // the wrapped file, stored right after this struct
};

sqlite3_file* real(sqlite3_file* f) { return reinterpret_cast<FaultyFile*>(f)->real; }
sqlite3_vfs* g_base = nullptr;
sqlite3_vfs g_vfs;

int f_close(sqlite3_file* f) { return real(f)->pMethods->xClose(real(f)); }
int f_read(sqlite3_file* f, void* b, int n, sqlite3_int64 o) {
    return real(f)->pMethods->xRead(real(f), b, n, o);
}
int f_truncate(sqlite3_file* f, sqlite3_int64 s) {
    return real(f)->pMethods->xTruncate(real(f), s);
}
int f_sync(sqlite3_file* f, int flags) {
    return real(f)->pMethods->xSync(real(f), flags);
}
int f_size(sqlite3_file* f, sqlite3_int64* s) {
    return real(f)->pMethods->xFileSize(real(f), s);
}
int f_lock(sqlite3_file* f, int l) { return real(f)->pMethods->xLock(real(f), l); }
int f_unlock(sqlite3_file* f, int l) { return real(f)->pMethods->xUnlock(real(f), l); }
int f_reserved(sqlite3_file* f, int* r) {
    return real(f)->pMethods->xCheckReservedLock(real(f), r);
}
int f_control(sqlite3_file* f, int op, void* a) {
    return real(f)->pMethods->xFileControl(real(f), op, a);
}
int f_sector(sqlite3_file* f) { return real(f)->pMethods->xSectorSize(real(f)); }
int f_device(sqlite3_file* f) {
    return real(f)->pMethods->xDeviceCharacteristics(real(f));
}
int f_shm_map(sqlite3_file* f, int i, int s, int e, void volatile** p) {
    return real(f)->pMethods->xShmMap(real(f), i, s, e, p);
}
int f_shm_lock(sqlite3_file* f, int o, int n, int fl) {
    return real(f)->pMethods->xShmLock(real(f), o, n, fl);
}
void f_shm_barrier(sqlite3_file* f) { real(f)->pMethods->xShmBarrier(real(f)); }
int f_shm_unmap(sqlite3_file* f, int d) {
    return real(f)->pMethods->xShmUnmap(real(f), d);
}
int f_fetch(sqlite3_file* f, sqlite3_int64 o, int n, void** p) {
    return real(f)->pMethods->xFetch(real(f), o, n, p);
}
int f_unfetch(sqlite3_file* f, sqlite3_int64 o, void* p) {
    return real(f)->pMethods->xUnfetch(real(f), o, p);
}

}  // namespace

int faulty_write(sqlite3_file* f, const void* b, int n, sqlite3_int64 o) {
    if (FaultyVfs::countdown_ > 0 && ++FaultyVfs::writes_ == FaultyVfs::countdown_) {
        FaultyVfs::fired_ = true;
        return SQLITE_IOERR_WRITE;
    }
    return real(f)->pMethods->xWrite(real(f), b, n, o);
}

namespace {

const sqlite3_io_methods g_methods = {
    3,          f_close,       f_read,      faulty_write, f_truncate, f_sync,   f_size,
    f_lock,     f_unlock,      f_reserved,  f_control,    f_sector,   f_device, f_shm_map,
    f_shm_lock, f_shm_barrier, f_shm_unmap, f_fetch,      f_unfetch};

int f_open(sqlite3_vfs*, const char* name, sqlite3_file* file, int flags,
           int* out_flags) {
    auto* ff = reinterpret_cast<FaultyFile*>(file);
    ff->real = reinterpret_cast<sqlite3_file*>(ff + 1);
    ff->base.pMethods = nullptr;
    int rc = g_base->xOpen(g_base, name, ff->real, flags, out_flags);
    if (ff->real->pMethods) ff->base.pMethods = &g_methods;
    return rc;
}

}  // namespace

void FaultyVfs::install() {
    if (g_base) return;
    g_base = sqlite3_vfs_find(nullptr);
    g_vfs = *g_base;
    g_vfs.zName = kName;
    g_vfs.szOsFile = static_cast<int>(sizeof(FaultyFile)) + g_base->szOsFile;
    g_vfs.xOpen = f_open;
    g_vfs.pNext = nullptr;
    sqlite3_vfs_register(&g_vfs, 0);
}

}  // namespace lucent::test
