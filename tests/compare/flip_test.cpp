// LDR-FLIP (compare/flip.h) against answers computed here independently from the paper's
// formulas (Andersson et al., HPG 2020): constant image pairs in closed form through the
// colour pipeline, and a direct (non-separable) 2D implementation on small images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "compare/compare.h"
#include "compare/flip.h"

namespace rc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- the colour pipeline, restated ------------------------------------------------------

double linearize(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// sRGB-encoded RGB -> CIE XYZ (D65), normalized by the white's XYZ.
void toXyzN(const double rgb[3], double xyzn[3]) {
  const double m[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                          {0.2126729, 0.7151522, 0.0721750},
                          {0.0193339, 0.1191920, 0.9503041}};
  double lin[3];
  for (int c = 0; c < 3; ++c) lin[c] = linearize(rgb[c]);
  for (int r = 0; r < 3; ++r) {
    const double white = m[r][0] + m[r][1] + m[r][2];
    xyzn[r] = (m[r][0] * lin[0] + m[r][1] * lin[1] + m[r][2] * lin[2]) / white;
  }
}

// Hunt-adjusted CIELAB of normalized XYZ.
void hunt(const double xyzn[3], double out[3]) {
  auto f = [](double t) {
    const double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
  };
  const double l = 116 * f(xyzn[1]) - 16;
  out[0] = l;
  out[1] = 0.01 * l * 500 * (f(xyzn[0]) - f(xyzn[1]));
  out[2] = 0.01 * l * 200 * (f(xyzn[1]) - f(xyzn[2]));
}

double hyabOf(const double p[3], const double q[3]) {
  return std::fabs(p[0] - q[0]) +
         std::sqrt((p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

// FLIP of two constant images: the filters keep a constant, the feature detectors answer
// 0, so the error is the remapped colour distance alone.
double constantPairFlip(const double a[3], const double b[3]) {
  double xa[3], xb[3], ha[3], hb[3];
  toXyzN(a, xa);
  toXyzN(b, xb);
  hunt(xa, ha);
  hunt(xb, hb);
  const double green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
  double xg[3], xbl[3], hg[3], hbl[3];
  toXyzN(green, xg);
  toXyzN(blue, xbl);
  hunt(xg, hg);
  hunt(xbl, hbl);
  const double cmax = std::pow(hyabOf(hg, hbl), 0.7);
  const double e = std::pow(hyabOf(ha, hb), 0.7);
  if (e < 0.4 * cmax) return 0.95 / (0.4 * cmax) * e;
  return 0.95 + (e - 0.4 * cmax) / (0.6 * cmax) * 0.05;
}

FlipImage constantImage(int w, int h, const double rgb[3]) {
  FlipImage img{w, h, {}};
  for (int i = 0; i < w * h; ++i)
    for (int c = 0; c < 3; ++c) img.rgb.push_back(static_cast<float>(rgb[c]));
  return img;
}

FlipImage randomImage(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  FlipImage img{w, h, {}};
  for (int i = 0; i < 3 * w * h; ++i) img.rgb.push_back(u(rng));
  return img;
}

TEST(Flip, IdenticalImagesScoreZero) {
  const FlipImage a = randomImage(40, 30, 1);
  const std::vector<float> e = flipError(a, a);
  ASSERT_EQ(e.size(), 40u * 30u);
  for (float v : e) EXPECT_EQ(v, 0.0f);
  const FlipStats s = poolFlip(e);
  EXPECT_EQ(s.mean, 0.0);
  EXPECT_EQ(s.max, 0.0);
  EXPECT_EQ(s.weighted_median, 0.0);
}

TEST(Flip, ViewingConditionsGive67PixelsPerDegree) {
  // 0.7 m * 3840 px / 0.7 m * pi / 180.
  EXPECT_NEAR(FlipViewing{}.pixelsPerDegree(), 67.0206432766, 1e-9);
}

TEST(Flip, ConstantPairsEqualTheRemappedColourDistance) {
  const double colours[][3] = {
      {0, 0, 0},       {1, 1, 1},        {1, 0, 0},       {0, 1, 0},       {0, 0, 1},
      {0.5, 0.5, 0.5}, {0.51, 0.5, 0.5}, {0.2, 0.7, 0.4}, {0.9, 0.8, 0.1}, {0.02, 0.03, 0.01}};
  for (const auto& a : colours)
    for (const auto& b : colours) {
      const std::vector<float> e = flipError(constantImage(24, 20, a), constantImage(24, 20, b));
      const double want = constantPairFlip(a, b);
      for (float v : e)
        ASSERT_NEAR(v, want, 2e-6)
            << a[0] << "," << a[1] << "," << a[2] << " vs " << b[0] << "," << b[1] << "," << b[2];
    }
  // By hand: white vs black is HyAB 100 (|dL| = 100, no chroma), 100^0.7 = 25.119 above
  // the knee 0.4 cmax = 16.51 (HyAB(green, blue) = 203.297, ^0.7 = 41.275): 0.95 +
  // (25.119 - 16.510) / (0.6 * 41.275) * 0.05 = 0.96738; green vs blue is the maximum, 1.
  const double w[3] = {1, 1, 1}, k[3] = {0, 0, 0}, g[3] = {0, 1, 0}, bl[3] = {0, 0, 1};
  EXPECT_NEAR(flipError(constantImage(8, 8, w), constantImage(8, 8, k))[0], 0.96738, 1e-5);
  EXPECT_NEAR(flipError(constantImage(8, 8, g), constantImage(8, 8, bl))[0], 1.0, 1e-6);
}

// ---- the whole metric, directly in 2D ----------------------------------------------------

struct Planes {
  int w, h;
  std::vector<double> c[3];
};

double at(const std::vector<double>& p, int w, int h, int x, int y) {
  return p[static_cast<std::size_t>(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)];
}

std::vector<double> convolve2d(const std::vector<double>& p, int w, int h,
                               const std::vector<double>& k, int r) {
  std::vector<double> out(p.size(), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0;
      for (int j = -r; j <= r; ++j)
        for (int i = -r; i <= r; ++i)
          s += k[(j + r) * (2 * r + 1) + (i + r)] * at(p, w, h, x + i, y + j);
      out[static_cast<std::size_t>(y) * w + x] = s;
    }
  return out;
}

std::vector<double> directFlip(const FlipImage& ref, const FlipImage& test) {
  const double ppd = 0.7 * 3840 / 0.7 * kPi / 180;
  const int w = ref.width, h = ref.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  // YyCxCz planes and the luminance Y/Yn of both images.
  auto ycc = [&](const FlipImage& img, std::vector<double> out[3], std::vector<double>& lum) {
    for (int c = 0; c < 3; ++c) out[c].resize(n);
    lum.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double rgb[3] = {img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]};
      double x[3];
      toXyzN(rgb, x);
      out[0][i] = 116 * x[1] - 16;
      out[1][i] = 500 * (x[0] - x[1]);
      out[2][i] = 200 * (x[1] - x[2]);
      lum[i] = x[1];
    }
  };
  std::vector<double> yr[3], yt[3], lr, lt;
  ycc(ref, yr, lr);
  ycc(test, yt, lt);
  // CSF kernels on the (2r+1)^2 grid, each normalized to sum 1.
  const double params[3][4] = {
      {1, 0.0047, 0, 1e-5}, {1, 0.0053, 0, 1e-5}, {34.1, 0.04, 13.5, 0.025}};
  const int r = static_cast<int>(std::ceil(3 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
  for (int c = 0; c < 3; ++c) {
    std::vector<double> k;
    double sum = 0;
    for (int j = -r; j <= r; ++j)
      for (int i = -r; i <= r; ++i) {
        const double d2 = (i * i + j * j) / (ppd * ppd);
        const double* p = params[c];
        const double v = p[0] * std::sqrt(kPi / p[1]) * std::exp(-kPi * kPi * d2 / p[1]) +
                         p[2] * std::sqrt(kPi / p[3]) * std::exp(-kPi * kPi * d2 / p[3]);
        k.push_back(v);
        sum += v;
      }
    for (double& v : k) v /= sum;
    yr[c] = convolve2d(yr[c], w, h, k, r);
    yt[c] = convolve2d(yt[c], w, h, k, r);
  }
  // Back to clamped linear RGB, then Hunt Lab.
  const double m[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                          {0.2126729, 0.7151522, 0.0721750},
                          {0.0193339, 0.1191920, 0.9503041}};
  double white[3];
  for (int i = 0; i < 3; ++i) white[i] = m[i][0] + m[i][1] + m[i][2];
  auto huntAt = [&](std::vector<double> y[3], std::size_t i, double out[3]) {
    const double yn = (y[0][i] + 16) / 116;
    const double xyz[3] = {(y[1][i] / 500 + yn) * white[0], yn * white[1],
                           (yn - y[2][i] / 200) * white[2]};
    // Solve m * rgb = xyz by Gaussian elimination (no shared inverse).
    double a[3][4];
    for (int r0 = 0; r0 < 3; ++r0) {
      for (int c = 0; c < 3; ++c) a[r0][c] = m[r0][c];
      a[r0][3] = xyz[r0];
    }
    for (int p = 0; p < 3; ++p)
      for (int r1 = 0; r1 < 3; ++r1) {
        if (r1 == p) continue;
        const double f = a[r1][p] / a[p][p];
        for (int c = p; c < 4; ++c) a[r1][c] -= f * a[p][c];
      }
    double rgb[3], xyzn[3];
    for (int c = 0; c < 3; ++c) rgb[c] = std::clamp(a[c][3] / a[c][c], 0.0, 1.0);
    for (int r1 = 0; r1 < 3; ++r1)
      xyzn[r1] = (m[r1][0] * rgb[0] + m[r1][1] * rgb[1] + m[r1][2] * rgb[2]) / white[r1];
    hunt(xyzn, out);
  };
  // Feature kernels: 2D derivatives of a Gaussian, positive weights summing to 1 and
  // negative ones to -1.
  const double sigma = 0.5 * 0.082 * ppd;
  const int fr = static_cast<int>(std::ceil(3 * sigma));
  auto kernel = [&](int kind, bool along_x) {
    std::vector<double> k;
    for (int j = -fr; j <= fr; ++j)
      for (int i = -fr; i <= fr; ++i) {
        const double d = along_x ? i : j;
        const double g = std::exp(-(i * i + j * j) / (2 * sigma * sigma));
        k.push_back(kind == 0 ? -d * g : (d * d / (sigma * sigma) - 1) * g);
      }
    double pos = 0, neg = 0;
    for (double v : k) (v > 0 ? pos : neg) += v;
    for (double& v : k) v = v > 0 ? v / pos : v < 0 ? v / -neg : 0.0;
    return k;
  };
  auto magnitude = [&](const std::vector<double>& lum, int kind) {
    const std::vector<double> gx = convolve2d(lum, w, h, kernel(kind, true), fr);
    const std::vector<double> gy = convolve2d(lum, w, h, kernel(kind, false), fr);
    std::vector<double> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = std::sqrt(gx[i] * gx[i] + gy[i] * gy[i]);
    return out;
  };
  const std::vector<double> er = magnitude(lr, 0), et = magnitude(lt, 0);
  const std::vector<double> pr = magnitude(lr, 1), pt = magnitude(lt, 1);
  const double gr[3] = {0, 1, 0}, bl[3] = {0, 0, 1};
  double xg[3], xb[3], hg[3], hb[3];
  toXyzN(gr, xg);
  toXyzN(bl, xb);
  hunt(xg, hg);
  hunt(xb, hb);
  const double cmax = std::pow(hyabOf(hg, hb), 0.7);
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    double a[3], b[3];
    huntAt(yr, i, a);
    huntAt(yt, i, b);
    const double e = std::pow(hyabOf(a, b), 0.7);
    const double dc =
        e < 0.4 * cmax ? 0.95 / (0.4 * cmax) * e : 0.95 + (e - 0.4 * cmax) / (0.6 * cmax) * 0.05;
    const double df = std::pow(
        std::max(std::fabs(er[i] - et[i]), std::fabs(pr[i] - pt[i])) / std::sqrt(2.0), 0.5);
    out[i] = std::pow(dc, 1 - df);
  }
  return out;
}

TEST(Flip, MatchesADirect2DImplementation) {
  // Random noise against a blurred, shifted copy with an edge: colour and feature terms.
  const int w = 26, h = 21;
  const FlipImage a = randomImage(w, h, 7);
  FlipImage b = a;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        float& v = b.rgb[3 * (static_cast<std::size_t>(y) * w + x) + c];
        v = x < 12 ? 0.5f * v + 0.25f : (c == 1 ? 0.9f : 0.1f);
      }
  const std::vector<float> got = flipError(a, b);
  const std::vector<double> want = directFlip(a, b);
  ASSERT_EQ(got.size(), want.size());
  double max_diff = 0;
  for (std::size_t i = 0; i < got.size(); ++i)
    max_diff = std::max(max_diff, std::fabs(got[i] - want[i]));
  EXPECT_LT(max_diff, 1e-5);
  EXPECT_GT(*std::max_element(got.begin(), got.end()), 0.3f);
}

// Differences in one corner: only the tiles near them are computed (compare/flip.cpp);
// the answer is still the whole metric's, and exactly 0 beyond the filters' reach.
TEST(Flip, SparseDifferencesGiveTheWholeImageAnswer) {
  const int w = 160, h = 140;
  const FlipImage a = randomImage(w, h, 3);
  FlipImage b = a;
  for (int y = 5; y < 20; ++y)
    for (int x = 8; x < 22; ++x) b.rgb[3 * (static_cast<std::size_t>(y) * w + x) + 2] = 1.0f;
  const std::vector<float> got = flipError(a, b);
  const std::vector<double> want = directFlip(a, b);
  double max_diff = 0;
  for (std::size_t i = 0; i < got.size(); ++i)
    max_diff = std::max(max_diff, std::fabs(got[i] - want[i]));
  EXPECT_LT(max_diff, 1e-5);
  // Beyond 10 px (the CSF radius at 67 ppd) of the changed block, nothing.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (x >= 22 + 10 || y >= 20 + 10) {
        ASSERT_EQ(got[static_cast<std::size_t>(y) * w + x], 0.0f) << x << "," << y;
        ASSERT_EQ(want[static_cast<std::size_t>(y) * w + x], 0.0) << x << "," << y;
      }
  EXPECT_GT(got[static_cast<std::size_t>(10) * w + 12], 0.1f);
}

TEST(Flip, PoolingIsValueWeighted) {
  const FlipStats a = poolFlip({0.1f, 0.2f, 0.3f, 0.4f});
  EXPECT_NEAR(a.mean, 0.25, 1e-7);
  EXPECT_FLOAT_EQ(a.weighted_q1, 0.2f);      // cumulative 0.1, 0.3 >= 0.25
  EXPECT_FLOAT_EQ(a.weighted_median, 0.3f);  // 0.6 >= 0.5
  EXPECT_FLOAT_EQ(a.weighted_q3, 0.4f);      // 1.0 >= 0.75
  EXPECT_FLOAT_EQ(a.max, 0.4f);
  const FlipStats b = poolFlip({0, 0, 0, 0.2f, 0.8f});
  EXPECT_FLOAT_EQ(b.weighted_median, 0.8f);  // many zero pixels do not hide the large error
  EXPECT_FLOAT_EQ(b.weighted_q1, 0.8f);      // 0.2 < 0.25 of the total 1.0
}

TEST(Flip, ThresholdFailsAPairWhoseMeanExceedsIt) {
  Frame e, a;
  const float clear[4] = {0.2f, 0.2f, 0.2f, 1.0f};
  e.allocate(16, 16, clear, 1.0f, false);
  a.allocate(16, 16, clear, 1.0f, false);
  for (std::size_t i = 0; i < 16; ++i) a.color[4 * i] = 0.9f;  // one row redder
  Tolerances t;
  FlipStats s = flipFrames(e, a, t);
  EXPECT_EQ(s.status, Status::Pass);
  EXPECT_GT(s.mean, 0.0);
  t.flip_mean_fail = s.mean;  // equal passes
  EXPECT_EQ(flipFrames(e, a, t).status, Status::Pass);
  t.flip_mean_fail = s.mean * 0.99;
  EXPECT_EQ(flipFrames(e, a, t).status, Status::Fail);
  // Frame colours are read as color.png shows them: clamped to [0, 1], NaN as 0, rounded
  // to 8 bits (halves up).
  a.color[0] = 7.0f;
  a.color[1] = std::nanf("");
  a.color[2] = 100.5f / 255.0f;
  a.color[4] = 0.30f;
  const FlipImage img = flipImageOf(a);
  EXPECT_EQ(img.rgb[0], 1.0f);
  EXPECT_EQ(img.rgb[1], 0.0f);
  EXPECT_EQ(img.rgb[2], 101.0f / 255.0f);
  EXPECT_EQ(img.rgb[3], std::round(0.30f * 255.0f) / 255.0f);
}

// FLIP is opt-in (`--flip`: on a 1080p pair it costs more than the rest of the comparison,
// docs/performance.md): compareFrames computes it only when
// the maps ask for it or a threshold is set; CIEDE2000 comes with every comparison.
TEST(Flip, OnlyComputedWhenAskedFor) {
  Frame e, a;
  const float clear[4] = {0.2f, 0.2f, 0.2f, 1.0f};
  e.allocate(16, 16, clear, 1.0f, false);
  a.allocate(16, 16, clear, 1.0f, false);
  for (std::size_t i = 0; i < 16; ++i) a.color[4 * i] = 0.9f;
  Tolerances t;
  ClassMaps maps;
  maps.flip.assign(3, 0.5f);  // a stale map from an earlier pair
  PairResult r = compareFrames(e, a, e, t, &maps);
  EXPECT_FALSE(r.flip.has_value());
  EXPECT_TRUE(maps.flip.empty());
  ASSERT_TRUE(r.ciede2000.has_value());
  EXPECT_EQ(r.ciede2000->differing, 16u);
  maps.want_flip = true;
  r = compareFrames(e, a, e, t, &maps);
  ASSERT_TRUE(r.flip.has_value());
  EXPECT_GT(r.flip->mean, 0.0);
  EXPECT_EQ(maps.flip.size(), 256u);
  t.flip_mean_fail = 1.0;  // a threshold alone asks for it too
  r = compareFrames(e, a, e, t);
  ASSERT_TRUE(r.flip.has_value());
  EXPECT_EQ(r.flip->threshold, 1.0);
}

}  // namespace
}  // namespace rc
