#pragma once
// Software version and build hash, recorded in manifests and session rows.
namespace lucent {
const char* version_string();  // "0.1.0"
const char* build_hash();      // git describe of the build, or "unknown"
}  // namespace lucent
