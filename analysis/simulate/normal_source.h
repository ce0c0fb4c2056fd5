#pragma once
// Standard normal deviates from a seeded 64-bit generator by Box-Muller:
// std::normal_distribution differs between standard libraries, and a seeded study (or
// power simulation) must be the same on every machine.
#include <cmath>
#include <cstdint>
#include <random>

namespace lucent::analysis {

class NormalSource {
public:
    explicit NormalSource(std::uint64_t seed) : engine_(seed) {}
    double next() {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        const double u1 = uniform_open(), u2 = uniform_open();
        const double radius = std::sqrt(-2.0 * std::log(u1));
        const double angle = 6.283185307179586476925 * u2;
        spare_ = radius * std::sin(angle);
        has_spare_ = true;
        return radius * std::cos(angle);
    }

private:
    double uniform_open() {  // (0, 1): 53 random bits, never 0
        return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
    }
    std::mt19937_64 engine_;
    double spare_ = 0.0;
    bool has_spare_ = false;
};

}  // namespace lucent::analysis
