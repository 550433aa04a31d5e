// Synthetic reference-like frames: see synthetic_frames.h.
#include "synthetic_frames.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rc::testing {
namespace {

struct Vec {
  double x, y;
};

double segmentDistance(Vec p, Vec a, Vec b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

}  // namespace

float quantizeD24(double z) {
  const double steps = 16777215.0;
  return static_cast<float>(std::nearbyint(std::clamp(z, 0.0, 1.0) * steps) / steps);
}

Frame renderRects(int width, int height, const std::vector<Rect>& rects) {
  Frame f;
  const float clear[4] = {0.f, 0.f, 0.f, 0.f};
  f.allocate(width, height, clear, 1.0f, true);
  f.meta = {{"backend", "ref"}, {"fixture", "synthetic/rects"}, {"subpixel_bits", 8}};
  f.drawn.depth_format = DepthFormat::D24;
  f.drawn.color_format = ColorFormat::RGBA32F;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Vec p{x + 0.5, y + 0.5};
      const std::size_t i = f.index(x, y);
      double best = std::numeric_limits<double>::infinity();
      double second = std::numeric_limits<double>::infinity();
      double best_slope = 0.0;  // steps/px of the winner and of the steepest other
      double other_slope = 0.0;
      double edge = 1.0;
      for (const Rect& r : rects) {
        const std::array<Vec, 4> c = {Vec{r.x0, r.y0}, Vec{r.x1, r.y0}, Vec{r.x1, r.y1},
                                      Vec{r.x0, r.y1}};
        // Edges of both triangles of any rectangle whose bounding box, grown by one
        // pixel, touches this pixel.
        if (p.x >= r.x0 - 1.5 && p.x <= r.x1 + 1.5 && p.y >= r.y0 - 1.5 && p.y <= r.y1 + 1.5) {
          for (int k = 0; k < 4; ++k)
            edge = std::min(edge, segmentDistance(p, c[k], c[(k + 1) % 4]));
          edge = std::min(edge, segmentDistance(p, c[0], c[2]));
        }
        if (p.x < r.x0 || p.x >= r.x1 || p.y < r.y0 || p.y >= r.y1) continue;
        const double z = r.z0 + r.dzdx * (p.x - r.x0) + r.dzdy * (p.y - r.y0);
        const double zs = std::nearbyint(z * 16777215.0);
        const double slope = std::hypot(r.dzdx, r.dzdy) * 16777215.0;
        if (zs < best) {
          second = best;
          best = zs;
          if (std::isfinite(second)) other_slope = std::max(other_slope, best_slope);
          best_slope = slope;
        } else {
          second = std::min(second, zs);
          other_slope = std::max(other_slope, slope);
          continue;
        }
        const double cross = (r.x1 - r.x0) * (p.y - r.y0) - (r.y1 - r.y0) * (p.x - r.x0);
        f.id[i] = cross < 0 ? r.first_id : r.first_id + 1;
        f.depth[i] = quantizeD24(z);
        const float shift = r.color_dx * static_cast<float>(p.x - r.x0);
        f.color[i * 4 + 0] = r.rgba[0] + shift;
        f.color[i * 4 + 1] = r.rgba[1] - 0.5f * shift;
        f.color[i * 4 + 2] = r.rgba[2] + (cross < 0 ? 0.05f : 0.0f);
        f.color[i * 4 + 3] = r.rgba[3];
      }
      f.edge_dist[i] = static_cast<float>(edge);
      f.depth_gap[i] = static_cast<float>(second - best);  // +inf when one fragment
      f.depth_slope[i] = static_cast<float>(best_slope);
      // The steeper of the two fragments of any comparison (an upper bound of the
      // reference's, which keeps only the comparisons that decided the id).
      if (std::isfinite(second))
        f.gap_slope[i] = static_cast<float>(std::max(best_slope, other_slope));
    }
  }
  return f;
}

std::vector<Rect> defaultRects(int width, int height) {
  const double w = width, h = height;
  Rect back;
  back.x0 = 0.05 * w;
  back.y0 = 0.08 * h;
  back.x1 = 0.60 * w;
  back.y1 = 0.70 * h;
  back.z0 = 0.7;
  back.dzdx = 20.0 / 16777215.0 * 256.0 / w;  // a gentle slope: 20 steps/px at 256 px
  back.dzdy = 10.0 / 16777215.0 * 256.0 / w;
  back.rgba[0] = 0.8f;
  back.rgba[1] = 0.3f;
  back.rgba[2] = 0.2f;
  back.color_dx = 0.4f / static_cast<float>(w);
  back.first_id = 1;

  Rect front;
  front.x0 = 0.40 * w;
  front.y0 = 0.35 * h;
  front.x1 = 0.92 * w;
  front.y1 = 0.93 * h;
  front.z0 = 0.4;
  front.dzdx = -5.0 / 16777215.0;
  front.rgba[0] = 0.2f;
  front.rgba[1] = 0.6f;
  front.rgba[2] = 0.9f;
  front.color_dx = 0.2f / static_cast<float>(w);
  front.first_id = 3;

  Rect steep;  // seen nearly edge-on: depth changes fast across x
  steep.x0 = 0.65 * w;
  steep.y0 = 0.05 * h;
  steep.x1 = 0.95 * w;
  steep.y1 = 0.30 * h;
  steep.z0 = 0.2;
  steep.dzdx = 0.5 / (0.30 * w);  // 0.5 of the depth range across its width
  steep.rgba[0] = 0.9f;
  steep.rgba[1] = 0.9f;
  steep.rgba[2] = 0.1f;
  steep.first_id = 5;
  return {back, front, steep};
}

}  // namespace rc::testing
