#include "study/time_and_ids.h"

#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <random>

namespace lucent::study {

std::string utc_iso8601(std::chrono::system_clock::time_point t) {
    // Floor, not truncation: a time before 1970 keeps its milliseconds in [0, 1000).
    const auto secs = std::chrono::floor<std::chrono::seconds>(t);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(t - secs).count();
    const std::time_t whole = std::chrono::system_clock::to_time_t(secs);
    std::tm tm{};
    gmtime_r(&whole, &tm);
    char out[64];
    std::snprintf(out, sizeof out, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ",
                  tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min,
                  tm.tm_sec, static_cast<int>(ms));
    return out;
}

std::string utc_now_iso8601() { return utc_iso8601(std::chrono::system_clock::now()); }

std::string new_uuid_v4() {
    std::random_device device;
    std::mt19937_64 rng(
        (uint64_t(device()) << 32) ^ device() ^
        uint64_t(std::chrono::steady_clock::now().time_since_epoch().count()));
    uint64_t hi = rng(), lo = rng();
    hi = (hi & ~0xF000ull) | 0x4000ull;                  // version 4
    lo = (lo & ~(0xC000ull << 48)) | (0x8000ull << 48);  // variant 10xx
    char out[40];
    std::snprintf(out, sizeof out, "%08x-%04x-%04x-%04x-%012llx", uint32_t(hi >> 32),
                  uint32_t(hi >> 16) & 0xFFFF, uint32_t(hi) & 0xFFFF, uint32_t(lo >> 48),
                  static_cast<unsigned long long>(lo & 0xFFFFFFFFFFFFull));
    return out;
}

std::string machine_id() {
    std::ifstream in("/etc/machine-id");
    std::string id;
    if (in >> id && !id.empty()) return id;
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    return std::string("host:") + host;
}

}  // namespace lucent::study
