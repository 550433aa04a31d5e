// Inside compare/: how fast depth and colour change across the screen at a pixel. The
// slope and gradient allowances of docs/tolerances.md scale with these; they are only
// asked for at the rare pixels whose error exceeds the flat part of a tolerance.
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

// Per axis, the larger one-sided depth difference to a neighbour showing the same
// primitive at distance 1, else at distance 2 (halved), in steps/px.
struct LocalSlope {
  std::optional<double> gx;
  std::optional<double> gy;
  bool complete() const { return gx.has_value() && gy.has_value(); }
  bool any() const { return gx.has_value() || gy.has_value(); }
  // Missing axes count as 0 (a lower bound).
  double magnitude() const { return std::hypot(gx.value_or(0.0), gy.value_or(0.0)); }
};
LocalSlope localDepthSlope(const Frame& u, const DepthScale& scale, int x, int y);

// The largest |dz| / distance to any drawn 8-neighbour, whatever its primitive: the slope
// of the surface around a pixel whose own primitive shows too few pixels to have one.
// nullopt when no neighbour is drawn (or the pixel itself is not).
std::optional<double> surfaceDepthSlope(const Frame& u, const DepthScale& scale, int x, int y);

// Least-squares depth planes z = c + a x + b y of requested primitives, fitted over every
// pixel where the frame shows them. Depth is linear in window x, y on a triangle (GL
// interpolates window z without perspective), so the fit is the triangle's own plane
// even where it shows only a sliver, as long as its pixels are not all on one line.
class PlaneFits {
 public:
  struct Fit {
    std::uint64_t pixels = 0;
    bool plane = false;  // pixels not collinear: slope = |(a, b)|
    double slope = 0.0;  // steps/px; with pixels >= 2 on one line, the slope along it
  };

  void request(std::uint32_t id) { requested_.push_back(id); }
  bool pending() const { return !requested_.empty(); }
  // One pass over the frame for every id requested since the last build.
  void build(const Frame& u, const DepthScale& scale);
  // nullptr when the id was not requested before the last build.
  const Fit* find(std::uint32_t id) const;

 private:
  std::vector<std::uint32_t> requested_;
  std::vector<std::uint32_t> ids_;  // sorted, unique: the fitted ids
  std::vector<Fit> fits_;
};

// How the colour around (x, y) varies, per channel, in 8-bit units. gradient: the largest
// difference to a 4-neighbour showing the same primitive (per px), else to any drawn
// 8-neighbour (divided by its distance), else 0. range: max - min over the drawn pixels
// of the 3x3 neighbourhood. Non-finite pixels are skipped.
struct ColourNeighbourhood {
  std::array<float, 4> gradient{};
  std::array<float, 4> range{};
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
