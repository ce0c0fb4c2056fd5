// LeakSanitizer's suppressions for the store suite (a sanitizer build reads them; other
// builds never call this). libpqxx 6.4 (Debian 12) leaks the PGresult of a statement
// whose connection broke: it throws broken_connection before wrapping the result, so
// nothing frees it (fixed upstream in 7.x, jtv/libpqxx#500). The suite breaks
// connections on purpose (a server stopped mid-session), so those few hundred bytes per
// broken statement are the library's. The library has no frame pointers, so ASan's fast
// unwinder stops inside it and only its module can be named: allocations made inside
// libpqxx are not reported, while an object of ours that leaks (a connection, a store)
// is still reported from our own frame that allocated it.
extern "C" const char* __lsan_default_suppressions() { return "leak:libpqxx-6.4.so\n"; }
