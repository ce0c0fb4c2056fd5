#include "study/serve/picture_names.h"

#include <algorithm>
#include <stdexcept>

#include "study/sha256.h"

namespace lucent::study {
namespace {

constexpr size_t kNonceBytes = 8, kIndexBytes = 4, kTagBytes = 8;
constexpr size_t kNameDigits = 2 * (kNonceBytes + kIndexBytes + kTagBytes);
constexpr std::string_view kPrefix = "/images/", kSuffix = ".png";

std::string hmac_bytes(std::string_view key, std::string_view message, size_t bytes) {
    return bytes_of_hex(hmac_sha256_hex(key, message).substr(0, 2 * bytes));
}

std::string hex_of(std::string_view bytes) {
    constexpr char kDigits[] = "0123456789abcdef";
    std::string out;
    for (const char c : bytes) {
        out += kDigits[static_cast<unsigned char>(c) >> 4];
        out += kDigits[static_cast<unsigned char>(c) & 15];
    }
    return out;
}

// The picture index, XORed with a key stream of the nonce (encrypting and decrypting).
std::string crypt_index(std::string_view key, std::string_view nonce, std::string index) {
    const std::string stream =
        hmac_bytes(key, "index " + std::string(nonce), kIndexBytes);
    for (size_t i = 0; i < kIndexBytes; ++i)
        index[i] = static_cast<char>(index[i] ^ stream[i]);
    return index;
}

std::string tag_of(std::string_view key, std::string_view nonce,
                   std::string_view sealed) {
    return hmac_bytes(key, "tag " + std::string(nonce) + std::string(sealed), kTagBytes);
}

uint64_t seed_of(std::string_view nonce) {
    uint64_t seed = 0;
    for (const char c : nonce) seed = seed << 8 | static_cast<unsigned char>(c);
    return seed;
}

bool same_bytes(std::string_view a, std::string_view b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

// SplitMix64 (Steele, Lea and Flood 2014): a well-mixed value per pixel from one seed.
uint64_t mix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

}  // namespace

PictureNames::PictureNames(std::string_view secret, std::vector<std::string> ids)
    : ids_(std::move(ids)) {
    std::sort(ids_.begin(), ids_.end());
    ids_.erase(std::unique(ids_.begin(), ids_.end()), ids_.end());
    // The list is part of the key: an instance with other pictures reads no name of
    // this one's as one of its own (404, never another picture).
    std::string list;
    for (const std::string& id : ids_) list += id + '\n';
    key_ =
        bytes_of_hex(hmac_sha256_hex(secret, "lucent picture names " + sha256_hex(list)));
}

std::string PictureNames::url(std::string_view trial_uuid, size_t slot,
                              const std::string& id) const {
    const auto at = std::lower_bound(ids_.begin(), ids_.end(), id);
    if (at == ids_.end() || *at != id)
        throw std::out_of_range("no picture '" + id + "' in the study");
    const auto index = static_cast<uint32_t>(at - ids_.begin());
    const std::string nonce = hmac_bytes(
        key_, "slot " + std::string(trial_uuid) + " " + std::to_string(slot) + " " + id,
        kNonceBytes);
    std::string plain(kIndexBytes, '\0');
    for (size_t i = 0; i < kIndexBytes; ++i)
        plain[i] = static_cast<char>(index >> (8 * (kIndexBytes - 1 - i)) & 0xff);
    const std::string sealed = crypt_index(key_, nonce, plain);
    return std::string(kPrefix) + hex_of(nonce + sealed + tag_of(key_, nonce, sealed)) +
           std::string(kSuffix);
}

std::optional<NamedPicture> PictureNames::picture(std::string_view target) const {
    target = target.substr(0, target.find('?'));
    if (target.size() != kPrefix.size() + kNameDigits + kSuffix.size() ||
        target.substr(0, kPrefix.size()) != kPrefix ||
        target.substr(target.size() - kSuffix.size()) != kSuffix)
        return std::nullopt;
    const std::string_view name = target.substr(kPrefix.size(), kNameDigits);
    // Lower-case hex only: one spelling per name.
    if (!std::all_of(name.begin(), name.end(), [](char c) {
            return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
        }))
        return std::nullopt;
    const std::string bytes = bytes_of_hex(name);
    const std::string nonce = bytes.substr(0, kNonceBytes);
    const std::string sealed = bytes.substr(kNonceBytes, kIndexBytes);
    if (!same_bytes(bytes.substr(kNonceBytes + kIndexBytes), tag_of(key_, nonce, sealed)))
        return std::nullopt;
    const std::string plain = crypt_index(key_, nonce, sealed);
    uint32_t index = 0;
    for (const char c : plain) index = index << 8 | static_cast<unsigned char>(c);
    if (index >= ids_.size()) return std::nullopt;
    return NamedPicture{ids_[index], seed_of(nonce)};
}

size_t add_serving_noise(std::vector<uint8_t>& rgba, uint64_t seed) {
    size_t changed = 0;
    for (size_t i = 0; i < rgba.size(); ++i) {
        if (i % 4 == 3 || rgba[i] == 0 || rgba[i] == 255) continue;
        // Three outcomes from 64 well-mixed bits: a bias of at most 2^-62.
        const int step = static_cast<int>(mix(seed ^ mix(i)) % 3) - 1;
        rgba[i] = static_cast<uint8_t>(rgba[i] + step);
        changed += step != 0;
    }
    return changed;
}

}  // namespace lucent::study
