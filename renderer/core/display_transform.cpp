// The final colour pass (display_transform.h).
#include "renderer/core/display_transform.h"

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "common/srgb.h"

namespace lucent {
namespace {

// Non-negative: their bit patterns order as their values (the table relies on it).
float clamp_unit(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

// threshold[k] is the smallest float whose lround(display_value(v) * 255) is at least k
// (binary search over the float bit patterns, as the curve is monotone), and bucket[]
// the code at the start of each run of 2^16 bit patterns, so a lookup is one index plus
// at most a few compares.
struct CodeTable {
    static constexpr int kShift = 16;
    float threshold[257];
    std::vector<std::uint8_t> bucket;

    static int direct(float v) { return int(std::lround(display_value(v) * 255.0f)); }
    static std::uint32_t bits(float v) { return std::bit_cast<std::uint32_t>(v); }

    CodeTable() {
        threshold[0] = 0.0f;
        for (int k = 1; k <= 255; ++k) {
            std::uint32_t lo = 0, hi = bits(1.0f);  // direct(lo) < k <= direct(hi)
            while (hi - lo > 1) {
                const std::uint32_t mid = lo + (hi - lo) / 2;
                (direct(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
            }
            threshold[k] = std::bit_cast<float>(hi);
        }
        threshold[256] = std::numeric_limits<float>::infinity();
        bucket.resize((bits(1.0f) >> kShift) + 1);
        int k = 0;
        for (std::size_t b = 0; b < bucket.size(); ++b) {
            const float start = std::bit_cast<float>(std::uint32_t(b << kShift));
            while (k < 255 && threshold[k + 1] <= start) ++k;
            bucket[b] = static_cast<std::uint8_t>(k);
        }
    }
};

const CodeTable& code_table() {
    static const CodeTable table;
    return table;
}

}  // namespace

float display_value(float linear) { return common::srgb_encode(clamp_unit(linear)); }

std::uint8_t display_code(float linear) {
    const CodeTable& table = code_table();
    const float u = clamp_unit(linear);
    int k = table.bucket[CodeTable::bits(u) >> CodeTable::kShift];
    while (table.threshold[k + 1] <= u) ++k;
    return static_cast<std::uint8_t>(k);
}

}  // namespace lucent
