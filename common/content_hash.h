#pragma once
// Content hashes: 64-bit FNV-1a over bytes fed in order (not cryptographic). They name
// cache files (meshes, ambient occlusion, density volumes), detect changed inputs in
// stimulus manifests and the study database, and key the frame plan's pass reuse; all of
// them are made by ContentHash, so one set of bytes has one hash everywhere.
//
// A stored hash must not change: feed the same bytes in the same order. Values that are
// stored are fed byte by byte in a fixed order (word, float_bits, field); value() and
// text() feed the machine's object representation, for keys that never leave a process.
#include <concepts>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>

namespace lucent::common {

class ContentHash {
public:
    // FNV-1a's 64-bit offset basis and prime.
    static constexpr std::uint64_t kOffsetBasis = 0xcbf29ce484222325ull;
    static constexpr std::uint64_t kPrime = 0x100000001b3ull;

    // Bytes, in order.
    ContentHash& bytes(const void* data, std::size_t size) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < size; ++i) state_ = (state_ ^ p[i]) * kPrime;
        return *this;
    }
    ContentHash& bytes(std::string_view data) { return bytes(data.data(), data.size()); }

    // A 32-bit word as four bytes, least significant first (the same on every machine).
    ContentHash& word(std::uint32_t w);
    // A float's bits as a word, -0 as +0 (values that compare equal hash alike).
    ContentHash& float_bits(float f);
    // Text after its length in decimal and ':' ("3:abc"), so fields never run together.
    ContentHash& field(std::string_view text);

    // A value's object representation (this machine's byte order and padding): for keys
    // that stay in one process.
    template <typename T>
    requires std::is_trivially_copyable_v<T> ContentHash& value(const T& v) {
        return bytes(&v, sizeof v);
    }
    // Text after its length as a std::size_t value(): in-process keys, like value().
    ContentHash& text(std::string_view s) {
        value(s.size());
        return bytes(s);
    }

    std::uint64_t result() const { return state_; }
    // The hash as 16 lower-case hex digits.
    std::string hex() const;

private:
    std::uint64_t state_ = kOffsetBasis;
};

// FNV-1a 64 of `data` in one call.
inline std::uint64_t fnv1a_64(std::string_view data) {
    return ContentHash().bytes(data).result();
}

// The hash (hex) of a file's bytes; throws std::runtime_error naming the file when it
// cannot be read.
std::string hash_file(const std::filesystem::path& path);

}  // namespace lucent::common
