#pragma once
// Colour maps for heat maps.
#include <array>
#include <cstdint>

namespace rtcost {

/// Viridis at `t` in [0, 1] (clamped; NaN gives the low end) as 8-bit sRGB.
std::array<std::uint8_t, 3> viridis(double t);

}  // namespace rtcost
