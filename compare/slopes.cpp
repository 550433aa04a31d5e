// Colour gradients around a pixel: see slopes.h.
#include "compare/slopes.h"

#include <algorithm>
#include <bit>
#include <limits>

namespace rc::detail {
namespace {

bool finite(float v) { return std::isfinite(v); }

}  // namespace

ColourNeighbourhood colourNeighbourhood(const Frame& f, int x, int y) {
  ColourNeighbourhood out;
  const std::size_t i = f.index(x, y);
  const float* c = &f.color[i * 4];
  for (int k = 0; k < 4; ++k)
    if (!finite(c[k])) return out;
  std::array<float, 4> same{};  // gradient to same-primitive 4-neighbours
  std::array<float, 4> any{};   // gradient to any drawn 8-neighbour
  bool found_same = false;
  forEachNeighbour(f, x, y, [&](std::size_t j, int dx, int dy) {
    if (f.id[j] == 0) return true;
    const float* n = &f.color[j * 4];
    if (!finite(n[0]) || !finite(n[1]) || !finite(n[2]) || !finite(n[3])) return true;
    const bool diagonal = dx != 0 && dy != 0;
    const bool same_4 = !diagonal && f.id[j] == f.id[i];
    found_same = found_same || same_4;
    const float inv_dist = diagonal ? 1.0f / 1.41421356f : 1.0f;
    for (int k = 0; k < 4; ++k) {
      const float diff = std::fabs(n[k] - c[k]) * 255.0f;
      if (same_4) same[k] = std::max(same[k], diff);
      any[k] = std::max(any[k], diff * inv_dist);
    }
    return true;
  });
  out.gradient = found_same ? same : any;
  return out;
}

}  // namespace rc::detail
