#pragma once
// The final colour pass: the one place where linear radiance becomes the values a
// display or an encoded file receives, for every runner and writer (`lucent render`'s
// PNG and TIFF files, the lab runner's live and EXR stimuli, the explorer's views,
// `lucent serve`'s page colours). Today it clamps to [0, 1] (NaN as black), applies the
// sRGB curve (IEC 61966-2-1) and rounds to the nearest code; a display's measured
// calibration and dithering belong here, not in the callers (as Filament's ColorGrading
// and Polyscope's final transform are one stage). Files that keep linear light (EXR,
// linear TIFF) do not pass through it.
#include <cstdint>

namespace lucent {

// The encoded value in [0, 1] of one linear channel: clamped (NaN as 0, -Inf as 0,
// +Inf as 1), then the sRGB curve, computed in float. For 16-bit files:
// lround(display_value(v) * 65535).
float display_value(float linear);

// The 8-bit code of one linear channel: exactly lround(display_value(v) * 255), by table
// (several times faster than the curve).
std::uint8_t display_code(float linear);

}  // namespace lucent
