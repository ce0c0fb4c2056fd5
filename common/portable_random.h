#pragma once
// Draws that give the same sequence from the same seed on every standard library
// (std::uniform_int_distribution and std::shuffle are implementation-defined): trial
// orders and interleaved staircases are reproducible from their stored seed.
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace lucent::common {

// Uniform integer in [0, n) (n > 0) by rejection, without the modulo bias.
inline std::uint64_t uniform_below(std::mt19937_64& rng, std::uint64_t n) {
    constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
    const std::uint64_t limit = kMax - kMax % n;
    std::uint64_t x;
    do x = rng();
    while (x >= limit);
    return x % n;
}

// Uniform double in [0, 1): the top 53 bits of one draw.
inline double uniform_unit(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Fisher-Yates with uniform_below.
template <class T>
void portable_shuffle(std::vector<T>& items, std::mt19937_64& rng) {
    for (std::size_t i = items.size(); i > 1; --i)
        std::swap(items[i - 1], items[uniform_below(rng, i)]);
}

}  // namespace lucent::common
