#pragma once
// Colour-space constants shared by the perceptual metrics (CIEDE2000, LDR-FLIP).

namespace rc {

// sRGB primaries and D65 white (IEC 61966-2-1): linear RGB to CIE XYZ.
inline constexpr double kRgbToXyz[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                           {0.2126729, 0.7151522, 0.0721750},
                                           {0.0193339, 0.1191920, 0.9503041}};

}  // namespace rc
