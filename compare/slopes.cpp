// Depth slopes, per-primitive depth planes and colour gradients: see slopes.h.
#include "compare/slopes.h"

#include <algorithm>
#include <bit>
#include <limits>

namespace rc::detail {
namespace {

bool finite(float v) { return std::isfinite(v); }

__extension__ using Int128 = __int128;  // a GCC/Clang extension, like the vector types

constexpr double kDiagonal = 1.4142135623730951;

}  // namespace

LocalSlope localDepthSlope(const Frame& u, const DepthScale& scale, int x, int y) {
  LocalSlope out;
  const std::size_t i = u.index(x, y);
  const std::uint32_t id = u.id[i];
  if (id == 0 || !finite(u.depth[i])) return out;
  const double z0 = scale(u.depth[i]);
  auto axis = [&](int dx, int dy) -> std::optional<double> {
    for (int dist = 1; dist <= 2; ++dist) {
      std::optional<double> g;
      for (int sign : {-1, 1}) {
        const int nx = x + sign * dist * dx;
        const int ny = y + sign * dist * dy;
        if (nx < 0 || ny < 0 || nx >= u.width || ny >= u.height) continue;
        const std::size_t j = u.index(nx, ny);
        if (u.id[j] != id || !finite(u.depth[j])) continue;
        g = std::max(g.value_or(0.0), std::fabs(scale(u.depth[j]) - z0) / dist);
      }
      if (g) return g;
    }
    return std::nullopt;
  };
  out.gx = axis(1, 0);
  out.gy = axis(0, 1);
  return out;
}

std::optional<double> surfaceDepthSlope(const Frame& u, const DepthScale& scale, int x, int y) {
  const std::size_t i = u.index(x, y);
  if (u.id[i] == 0 || !finite(u.depth[i])) return std::nullopt;
  const double z0 = scale(u.depth[i]);
  std::optional<double> s;
  forEachNeighbour(u, x, y, [&](std::size_t j, int dx, int dy) {
    if (u.id[j] == 0 || !finite(u.depth[j])) return true;
    const double dist = dx != 0 && dy != 0 ? kDiagonal : 1.0;
    s = std::max(s.value_or(0.0), std::fabs(scale(u.depth[j]) - z0) / dist);
    return true;
  });
  return s;
}

void PlaneFits::build(const Frame& u, const DepthScale& scale) {
  ids_ = std::move(requested_);
  requested_.clear();
  std::sort(ids_.begin(), ids_.end());
  ids_.erase(std::unique(ids_.begin(), ids_.end()), ids_.end());
  fits_.assign(ids_.size(), Fit{});
  if (ids_.empty()) return;

  // Sums over each primitive's pixels, relative to its first pixel so that they stay
  // small. Coordinate sums are integers: exact, so collinear pixel sets are recognised
  // exactly (int128 holds the squares for any frame of < 2^31 pixels).
  struct Sums {
    bool anchored = false;
    int x0 = 0, y0 = 0;
    double z0 = 0.0;
    std::int64_t n = 0, sx = 0, sy = 0;
    Int128 sxx = 0, sxy = 0, syy = 0;
    double sz = 0.0, sxz = 0.0, syz = 0.0;
  };
  std::vector<Sums> sums(ids_.size());
  // A 2^16-bit prefilter keeps the per-pixel cost of ids that were not asked for to one
  // test; a hit is confirmed by binary search.
  constexpr unsigned kFilterBits = 16;
  std::vector<std::uint64_t> filter((1u << kFilterBits) / 64, 0);
  auto hash = [](std::uint32_t id) { return (id * 2654435761u) >> (32 - kFilterBits); };
  for (std::uint32_t id : ids_) filter[hash(id) / 64] |= std::uint64_t{1} << (hash(id) % 64);

  for (int y = 0; y < u.height; ++y) {
    const std::uint32_t* row = &u.id[u.index(0, y)];
    for (int x = 0; x < u.width; ++x) {
      const std::uint32_t id = row[x];
      const std::uint32_t h = hash(id);
      if (!((filter[h / 64] >> (h % 64)) & 1u)) continue;
      const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
      if (it == ids_.end() || *it != id) continue;
      const float zf = u.depth[u.index(x, y)];
      if (!finite(zf)) continue;
      Sums& s = sums[static_cast<std::size_t>(it - ids_.begin())];
      if (!s.anchored) {
        s.anchored = true;
        s.x0 = x;
        s.y0 = y;
        s.z0 = scale(zf);
      }
      const std::int64_t dx = x - s.x0;
      const std::int64_t dy = y - s.y0;
      const double dz = scale(zf) - s.z0;
      ++s.n;
      s.sx += dx;
      s.sy += dy;
      s.sxx += static_cast<Int128>(dx) * dx;
      s.sxy += static_cast<Int128>(dx) * dy;
      s.syy += static_cast<Int128>(dy) * dy;
      s.sz += dz;
      s.sxz += static_cast<double>(dx) * dz;
      s.syz += static_cast<double>(dy) * dz;
    }
  }

  for (std::size_t k = 0; k < ids_.size(); ++k) {
    const Sums& s = sums[k];
    Fit& f = fits_[k];
    f.pixels = static_cast<std::uint64_t>(s.n);
    if (s.n < 2) continue;
    // n^2 times the covariances (normal equations of the centred fit).
    const Int128 n = s.n;
    const Int128 nxx = n * s.sxx - static_cast<Int128>(s.sx) * s.sx;
    const Int128 nyy = n * s.syy - static_cast<Int128>(s.sy) * s.sy;
    const Int128 nxy = n * s.sxy - static_cast<Int128>(s.sx) * s.sy;
    const double dn = static_cast<double>(s.n);
    const double nxz = dn * s.sxz - static_cast<double>(s.sx) * s.sz;
    const double nyz = dn * s.syz - static_cast<double>(s.sy) * s.sz;
    constexpr Int128 kExactLimit = static_cast<Int128>(1) << 62;
    bool plane = false;
    if (nxx < kExactLimit && nyy < kExactLimit && nxy < kExactLimit && -nxy < kExactLimit) {
      plane = nxx * nyy - nxy * nxy > 0;
    } else {
      const long double rel =
          1.0L - (static_cast<long double>(nxy) * static_cast<long double>(nxy)) /
                     (static_cast<long double>(nxx) * static_cast<long double>(nyy));
      plane = rel > 1e-12L;
    }
    const double dxx = static_cast<double>(nxx);
    const double dyy = static_cast<double>(nyy);
    const double dxy = static_cast<double>(nxy);
    if (plane) {
      const double det = dxx * dyy - dxy * dxy;
      const double a = (dyy * nxz - dxy * nyz) / det;
      const double b = (dxx * nyz - dxy * nxz) / det;
      f.plane = true;
      f.slope = std::hypot(a, b);
    } else {
      // All pixels on one line: only the slope along it is known.
      f.slope = std::hypot(nxz, nyz) / (dxx + dyy);
    }
    if (!std::isfinite(f.slope)) f.slope = std::numeric_limits<double>::max();
  }
}

const PlaneFits::Fit* PlaneFits::find(std::uint32_t id) const {
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
  if (it == ids_.end() || *it != id) return nullptr;
  return &fits_[static_cast<std::size_t>(it - ids_.begin())];
}

ColourNeighbourhood colourNeighbourhood(const Frame& f, int x, int y) {
  ColourNeighbourhood out;
  const std::size_t i = f.index(x, y);
  const float* c = &f.color[i * 4];
  for (int k = 0; k < 4; ++k)
    if (!finite(c[k])) return out;
  std::array<float, 4> lo = {c[0], c[1], c[2], c[3]};
  std::array<float, 4> hi = lo;
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
      lo[k] = std::min(lo[k], n[k]);
      hi[k] = std::max(hi[k], n[k]);
    }
    return true;
  });
  out.gradient = found_same ? same : any;
  for (int k = 0; k < 4; ++k) out.range[k] = (hi[k] - lo[k]) * 255.0f;
  return out;
}

}  // namespace rc::detail
