// 64-bit FNV-1a content hashes (see content_hash.h).
#include "common/content_hash.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace lucent::common {

ContentHash& ContentHash::word(std::uint32_t w) {
    const unsigned char b[4] = {static_cast<unsigned char>(w & 0xffu),
                                static_cast<unsigned char>((w >> 8) & 0xffu),
                                static_cast<unsigned char>((w >> 16) & 0xffu),
                                static_cast<unsigned char>((w >> 24) & 0xffu)};
    return bytes(b, sizeof b);
}

ContentHash& ContentHash::float_bits(float f) {
    const float value = f == 0.0f ? 0.0f : f;  // -0 and +0 hash alike
    std::uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    return word(bits);
}

ContentHash& ContentHash::field(std::string_view text) {
    bytes(std::to_string(text.size()) + ":");
    return bytes(text);
}

std::string ContentHash::hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(state_));
    return text;
}

std::string hash_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": cannot read");
    ContentHash hash;
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0)
        hash.bytes(buffer, static_cast<std::size_t>(in.gcount()));
    return hash.hex();
}

}  // namespace lucent::common
