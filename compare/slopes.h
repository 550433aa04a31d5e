// Inside compare/: the depth scale the comparator counts steps in, and how fast colour
// changes across the screen around a pixel (the gradient and linear-filtering allowances
// of docs/tolerances.md scale with it; only asked for at the rare pixels whose error
// exceeds the flat part of a tolerance). Depth slopes come from the reference's
// depth_slope channel, not from here.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "fixtures/frame.h"

namespace rc::detail {

// Depth in steps of the format, as the comparator counts them (rounded for d16/d24).
struct DepthScale {
  double steps_per_unit = 16777215.0;
  bool quantized = true;
  double operator()(float z) const {
    const double s = static_cast<double>(z) * steps_per_unit;
    // Round to nearest without libm: adding 1.5 * 2^52 leaves no fraction bits.
    constexpr double kMagic = 6755399441055744.0;
    return quantized ? (s + kMagic) - kMagic : s;
  }
};

// How the colour around (x, y) varies, per channel, in 8-bit units per px: the largest
// difference to a 4-neighbour showing the same primitive, else to any drawn 8-neighbour
// (divided by its distance), else 0. Non-finite pixels are skipped.
struct ColourNeighbourhood {
  std::array<float, 4> gradient{};
};
ColourNeighbourhood colourNeighbourhood(const Frame& f, int x, int y);

// Calls fn(index, dx, dy) for each of the up to 8 neighbours of (x, y) inside the frame,
// row by row; stops early and returns false when fn returns false.
template <class Fn>
bool forEachNeighbour(const Frame& f, int x, int y, Fn&& fn) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx;
      const int ny = y + dy;
      if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= f.width || ny >= f.height) continue;
      if (!fn(f.index(nx, ny), dx, dy)) return false;
    }
  }
  return true;
}

}  // namespace rc::detail
