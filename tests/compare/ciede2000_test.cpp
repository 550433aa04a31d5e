// CIEDE2000 (compare/ciede2000.h) against published values: the 34 colour pairs of Sharma,
// Wu and Dalal (2005), Table 1, with their differences to four decimals, and the CIELAB of
// the sRGB primaries (Lindbloom's calculator, D65); the pooled frame statistics against
// hand-computed lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "compare/ciede2000.h"

namespace rc {
namespace {

struct PublishedPair {
  Lab x;
  Lab y;
  double delta_e;  // as printed: four decimals
};

// G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation
// notes, supplementary test data, and mathematical observations", Color Research and
// Application 30(1), 21-30, 2005, Table 1 (also ciede2000testdata.txt on the authors'
// page). Pairs 7-16 probe the hue discontinuities (mean hue and hue difference across 0
// and 180 degrees), 17-24 the chroma weighting near neutral, 25-34 are from the CIE's
// original publication.
const std::vector<PublishedPair>& sharmaTable1() {
  static const std::vector<PublishedPair> table = {
      {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
      {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
      {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
      {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
      {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
      {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
      {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
      {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
      {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
      {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
      {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
      {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
      {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
      {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
      {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
      {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
      {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
      {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
      {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
      {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
      {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
      {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
      {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
      {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
      {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
      {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
      {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
      {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
      {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
      {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
      {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
      {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
      {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
      {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
  };
  return table;
}

// The values are printed to four decimals, so a correct double implementation is within
// half a unit of the last one (5e-5); a few ulps more for the arithmetic.
constexpr double kPrintedHalfUnit = 5e-5 + 1e-12;

TEST(Ciede2000, MatchesSharmaWuDalalTable1) {
  const auto& table = sharmaTable1();
  ASSERT_EQ(table.size(), 34u);
  double worst = 0.0;
  for (std::size_t k = 0; k < table.size(); ++k) {
    const PublishedPair& p = table[k];
    const double d = ciede2000(p.x, p.y);
    EXPECT_NEAR(d, p.delta_e, kPrintedHalfUnit) << "pair " << k + 1;
    // The formula is symmetric (the paper's pairs 7 and 8 are one pair both ways round).
    EXPECT_NEAR(ciede2000(p.y, p.x), d, 1e-12) << "pair " << k + 1 << " reversed";
    worst = std::max(worst, std::fabs(d - p.delta_e));
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.3e", worst);
  RecordProperty("worst_abs_error", text);  // docs/tolerances.md section 7 quotes it
}

TEST(Ciede2000, EqualColoursAreZero) {
  for (const PublishedPair& p : sharmaTable1()) {
    EXPECT_EQ(ciede2000(p.x, p.x), 0.0);
    EXPECT_EQ(ciede2000(p.y, p.y), 0.0);
  }
}

// The hue-difference discontinuity (Sharma et al., pairs 9-12): a 1e-4 change of b across
// the point where the hues are exactly half a turn apart changes the difference by 0.04,
// and a lightness step alone is the lightness term (pairs 4-6 show the unit ellipse).
TEST(Ciede2000, HueDiscontinuityIsWhereThePaperPutsIt) {
  const double below = ciede2000({50, 2.49, -0.001}, {50, -2.49, 0.0010});
  const double above = ciede2000({50, 2.49, -0.001}, {50, -2.49, 0.0011});
  EXPECT_GT(above - below, 0.03);
  // Lightness only, mean lightness 50 (S_L = 1): the difference is |dL|; at mean 50.5,
  // S_L = 1 + 0.015 * 0.25 / sqrt(20.25) shrinks it.
  EXPECT_NEAR(ciede2000({49.5, 0, 0}, {50.5, 0, 0}), 1.0, 1e-12);
  EXPECT_NEAR(ciede2000({50, 0, 0}, {51, 0, 0}), 1.0 / (1.0 + 0.015 * 0.25 / 4.5), 1e-12);
}

// sRGB primaries in CIELAB under D65 (Bruce Lindbloom's colour calculator, reproduced in
// many colour libraries' tests), to the printed four decimals.
TEST(Ciede2000, SrgbToLabMatchesPublishedPrimaries) {
  struct Case {
    double r, g, b;
    Lab lab;
  };
  const Case cases[] = {
      {1, 0, 0, {53.2408, 80.0925, 67.2032}},
      {0, 1, 0, {87.7347, -86.1827, 83.1793}},
      {0, 0, 1, {32.2970, 79.1875, -107.8602}},
      {1, 1, 1, {100.0, 0.0, 0.0}},
      {0, 0, 0, {0.0, 0.0, 0.0}},
      {128 / 255.0, 128 / 255.0, 128 / 255.0, {53.5850, 0, 0}},
  };
  for (const Case& c : cases) {
    const Lab got = srgbToLab(c.r, c.g, c.b);
    EXPECT_NEAR(got.l, c.lab.l, 1e-4) << c.r << " " << c.g << " " << c.b;
    EXPECT_NEAR(got.a, c.lab.a, 1e-4) << c.r << " " << c.g << " " << c.b;
    EXPECT_NEAR(got.b, c.lab.b, 1e-4) << c.r << " " << c.g << " " << c.b;
  }
}

Frame flatFrame(int w, int h, float r, float g, float b) {
  Frame f;
  const float clear[4] = {r, g, b, 1.0f};
  f.allocate(w, h, clear, 1.0f, false);
  return f;
}

TEST(Ciede2000, FramesPoolEveryPixel) {
  // 4 x 1: two equal pixels, then red against white, then one blue 8-bit step.
  Frame e = flatFrame(4, 1, 0.5f, 0.5f, 0.5f);
  Frame a = flatFrame(4, 1, 0.5f, 0.5f, 0.5f);
  for (int c = 0; c < 3; ++c) e.color[8 + c] = 1.0f;
  a.color[8] = 1.0f;
  a.color[9] = a.color[10] = 0.0f;
  a.color[14] = 129.0f / 255.0f;
  const double red_white = ciede2000(srgbToLab(1, 1, 1), srgbToLab(1, 0, 0));
  const double grey = 128 / 255.0;  // 0.5 is stored as 128 in color.png
  const double blue_step =
      ciede2000(srgbToLab(grey, grey, grey), srgbToLab(grey, grey, 129 / 255.0));
  ASSERT_GT(red_white, blue_step);
  const DeltaE2000Stats s = deltaE2000Frames(e, a);
  EXPECT_EQ(s.differing, 2u);
  EXPECT_NEAR(s.mean, (red_white + blue_step) / 4.0, 1e-12);
  EXPECT_EQ(s.min, 0.0);
  EXPECT_NEAR(s.max, red_white, 1e-12);
  EXPECT_EQ(s.worst_x, 2);
  EXPECT_EQ(s.worst_y, 0);
  // Value-weighted: the larger difference holds more than three quarters of the sum.
  EXPECT_NEAR(s.weighted_median, red_white, 1e-12);
  EXPECT_NEAR(s.weighted_q3, red_white, 1e-12);
  EXPECT_NEAR(s.weighted_q1, red_white > 3 * blue_step ? red_white : blue_step, 1e-12);
  const nlohmann::json j = deltaE2000Json(s, 1);
  EXPECT_EQ(j["differing"], 2);
  EXPECT_EQ(j["worst"], nlohmann::json::array({2, 0}));
  EXPECT_EQ(j["worst_window"], nlohmann::json::array({2, 0}));
}

TEST(Ciede2000, FramesAreReadAsTheirEightBitPictures) {
  Frame e = flatFrame(3, 1, 0.2f, 0.4f, 0.6f);
  Frame a = flatFrame(3, 1, 0.2f, 0.4f, 0.6f);
  a.color[0] += 0.4f / 255.0f;  // same byte: no difference
  a.color[4] = -3.0f;           // clamped to 0
  e.color[4] = 0.0f;            //   like this one: equal
  a.color[8] = std::nanf("");   // NaN reads as 0 ...
  const DeltaE2000Stats s = deltaE2000Frames(e, a);
  EXPECT_EQ(s.differing, 1u);  // ... and differs from 0.2
  const double want = ciede2000(srgbToLab(51 / 255.0, 102 / 255.0, 153 / 255.0),
                                srgbToLab(0.0, 102 / 255.0, 153 / 255.0));
  EXPECT_NEAR(s.max, want, 1e-12);
  EXPECT_EQ(s.worst_x, 2);
  const DeltaE2000Stats same = deltaE2000Frames(e, e);
  EXPECT_EQ(same.differing, 0u);
  EXPECT_EQ(same.mean, 0.0);
  EXPECT_EQ(same.max, 0.0);
  EXPECT_EQ(same.worst_x, -1);
  EXPECT_TRUE(deltaE2000Json(same, 1)["worst"].is_null());
}

// A frame large enough to be split over two threads (512 x 512), random colours, against
// the statistics computed here pixel by pixel in one pass with a plain sort; the largest
// difference placed twice, once in each half: the worst pixel is the first in row order.
TEST(Ciede2000, LargeFramesGiveTheOnePassAnswer) {
  constexpr int kSide = 512;
  Frame e = flatFrame(kSide, kSide, 0.0f, 0.0f, 0.0f);
  Frame a = flatFrame(kSide, kSide, 0.0f, 0.0f, 0.0f);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> step(-3, 3);
  for (std::size_t i = 0; i < e.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const int v = byte(rng);
      e.color[4 * i + c] = static_cast<float>(v) / 255.0f;
      a.color[4 * i + c] = static_cast<float>(std::clamp(v + step(rng), 0, 255)) / 255.0f;
    }
  for (const std::size_t i : {std::size_t{1000}, e.pixelCount() - 1000}) {  // black vs white
    for (int c = 0; c < 3; ++c) {
      e.color[4 * i + c] = 0.0f;
      a.color[4 * i + c] = 1.0f;
    }
  }
  std::vector<double> d;
  double total = 0.0;
  for (std::size_t i = 0; i < e.pixelCount(); ++i) {
    auto byteOf = [](float v) { return std::lround(v * 255.0f) / 255.0; };
    const double x = ciede2000(
        srgbToLab(byteOf(e.color[4 * i]), byteOf(e.color[4 * i + 1]), byteOf(e.color[4 * i + 2])),
        srgbToLab(byteOf(a.color[4 * i]), byteOf(a.color[4 * i + 1]), byteOf(a.color[4 * i + 2])));
    total += x;
    if (x > 0.0) d.push_back(x);
  }
  std::sort(d.begin(), d.end());
  double cum = 0.0, median = 0.0;
  for (const double x : d)
    if ((cum += x) >= 0.5 * total) {
      median = x;
      break;
    }
  const DeltaE2000Stats s = deltaE2000Frames(e, a);
  EXPECT_EQ(s.differing, d.size());
  EXPECT_NEAR(s.mean, total / static_cast<double>(e.pixelCount()), 1e-9);
  EXPECT_NEAR(s.max, d.back(), 1e-9);
  EXPECT_NEAR(s.weighted_median, median, 1e-9);
  EXPECT_EQ(s.worst_x, 1000 % kSide);
  EXPECT_EQ(s.worst_y, 1000 / kSide);
}

}  // namespace
}  // namespace rc
