// Not part of lucent_renderer: executables that create GL contexts add this file to
// their own sources (a static library member defining it would never be linked in).
// Linked into every binary that creates GL contexts. Mesa's drivers are dlopen'ed and
// unloaded at exit, so LeakSanitizer reports their allocations with "<unknown module>"
// frames that no suppression file can name; leak checking is therefore off in these
// binaries (ASan's other checks and UBSan stay on). GL-free binaries keep leak checks.
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }
