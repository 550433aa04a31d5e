// LDR-FLIP from the formulas of Andersson et al., HPG 2020 (see flip.h): the colour
// pipeline (CSF filtering in YyCxCz, Hunt-adjusted CIELAB, HyAB distance, remapping), the
// feature pipeline (edge and point detectors on the achromatic channel), and their
// combination. Computed in double; the map is stored as float.
#include "compare/flip.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <thread>

#include <fmt/format.h>

#include "compare/colour_space.h"
#include "compare/cube_root.h"
#include "compare/pair_images.h"
#include "fixtures/errors.h"

namespace rc {
namespace {

// The paper's constants.
constexpr double kQc = 0.7;                 // exponent of the HyAB colour distance
constexpr double kPc = 0.4;                 // remapping knee, as a fraction of cmax
constexpr double kPt = 0.95;                // remapped error at the knee
constexpr double kQf = 0.5;                 // exponent of the feature difference
constexpr double kFeatureWidthDeg = 0.082;  // w: feature detector width (degrees)

// Contrast sensitivity of one opponent channel, as a spatial filter (x in degrees):
// S(x) = a1 sqrt(pi / b1) exp(-pi^2 x^2 / b1) + a2 sqrt(pi / b2) exp(-pi^2 x^2 / b2).
struct Csf {
  double a1, b1, a2, b2;
};
constexpr Csf kCsf[3] = {
    {1.0, 0.0047, 0.0, 1e-5},   // achromatic (Yy)
    {1.0, 0.0053, 0.0, 1e-5},   // red-green (Cx)
    {34.1, 0.04, 13.5, 0.025},  // blue-yellow (Cz)
};
constexpr double kCsfMaxB = 0.04;  // the largest b: sets the filter radius for all three

// The radius of the CSF filters (3 standard deviations of the widest Gaussian term) and of
// the feature detectors (3 sigma), px.
int csfRadius(double ppd) {
  return static_cast<int>(
      std::ceil(3.0 * std::sqrt(kCsfMaxB / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
}
int featureRadius(double ppd) {
  return static_cast<int>(std::ceil(3.0 * 0.5 * kFeatureWidthDeg * ppd));
}

struct Vec3 {
  double v[3];
  double operator[](int i) const { return v[i]; }
  double& operator[](int i) { return v[i]; }
};

Vec3 mul(const double m[3][3], const Vec3& x) {
  Vec3 r{};
  for (int i = 0; i < 3; ++i) r[i] = m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2];
  return r;
}

// The inverse of kRgbToXyz (Cramer's rule) and the reference white: XYZ of RGB (1, 1, 1).
struct ColorSpace {
  double xyz_to_rgb[3][3];
  Vec3 white;
  ColorSpace() {
    const auto& m = kRgbToXyz;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
        xyz_to_rgb[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
      }
    white = mul(kRgbToXyz, Vec3{{1.0, 1.0, 1.0}});
  }
};
const ColorSpace& colorSpace() {
  static const ColorSpace cs;
  return cs;
}

double srgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// srgbToLinear of the 256 8-bit values (rgba8 frames hold only these): the same numbers,
// without a pow per channel.
double srgbToLinearFast(float c) {
  static const std::vector<double> table = [] {
    std::vector<double> t(256);
    for (int i = 0; i < 256; ++i) t[i] = srgbToLinear(static_cast<float>(i) / 255.0f);
    return t;
  }();
  const float q = c * 255.0f;
  const auto k = static_cast<int>(q);
  if (static_cast<float>(k) == q && static_cast<float>(k) / 255.0f == c) return table[k];
  return srgbToLinear(c);
}

// XYZ <-> YyCxCz: CIELAB without its cube root (a linear opponent space where filtering is
// meaningful): Yy = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn).
Vec3 xyzToYcc(const Vec3& xyz, const Vec3& w) {
  const double y = xyz[1] / w[1];
  return {{116.0 * y - 16.0, 500.0 * (xyz[0] / w[0] - y), 200.0 * (y - xyz[2] / w[2])}};
}
Vec3 yccToXyz(const Vec3& ycc, const Vec3& w) {
  const double y = (ycc[0] + 16.0) / 116.0;
  return {{(ycc[1] / 500.0 + y) * w[0], y * w[1], (y - ycc[2] / 200.0) * w[2]}};
}

// CIELAB, then the Hunt adjustment of the chroma by lightness: a' = 0.01 L a, b' = 0.01 L b.
Vec3 huntLab(const Vec3& xyz, const Vec3& w) {
  constexpr double d = 6.0 / 29.0;
  auto f = [&](double t) { return t > d * d * d ? cubeRoot(t) : t / (3.0 * d * d) + 4.0 / 29.0; };
  const double fx = f(xyz[0] / w[0]);
  const double fy = f(xyz[1] / w[1]);
  const double fz = f(xyz[2] / w[2]);
  const double l = 116.0 * fy - 16.0;
  return {{l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)}};
}

// HyAB: |dL| + Euclidean distance in the (a', b') plane.
double hyab(const Vec3& p, const Vec3& q) {
  const double da = p[1] - q[1];
  const double db = p[2] - q[2];
  return std::fabs(p[0] - q[0]) + std::sqrt(da * da + db * db);
}

// ---- separable filtering, borders clamped to the edge pixel ------------------------------

// Planes and kernels in double: float filtering would save ~23 % of the instructions
// (callgrind, 256x256) but moves the error by up to ~1e-5 (float rounding of Yy ~ 100).
using Plane = std::vector<double>;
using Kernel = std::vector<double>;

Kernel toKernel(const std::vector<double>& k) { return Kernel(k.begin(), k.end()); }

void filterRows(const Plane& in, int w, int h, const Kernel& k, Plane& out) {
  const int r = static_cast<int>(k.size() / 2);
  std::vector<double> row(static_cast<std::size_t>(w + 2 * r));
  out.resize(in.size());
  for (int y = 0; y < h; ++y) {
    const double* src = &in[static_cast<std::size_t>(y) * w];
    for (int x = -r; x < w + r; ++x) row[x + r] = src[std::clamp(x, 0, w - 1)];
    double* dst = &out[static_cast<std::size_t>(y) * w];
    for (int x = 0; x < w; ++x) dst[x] = k[0] * row[x];
    for (std::size_t t = 1; t < k.size(); ++t) {
      const double kt = k[t];
      const double* s = &row[t];
      for (int x = 0; x < w; ++x) dst[x] += kt * s[x];
    }
  }
}

void filterColumns(const Plane& in, int w, int h, const Kernel& k, Plane& out) {
  const int r = static_cast<int>(k.size() / 2);
  out.resize(in.size());
  for (int y = 0; y < h; ++y) {
    double* dst = &out[static_cast<std::size_t>(y) * w];
    const double* first = &in[static_cast<std::size_t>(std::clamp(y - r, 0, h - 1)) * w];
    for (int x = 0; x < w; ++x) dst[x] = k[0] * first[x];
    for (std::size_t t = 1; t < k.size(); ++t) {
      const int sy = std::clamp(y + static_cast<int>(t) - r, 0, h - 1);
      const double kt = k[t];
      const double* s = &in[static_cast<std::size_t>(sy) * w];
      for (int x = 0; x < w; ++x) dst[x] += kt * s[x];
    }
  }
}

// The CSF filter of one channel, normalized to sum 1 over its (2r+1)^2 support, applied as
// a weighted sum of separable Gaussians (each term of S is a product in x and y).
void csfFilter(Plane& channel, int w, int h, const Csf& c, double ppd, int r) {
  const std::size_t n = 2 * static_cast<std::size_t>(r) + 1;
  Plane blurred[2];
  double weight[2] = {0.0, 0.0};
  const double a[2] = {c.a1, c.a2};
  const double b[2] = {c.b1, c.b2};
  Plane tmp;
  for (int term = 0; term < 2; ++term) {
    if (a[term] == 0.0) continue;
    std::vector<double> g(n);
    for (int i = -r; i <= r; ++i) {
      const double x = i / ppd;  // degrees
      g[i + r] = std::exp(-std::numbers::pi * std::numbers::pi * x * x / b[term]);
    }
    const double sum = std::accumulate(g.begin(), g.end(), 0.0);
    for (double& v : g) v /= sum;
    // The term's share of the 2D kernel's sum.
    weight[term] = a[term] * std::sqrt(std::numbers::pi / b[term]) * sum * sum;
    // Taps below 1e-15 of the centre change no result in double (the narrow achromatic and
    // red-green kernels need 9 of the 21): dropped, the rest kept as they are.
    std::size_t cut = 0;
    while (g[cut] < 1e-15 * g[static_cast<std::size_t>(r)]) ++cut;
    g = std::vector<double>(g.begin() + static_cast<std::ptrdiff_t>(cut),
                            g.end() - static_cast<std::ptrdiff_t>(cut));
    const Kernel kg = toKernel(g);
    filterRows(channel, w, h, kg, tmp);
    filterColumns(tmp, w, h, kg, blurred[term]);
  }
  const double total = weight[0] + weight[1];
  for (std::size_t i = 0; i < channel.size(); ++i) {
    double v = 0.0;
    for (int term = 0; term < 2; ++term)
      if (weight[term] > 0.0) v += weight[term] / total * blurred[term][i];
    channel[i] = v;
  }
}

// The feature detectors' 1D factors (x in px, sigma = 0.5 w ppd, radius ceil(3 sigma)): the
// 2D first- and second-derivative-of-Gaussian kernels are products of one of these along
// the derivative's axis and the normalized Gaussian along the other, and normalizing the
// 2D kernel's positive weights to 1 and negative ones to -1 normalizes the 1D factor so.
struct FeatureKernels {
  Kernel smooth, edge, point;
};
FeatureKernels featureKernels(double ppd) {
  const double sigma = 0.5 * kFeatureWidthDeg * ppd;
  const int r = featureRadius(ppd);
  std::vector<double> smooth, edge, point;
  for (int i = -r; i <= r; ++i) {
    const double x = i;
    const double g = std::exp(-x * x / (2.0 * sigma * sigma));
    smooth.push_back(g);
    edge.push_back(-x * g);
    point.push_back((x * x / (sigma * sigma) - 1.0) * g);
  }
  const double s = std::accumulate(smooth.begin(), smooth.end(), 0.0);
  for (double& v : smooth) v /= s;
  for (std::vector<double>* f : {&edge, &point}) {
    double pos = 0.0, neg = 0.0;
    for (double v : *f) (v > 0.0 ? pos : neg) += v;
    for (double& v : *f) v = v > 0.0 ? v / pos : v < 0.0 ? v / -neg : 0.0;
  }
  return {toKernel(smooth), toKernel(edge), toKernel(point)};
}

// |gradient| and |(Ixx, Iyy)| of the achromatic channel.
void features(const Plane& lum, int w, int h, const FeatureKernels& k, Plane& edge, Plane& point) {
  Plane sx, ex, px, a, b;
  filterRows(lum, w, h, k.smooth, sx);
  filterRows(lum, w, h, k.edge, ex);
  filterRows(lum, w, h, k.point, px);
  filterColumns(ex, w, h, k.smooth, a);
  filterColumns(sx, w, h, k.edge, b);
  edge.resize(lum.size());
  for (std::size_t i = 0; i < lum.size(); ++i) edge[i] = std::sqrt(a[i] * a[i] + b[i] * b[i]);
  filterColumns(px, w, h, k.smooth, a);
  filterColumns(sx, w, h, k.point, b);
  point.resize(lum.size());
  for (std::size_t i = 0; i < lum.size(); ++i) point[i] = std::sqrt(a[i] * a[i] + b[i] * b[i]);
}

struct Prepared {
  std::array<Plane, 3> ycc;  // filtered
  Plane lum;                 // Y / Yn, unfiltered: the feature detectors' input
};

Prepared prepare(const FlipImage& img, double ppd) {
  const ColorSpace& cs = colorSpace();
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  Prepared p;
  for (Plane& c : p.ycc) c.resize(n);
  p.lum.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 lin{};
    for (int c = 0; c < 3; ++c)
      lin[c] = srgbToLinearFast(std::clamp(img.rgb[3 * i + c], 0.0f, 1.0f));
    const Vec3 ycc = xyzToYcc(mul(kRgbToXyz, lin), cs.white);
    for (int c = 0; c < 3; ++c) p.ycc[c][i] = ycc[c];
    p.lum[i] = (ycc[0] + 16.0) / 116.0;
  }
  const int r = csfRadius(ppd);
  for (int c = 0; c < 3; ++c) csfFilter(p.ycc[c], img.width, img.height, kCsf[c], ppd, r);
  return p;
}

// Filtered YyCxCz -> linear RGB clamped to [0, 1] (filtering may leave the gamut) -> Hunt Lab.
Vec3 filteredHunt(const Prepared& p, std::size_t i) {
  const ColorSpace& cs = colorSpace();
  Vec3 rgb = mul(cs.xyz_to_rgb, yccToXyz(Vec3{{p.ycc[0][i], p.ycc[1][i], p.ycc[2][i]}}, cs.white));
  for (int c = 0; c < 3; ++c) rgb[c] = std::clamp(rgb[c], 0.0, 1.0);
  return huntLab(mul(kRgbToXyz, rgb), cs.white);
}

void checkImage(const FlipImage& img, const char* role) {
  if (img.width < 1 || img.height < 1 ||
      img.rgb.size() != 3 * static_cast<std::size_t>(img.width) * img.height)
    throw InputError(fmt::format("FLIP: the {} image's buffer does not match its size {}x{}", role,
                                 img.width, img.height));
}

// FLIP of a whole image pair.
std::vector<float> flipWhole(const FlipImage& reference, const FlipImage& test, double ppd) {
  const int w = reference.width;
  const int h = reference.height;
  // The two images are independent up to the per-pixel combination: one on another thread.
  Prepared pr;
  std::thread other([&] { pr = prepare(reference, ppd); });
  const Prepared pt = prepare(test, ppd);
  other.join();

  // cmax: the distance between green and blue, the largest in the sRGB gamut.
  const ColorSpace& cs = colorSpace();
  const double cmax = std::pow(hyab(huntLab(mul(kRgbToXyz, Vec3{{0.0, 1.0, 0.0}}), cs.white),
                                    huntLab(mul(kRgbToXyz, Vec3{{0.0, 0.0, 1.0}}), cs.white)),
                               kQc);

  const FeatureKernels k = featureKernels(ppd);
  Plane edge_r, point_r, edge_t, point_t;
  std::thread feature_thread([&] { features(pr.lum, w, h, k, edge_r, point_r); });
  features(pt.lum, w, h, k, edge_t, point_t);
  feature_thread.join();

  std::vector<float> out(static_cast<std::size_t>(w) * h);
  auto combine = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const double e = std::pow(hyab(filteredHunt(pr, i), filteredHunt(pt, i)), kQc);
      double color = e < kPc * cmax ? kPt / (kPc * cmax) * e
                                    : kPt + (e - kPc * cmax) / (cmax - kPc * cmax) * (1.0 - kPt);
      color = std::min(color, 1.0);
      static_assert(kQf == 0.5, "the feature exponent is taken as a square root");
      const double feature =
          std::sqrt(std::max(std::fabs(edge_r[i] - edge_t[i]), std::fabs(point_r[i] - point_t[i])) /
                    std::sqrt(2.0));
      out[i] = static_cast<float>(std::pow(color, 1.0 - std::min(feature, 1.0)));
    }
  };
  std::thread half([&] { combine(0, out.size() / 2); });
  combine(out.size() / 2, out.size());
  half.join();
  return out;
}

FlipImage crop(const FlipImage& img, int x0, int y0, int x1, int y1) {
  FlipImage out{x1 - x0, y1 - y0, {}};
  out.rgb.reserve(3 * static_cast<std::size_t>(out.width) * out.height);
  for (int y = y0; y < y1; ++y) {
    const auto row = img.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * img.width + x0);
    out.rgb.insert(out.rgb.end(), row, row + 3 * static_cast<std::ptrdiff_t>(x1 - x0));
  }
  return out;
}

constexpr int kTile = 64;  // px; the halo (10 px at 67 ppd) must not exceed it

}  // namespace

double FlipViewing::pixelsPerDegree() const {
  return distance_m * (monitor_width_px / monitor_width_m) * std::numbers::pi / 180.0;
}

std::vector<float> flipError(const FlipImage& reference, const FlipImage& test,
                             const FlipViewing& viewing) {
  checkImage(reference, "reference");
  checkImage(test, "test");
  if (reference.width != test.width || reference.height != test.height)
    throw InputError(fmt::format("FLIP: images differ in size ({}x{} and {}x{})", reference.width,
                                 reference.height, test.width, test.height));
  const int w = reference.width;
  const int h = reference.height;
  const double ppd = viewing.pixelsPerDegree();
  // A pixel whose neighbourhood (every filter's radius, the halo) is the same in both
  // images gets exactly 0: equal filtered colours and features. So only the pixels within
  // the halo of a differing pixel are computed, tile by tile, each from its rectangle plus
  // the halo: the same sums over the same values as the whole image, bit for bit (the
  // clamped borders of a cut rectangle reach none of the pixels kept from it).
  const int halo = std::max(csfRadius(ppd), featureRadius(ppd));
  if (halo > kTile) return flipWhole(reference, test, ppd);
  const int tiles_x = (w + kTile - 1) / kTile;
  const int tiles_y = (h + kTile - 1) / kTile;
  struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // half-open; empty when x0 >= x1
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    void add(const Rect& o) {
      if (o.empty()) return;
      if (empty()) {
        *this = o;
        return;
      }
      x0 = std::min(x0, o.x0), y0 = std::min(y0, o.y0);
      x1 = std::max(x1, o.x1), y1 = std::max(y1, o.y1);
    }
    Rect intersect(const Rect& o) const {
      return {std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
    }
  };
  std::vector<Rect> differ(static_cast<std::size_t>(tiles_x) * tiles_y);  // bounding boxes
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * w + x);
      if (reference.rgb[i] != test.rgb[i] || reference.rgb[i + 1] != test.rgb[i + 1] ||
          reference.rgb[i + 2] != test.rgb[i + 2])
        differ[static_cast<std::size_t>(y / kTile) * tiles_x + x / kTile].add({x, y, x + 1, y + 1});
    }
  // Per tile, the part within the halo of a difference (differences within the halo of a
  // tile lie in it or its 8 neighbours: halo <= tile), and the pixels it costs with halo.
  std::vector<Rect> out_rect(differ.size());
  double cost = 0.0;
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      const Rect tile{tx * kTile, ty * kTile, std::min(w, (tx + 1) * kTile),
                      std::min(h, (ty + 1) * kTile)};
      Rect r;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = tx + dx, ny = ty + dy;
          if (nx < 0 || ny < 0 || nx >= tiles_x || ny >= tiles_y) continue;
          const Rect& d = differ[static_cast<std::size_t>(ny) * tiles_x + nx];
          if (d.empty()) continue;
          r.add(Rect{d.x0 - halo, d.y0 - halo, d.x1 + halo, d.y1 + halo}.intersect(tile));
        }
      out_rect[static_cast<std::size_t>(ty) * tiles_x + tx] = r;
      if (!r.empty())
        cost += static_cast<double>(std::min(w, r.x1 + halo) - std::max(0, r.x0 - halo)) *
                (std::min(h, r.y1 + halo) - std::max(0, r.y0 - halo));
    }
  std::vector<float> out(static_cast<std::size_t>(w) * h, 0.0f);
  if (cost == 0.0) return out;
  if (cost >= 0.9 * w * h) return flipWhole(reference, test, ppd);
  for (const Rect& r : out_rect) {
    if (r.empty()) continue;
    const int rx0 = std::max(0, r.x0 - halo), ry0 = std::max(0, r.y0 - halo);
    const int rx1 = std::min(w, r.x1 + halo), ry1 = std::min(h, r.y1 + halo);
    const std::vector<float> part =
        flipWhole(crop(reference, rx0, ry0, rx1, ry1), crop(test, rx0, ry0, rx1, ry1), ppd);
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x)
        out[static_cast<std::size_t>(y) * w + x] =
            part[static_cast<std::size_t>(y - ry0) * (rx1 - rx0) + (x - rx0)];
  }
  return out;
}

FlipImage flipImageOf(const Frame& frame) {
  FlipImage img;
  img.width = frame.width;
  img.height = frame.height;
  const std::size_t n = frame.pixelCount();
  img.rgb.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      // color.png's byte (DESIGN.md): clamp to [0, 1] (NaN as 0), round to nearest, halves up.
      float v = frame.color[4 * i + c];
      v = v > 0.0f ? v : 0.0f;
      v = v < 1.0f ? v : 1.0f;
      const float x = v * 255.0f;
      const auto q = static_cast<int>(x);
      img.rgb[3 * i + c] =
          static_cast<float>(q + (x - static_cast<float>(q) >= 0.5f ? 1 : 0)) / 255.0f;
    }
  return img;
}

FlipStats poolFlip(const std::vector<float>& error) {
  FlipStats s;
  if (error.empty()) return s;
  std::vector<float> sorted(error);
  std::sort(sorted.begin(), sorted.end());
  double total = 0.0;
  for (float v : sorted) total += v;
  s.mean = total / static_cast<double>(sorted.size());
  s.min = sorted.front();
  s.max = sorted.back();
  if (total <= 0.0) return s;
  const double fractions[3] = {0.25, 0.5, 0.75};
  double* targets[3] = {&s.weighted_q1, &s.weighted_median, &s.weighted_q3};
  double cum = 0.0;
  int next = 0;
  for (float v : sorted) {
    cum += v;
    while (next < 3 && cum >= fractions[next] * total) *targets[next++] = v;
    if (next == 3) break;
  }
  while (next < 3) *targets[next++] = s.max;  // rounding of the running sum
  return s;
}

FlipStats flipFrames(const Frame& expected, const Frame& actual, const Tolerances& tolerances,
                     std::vector<float>* map) {
  const FlipViewing viewing;
  std::vector<float> error = flipError(flipImageOf(expected), flipImageOf(actual), viewing);
  FlipStats s = poolFlip(error);
  s.ppd = viewing.pixelsPerDegree();
  s.threshold = tolerances.flip_mean_fail;
  if (s.threshold && s.mean > *s.threshold) s.status = Status::Fail;
  if (map) *map = std::move(error);
  return s;
}

std::vector<std::uint8_t> flipHeatRgb(const std::vector<float>& error) {
  static const std::vector<Rgb8> lut = colorStops(256, kFlipColorMap);
  std::vector<std::uint8_t> out(3 * error.size());
  for (std::size_t i = 0; i < error.size(); ++i) {
    const float e = std::isnan(error[i]) ? 1.0f : std::clamp(error[i], 0.0f, 1.0f);
    const auto k = static_cast<std::size_t>(std::lround(e * 255.0f));
    for (int c = 0; c < 3; ++c) out[3 * i + c] = lut[k][c];
  }
  return out;
}

nlohmann::json flipJson(const FlipStats& s) {
  return {{"status", toString(s.status)},
          {"mean", s.mean},
          {"weighted_median", s.weighted_median},
          {"weighted_q1", s.weighted_q1},
          {"weighted_q3", s.weighted_q3},
          {"min", s.min},
          {"max", s.max},
          {"threshold", s.threshold ? nlohmann::json(*s.threshold) : nlohmann::json(nullptr)},
          {"pixels_per_degree", s.ppd}};
}

}  // namespace rc
