#pragma once
// The sRGB transfer function (IEC 61966-2-1) and its inverse, for images written and
// read (PNG, TIFF, textures, contact sheets) and colours shown in a browser. Header-only:
// float arguments are computed in float, double arguments in double, so each caller
// keeps the precision (and the 8-bit codes) it always had.
#include <algorithm>
#include <cmath>
#include <concepts>

namespace lucent::common {

// Linear -> encoded, the argument clamped to [0, 1] (NaN stays NaN).
template <std::floating_point T>
T srgb_encode(T linear) {
    const T v = std::clamp(linear, T(0), T(1));
    return v <= T(0.0031308) ? T(12.92) * v
                             : T(1.055) * std::pow(v, T(1) / T(2.4)) - T(0.055);
}

// Encoded -> linear, the argument clamped to [0, 1] (NaN stays NaN).
template <std::floating_point T>
T srgb_decode(T encoded) {
    const T v = std::clamp(encoded, T(0), T(1));
    return v <= T(0.04045) ? v / T(12.92) : std::pow((v + T(0.055)) / T(1.055), T(2.4));
}

}  // namespace lucent::common
