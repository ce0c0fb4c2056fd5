#pragma once
// SHA-256 (FIPS 180-4), for protocol hashes; no crypto library is in the stack.
#include <string>
#include <string_view>

namespace lucent::study {
std::string sha256_hex(std::string_view data);  // 64 lower-case hex digits
}  // namespace lucent::study
