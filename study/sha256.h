#pragma once
// SHA-256 (FIPS 180-4) and HMAC-SHA256 (RFC 2104), for protocol hashes, session tokens
// and picture names; no crypto library is in the stack.
#include <string>
#include <string_view>

namespace lucent::study {
std::string sha256_hex(std::string_view data);  // 64 lower-case hex digits
// HMAC-SHA256 (RFC 2104) in lower-case hex.
std::string hmac_sha256_hex(std::string_view key, std::string_view message);
// The bytes a hex text spells (two digits a byte; the caller checked the digits).
std::string bytes_of_hex(std::string_view hex);
}  // namespace lucent::study
