// Depth quantization per format against hand-computed values, the depth test, and the
// uncertainty channels (depth_gap, edge_dist) against analytic values.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "reference/fragment_ops.h"
#include "reference/reference_renderer.h"
#include "reference/uncertainty.h"
#include "reference/vertex_stage.h"
#include "reference/viewport.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

// A full-viewport rectangle at window depth 1 - z (test::windowScene).
Frame renderPlane(DepthFormat format, float z) {
  Scene s = test::windowScene(8, 8);
  s.state.depth_format = format;
  test::addRect(s, -1, -1, 9, 9, z);
  return renderReference(s);
}

TEST(DepthQuantization, UnormRoundsToNearestEvenAtHandComputedValues) {
  struct Case {
    float z_world;    // window z = 1 - z_world, exact for these dyadic values
    double q16, q24;  // hand-computed round-half-even(zw * (2^b - 1))
  };
  const Case cases[] = {
      {0.75f, 16384.0, 4194304.0},    // zw 0.25:  16383.75 -> 16384, 4194303.75 -> 4194304
      {0.6875f, 20480.0, 5242880.0},  // zw 0.3125: 20479.6875, 5242879.6875 (round up)
      {0.25f, 49151.0, 12582911.0},   // zw 0.75:  49151.25, 12582911.25 (round down)
      {0.5f, 32768.0, 8388608.0},  // zw 0.5:   32767.5 -> 32768, 8388607.5 -> 8388608 (tie, even)
      {1.0f, 0.0, 0.0},            // zw 0 (the near plane)
  };
  for (const Case& c : cases) {
    const Frame f16 = renderPlane(DepthFormat::D16, c.z_world);
    const Frame f24 = renderPlane(DepthFormat::D24, c.z_world);
    EXPECT_EQ(f16.depth[f16.index(3, 4)], static_cast<float>(c.q16 / 65535.0)) << c.z_world;
    EXPECT_EQ(f24.depth[f24.index(3, 4)], static_cast<float>(c.q24 / 16777215.0)) << c.z_world;
  }
}

TEST(DepthQuantization, Float32StoresTheFloatOfTheWindowDepth) {
  // world z = 0.9f -> window z = 1 - 0.89999997615814209 = 0.10000002384185791 (exact).
  const Frame f = renderPlane(DepthFormat::D32F, 0.9f);
  EXPECT_EQ(f.depth[f.index(0, 0)], 0.10000002384185791f);
  EXPECT_EQ(renderPlane(DepthFormat::D32F, 0.75f).depth[5], 0.25f);
}

TEST(DepthQuantization, KeysOrderLikeStoredValuesAndRoundTrip) {
  using ref::depthKey;
  using ref::storedDepth;
  for (DepthFormat fmt : {DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F}) {
    double prev = -1.0;
    std::uint32_t prev_key = 0;
    for (int i = 0; i <= 1000; ++i) {
      const double z = i / 1000.0;
      const std::uint32_t k = depthKey(z, fmt);
      const double stored = storedDepth(k, fmt);
      EXPECT_NEAR(stored, z, fmt == DepthFormat::D16 ? 0.5 / 65535 : 0.5 / 16777215 + 1e-9);
      if (i > 0) {
        EXPECT_EQ(stored > prev, k > prev_key);
      }
      prev = stored;
      prev_key = k;
    }
  }
  EXPECT_EQ(ref::clampDepth(-0.0), 0.0);
  EXPECT_FALSE(std::signbit(ref::clampDepth(-0.0)));
  EXPECT_EQ(ref::clampDepth(std::nan("")), 0.0);
  EXPECT_EQ(ref::clampDepth(1.5), 1.0);
}

// The frame's depth plane (storedDepthPlane(): a product by 1 / steps) against the
// float of storedDepth()'s quotient, for every key of both integer formats, and the bits of
// some float keys. Fails if the product is taken in float, or with 1 / steps rounded to float.
TEST(DepthKeys, PlaneIsStoredDepthForEveryKey) {
  for (DepthFormat fmt : {DepthFormat::D16, DepthFormat::D24}) {
    const auto last = static_cast<std::uint32_t>(ref::depthStepsPerUnit(fmt));
    std::vector<std::uint32_t> keys(4096);
    std::vector<float> plane(keys.size());
    std::uint64_t wrong = 0;
    for (std::uint64_t first = 0; first <= last; first += keys.size()) {
      const std::size_t count = std::min<std::uint64_t>(keys.size(), last - first + 1);
      for (std::size_t i = 0; i < count; ++i) keys[i] = static_cast<std::uint32_t>(first + i);
      ref::storedDepthPlane(keys.data(), count, fmt, plane.data());
      for (std::size_t i = 0; i < count; ++i) {
        const auto expected = static_cast<float>(ref::storedDepth(keys[i], fmt));
        if (std::bit_cast<std::uint32_t>(plane[i]) != std::bit_cast<std::uint32_t>(expected) &&
            ++wrong <= 3)
          ADD_FAILURE() << toString(fmt) << " key " << keys[i] << ": " << plane[i]
                        << " != " << expected;
      }
    }
    EXPECT_EQ(wrong, 0u) << toString(fmt);
    EXPECT_EQ(plane[(last % keys.size())], 1.0f) << toString(fmt);  // the last key is 1
  }
  const std::uint32_t floats[] = {0u, std::bit_cast<std::uint32_t>(0.1f),
                                  std::bit_cast<std::uint32_t>(1.0f), 0x00000001u};
  float plane[4];
  ref::storedDepthPlane(floats, 4, DepthFormat::D32F, plane);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(std::bit_cast<std::uint32_t>(plane[i]), floats[i]);
}

TEST(DepthTest, LessKeepsTheFirstOfEqualDepthsAndTheNearest) {
  Scene s = test::windowScene(8, 8);
  test::addRect(s, 0, 0, 8, 8, 0.5f);   // ids 1, 2
  test::addRect(s, 0, 0, 8, 8, 0.5f);   // ids 3, 4: equal depth, LESS fails
  test::addRect(s, 0, 0, 4, 8, 0.25f);  // ids 5, 6: farther, fails
  test::addRect(s, 4, 0, 8, 8, 0.75f);  // ids 7, 8: nearer, passes on the right half
  const Frame f = renderReference(s);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const std::uint32_t id = f.id[f.index(x, y)];
      if (x < 4)
        EXPECT_TRUE(id == 1 || id == 2) << id;
      else
        EXPECT_TRUE(id == 7 || id == 8) << id;
    }
  s.state.depth_test = false;  // ALWAYS: the last drawn wins
  const Frame g = renderReference(s);
  EXPECT_TRUE(g.id[g.index(1, 1)] == 5 || g.id[g.index(1, 1)] == 6);
  EXPECT_EQ(g.depth[g.index(1, 1)], static_cast<float>(std::round(0.75 * 16777215.0) / 16777215.0));
}

TEST(DepthGap, TwoParallelPlanesAKnownNumberOfStepsApart) {
  for (DepthFormat fmt : {DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F}) {
    Scene s = test::windowScene(8, 8);
    s.state.depth_format = fmt;
    // Window depths 0.5 and 0.5 - 10 * 2^-24 (world z = 1 - window z, exact in float).
    test::addRect(s, 0, 0, 8, 8, 0.5f);
    test::addRect(s, 0, 0, 8, 4, 0.5f + 10.0f / 16777216.0f);
    test::addRect(s, 0, 0, 8, 2, 0.25f);  // a third, farther plane on the bottom rows
    const Frame f = renderReference(s);
    const double steps = ref::depthStepsPerUnit(fmt);
    const double expected = 10.0 / 16777216.0 * steps;  // d24: 9.9999994, d32f: 10
    for (int y = 0; y < 8; ++y) {
      const float gap = f.depth_gap[f.index(3, y)];
      // Every plane would have to fail against the clear depth 1 for background: the
      // farthest from it, the plane at 0.5 (or 10 steps nearer), decides.
      EXPECT_NEAR(f.clear_gap[f.index(3, y)], 0.5 * steps, 1e-5 * steps) << y;
      if (y < 4)
        EXPECT_EQ(gap, std::numeric_limits<float>::infinity()) << y;  // one plane only
      else
        EXPECT_NEAR(gap, expected, 1e-6 * expected) << toString(fmt) << " row " << y;
    }
  }
}

// Every pixel of a frame has depth_gap +inf.
void expectAllInfinite(const Frame& f, const std::string& what) {
  int finite = 0;
  for (float g : f.depth_gap) finite += !std::isinf(g);
  EXPECT_EQ(finite, 0) << what;
}

TEST(DepthGap, PassesWithoutADepthTestDecideNothingByDepth) {
  // Three overlapping planes: with a depth test the pixel's gap is finite; painter's
  // (forced or from the fixture) and depth_test false draw in an order both renderers
  // share, so no depth comparison decided the winner anywhere.
  Scene s = test::windowScene(8, 8);
  test::addRect(s, 0, 0, 8, 8, 0.5f);
  test::addRect(s, 0, 0, 8, 8, 0.25f);
  test::addRect(s, 0, 0, 8, 8, 0.75f);
  EXPECT_EQ(renderReference(s).depth_gap[0], static_cast<float>(0.25 * 16777215.0));
  expectAllInfinite(renderReference(s, ReferenceOptions{8, true, true}), "ref:painter");
  Scene painter = s;
  painter.state.visibility = Visibility::Painter;
  expectAllInfinite(renderReference(painter), "visibility painter");
  Scene no_test = s;
  no_test.state.depth_test = false;
  expectAllInfinite(renderReference(no_test), "depth_test false");
  no_test.materials[0].opacity = 0.5;  // and the transparent pass without a test
  no_test.state.blend = Blend::Alpha;
  expectAllInfinite(renderReference(no_test), "depth_test false, alpha");
}

TEST(DepthGap, AlphaPassCountsOnlyTheComparisonsThatDecidedTheWinner) {
  // Window depths (1 - world z, all exact): opaque W 0.5 and, drawn after it, opaque O2
  // 2^-10 behind (it fails against W); transparent X at 0.75 everywhere (behind W), and on
  // the left half transparent V at 0.5 - 2^-7 and T at 0.25, both in front of W. The
  // transparent pass draws far-to-near: X, V, T.
  Scene s = test::windowScene(8, 8);
  Material glass = s.materials[0];
  glass.opacity = 0.5;
  const std::size_t g = test::addMaterial(s, glass);
  s.state.blend = Blend::Alpha;
  test::addRect(s, 0, 0, 8, 8, 0.5f);                     // W: ids 1, 2
  test::addRect(s, 0, 0, 8, 8, 0.5f - 1.0f / 1024.0f);    // O2: ids 3, 4
  test::addRect(s, 0, 0, 8, 8, 0.25f, g);                 // X: ids 5, 6
  test::addRect(s, 0, 0, 4, 8, 0.5f + 1.0f / 128.0f, g);  // V: ids 7, 8
  test::addRect(s, 0, 0, 4, 8, 0.75f, g);                 // T: ids 9, 10
  const Frame f = renderReference(s);
  const double steps = 16777215.0;
  for (int y = 0; y < 8; ++y) {
    // Right half: W is the final id. Deciding: O2 failing against W (2^-10) and X failing
    // against W (0.25).
    const std::size_t right = f.index(6, y);
    EXPECT_TRUE(f.id[right] == 1 || f.id[right] == 2) << f.id[right];
    EXPECT_EQ(f.depth_gap[right], static_cast<float>(steps / 1024.0)) << y;
    // Left half: T is the final id. Only T's own test against W decided it (0.25); V's
    // test (2^-7 from W) and the opaque z-fight do not: whatever they gave, T, drawn last
    // in front of W, still wins. (The two nearest fragments, T and V, are 0.2421875 apart.)
    const std::size_t left = f.index(1, y);
    EXPECT_TRUE(f.id[left] == 9 || f.id[left] == 10) << f.id[left];
    EXPECT_EQ(f.depth_gap[left], static_cast<float>(0.25 * steps)) << y;
  }
}

// The depth_gap definition evaluated by brute force: simulate the pixel's fragments, flip
// each depth comparison's outcome alone (later fragments re-tested against what then gets
// stored), and keep |z_f - z_s| of every comparison with a stored fragment whose flip
// changes the final fragment. clear_gap by its definition: a drawn pixel is background
// only if every tested fragment fails against the clear depth 1 (the largest |z - 1|), a
// background pixel drawn if one passes (the smallest); +inf with an untested fragment.
struct Gaps {
  double depth = std::numeric_limits<double>::infinity();
  double clear = std::numeric_limits<double>::infinity();
};
struct TestFragment {
  double z;
  bool tested;  // LESS, else ALWAYS
  bool writes;
};

Gaps bruteForceGaps(const std::vector<TestFragment>& frags, DepthFormat format) {
  const std::uint32_t clear = ref::depthKey(1.0, format);
  struct Run {
    int final = -1;
    std::vector<std::pair<int, int>> comparisons;  // (fragment, fragment that stored)
  };
  auto simulate = [&](int flip) {
    Run r;
    std::uint32_t stored = clear;
    int stored_by = -1;
    for (int i = 0; i < static_cast<int>(frags.size()); ++i) {
      const TestFragment& f = frags[static_cast<std::size_t>(i)];
      const std::uint32_t key = ref::depthKey(f.z, format);
      bool pass = !f.tested || key < stored;
      if (f.tested) {
        r.comparisons.emplace_back(i, stored_by);
        if (i == flip) pass = !pass;
      }
      if (!pass) continue;
      r.final = i;
      if (f.writes) {
        stored = key;
        stored_by = i;
      }
    }
    return r;
  };
  const Run base = simulate(-1);
  Gaps gaps;
  for (const auto& [f, s] : base.comparisons) {
    if (s < 0 || simulate(f).final == base.final) continue;
    gaps.depth = std::min(gaps.depth, std::fabs(frags[static_cast<std::size_t>(f)].z -
                                                frags[static_cast<std::size_t>(s)].z));
  }
  bool untested = false;
  double near = std::numeric_limits<double>::infinity();
  double far = -1.0;
  for (const TestFragment& f : frags) {
    untested = untested || !f.tested;
    if (!f.tested) continue;
    near = std::min(near, 1.0 - f.z);
    far = std::max(far, 1.0 - f.z);
  }
  if (!untested && far >= 0.0) gaps.clear = base.final >= 0 ? far : near;
  return gaps;
}

TEST(DepthGap, TrackerEqualsTheBruteForceDefinitionOnRandomPixels) {
  // Pixel histories shaped like drawPasses(): a z-buffer pass (LESS, writes) then a
  // transparent pass (LESS, no writes), or ALWAYS passes; depths from a small set so that
  // d16 keys tie often.
  std::uint32_t seed = 7;
  auto rnd = [&](std::uint32_t n) {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) % n;
  };
  int finite = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const DepthFormat format = trial % 2 ? DepthFormat::D16 : DepthFormat::D24;
    const bool always = rnd(8) == 0;
    std::vector<TestFragment> frags;
    const std::uint32_t opaque = rnd(5);
    const std::uint32_t transparent = rnd(4);
    for (std::uint32_t i = 0; i < opaque + transparent; ++i) {
      const double z = 0.25 + 0.001 * rnd(16) + (rnd(2) ? 1e-6 * rnd(8) : 0.0);
      frags.push_back({z, !always, i < opaque});
    }
    Frame pixel;  // one pixel's uncertainty channels
    const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    pixel.allocate(1, 1, clear, 1.0f, true);
    ref::UncertaintyTracker tracker;
    tracker.reset(pixel, format, 1.0);
    std::uint32_t stored = ref::depthKey(1.0, format);
    for (const TestFragment& f : frags) {
      const std::uint32_t key = ref::depthKey(f.z, format);
      if (!f.tested || key < stored) {
        tracker.passed(0, f.z, 0.0f, 0.0f, f.tested, f.writes, !f.writes);
        pixel.id[0] = 1;  // drawn
        if (f.writes) stored = key;
      } else {
        tracker.failed(0, f.z, 0.0f, 0.0f, !f.writes);
      }
    }
    tracker.finish(pixel);
    const Gaps want = bruteForceGaps(frags, format);
    auto steps = [&](double gap) {
      return std::isinf(gap) ? std::numeric_limits<float>::infinity()
                             : static_cast<float>(gap * ref::depthStepsPerUnit(format));
    };
    ASSERT_EQ(pixel.depth_gap[0], steps(want.depth)) << "trial " << trial;
    std::string history;
    for (const TestFragment& f : frags)
      history += fmt::format(" (z {}, {}, {})", f.z, f.tested ? "LESS" : "ALWAYS",
                             f.writes ? "writes" : "no writes");
    ASSERT_EQ(pixel.clear_gap[0], steps(want.clear)) << "trial " << trial << ":" << history;
    finite += !std::isinf(want.depth);
  }
  EXPECT_GT(finite, 5000);  // the cases are not all trivial
}

// Distance from (px, py) to segment a-b: the test's own oracle.
double segDist(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 d = b - a;
  const double t = std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0);
  return glm::length(p - (a + t * d));
}

// Every edge distance is less the edge's float32 reach (docs/tolerances.md "Vertex
// precision"): 8 ulps of window-sized magnitudes, below 1e-4 px in these small scenes.
constexpr double kSmallReach = 1e-4;

TEST(EdgeDist, DistanceToEdgeSegmentsCappedAtOne) {
  Scene s = test::windowScene(16, 16);
  test::addTriangle(s, {3.25f, 1.0f, 0.5f}, {14.0f, 1.0f, 0.5f}, {3.25f, 15.0f, 0.5f});
  const Frame f = renderReference(s);
  auto at = [&](int x, int gl_y) { return f.edge_dist[f.index(x, 15 - gl_y)]; };
  EXPECT_NEAR(at(3, 8), 0.25, kSmallReach);  // centre 3.5: 0.25 right of x = 3.25
  EXPECT_NEAR(at(2, 8), 0.75, kSmallReach);
  EXPECT_FLOAT_EQ(at(4, 8), 1.0f);          // 1.25 away: capped
  EXPECT_NEAR(at(8, 1), 0.5, kSmallReach);  // centre y 1.5 above the bottom edge y = 1
  // Below-left of the vertex (3.25, 1): distance to the segment end, not to the line.
  EXPECT_NEAR(at(2, 0), std::hypot(0.75, 0.5), kSmallReach);
  EXPECT_LE(at(2, 0), std::hypot(0.75, 0.5));  // the reach only ever lowers it
  EXPECT_FLOAT_EQ(at(0, 0), 1.0f);
  const Frame none = renderReference(s, ReferenceOptions{8, false, false});
  EXPECT_FALSE(none.hasUncertainty());
}

// addEdgeDistances() and EdgeDistanceBatch against their definition evaluated at every
// pixel of the image for every segment (no band, no interval shortcut, no lanes): each
// visit leaves min(cur, float(max(hypot(q) - reach, 0))) with q from the segment point
// nearest the centre. Bit for bit, on random segments from a fraction of a pixel to longer
// than the image (the short ones take the bounding-box rows, the long ones the per-row
// band; in the batch, triangles up to 4 px across take the small-triangle pass, all three
// edges over one box), in an image whose width is not a multiple of four (rows end inside a group
// of four lanes), with and without reach, points on the segments, diagonals through pixel
// centres and zero-length segments.
TEST(EdgeDist, EqualsItsDefinitionAtEveryPixelBitForBit) {
  constexpr int kW = 37;
  constexpr int kH = 23;
  const ref::PixelRect clip{0, 0, kW, kH};
  auto oracle = [&](std::vector<float>& dist, const ref::WindowVertex* poly, int count,
                    const double* reach) {
    for (int i = 0; i < count; ++i) {
      const ref::WindowVertex& a = poly[i];
      const ref::WindowVertex& b = poly[(i + 1) % count];
      const double r = std::max(reach[i], reach[(i + 1) % count]);
      const double dx = b.x - a.x;
      const double dy = b.y - a.y;
      const double len2 = dx * dx + dy * dy;
      for (int py = 0; py < kH; ++py) {
        for (int px = 0; px < kW; ++px) {
          const double cx = px + 0.5;
          const double cy = py + 0.5;
          double t = 0.0;
          if (len2 > 0.0) {
            const double num = (cx - a.x) * dx + (cy - a.y) * dy;
            t = num >= len2 ? 1.0 : num <= 0.0 ? 0.0 : num / len2;
          }
          const double d = std::hypot(cx - (a.x + t * dx), cy - (a.y + t * dy)) - r;
          float& cur = dist[static_cast<std::size_t>(kH - 1 - py) * kW + px];
          cur = std::min(cur, static_cast<float>(std::max(d, 0.0)));
        }
      }
    }
  };
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> pos(-4.0, kW + 4.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int lowered = 0;
  for (int scene = 0; scene < 300; ++scene) {
    std::vector<float> want(static_cast<std::size_t>(kW) * kH, 1.0f);
    std::vector<float> got = want;
    std::vector<float> batched = want;
    std::vector<float> narrow = want;  // four centres at a time wherever AVX-512 is
    ref::EdgeDistanceBatch batch;
    ref::EdgeDistanceBatch narrow_batch;
    narrow_batch.allowWideLanes(false);
    for (int polygon = 0; polygon < 5; ++polygon) {
      ref::WindowVertex v[3] = {};
      // Sizes from a tenth of a pixel to the whole image.
      const double size = std::pow(10.0, -1.0 + 2.5 * unit(rng));
      v[0].x = pos(rng);
      v[0].y = pos(rng);
      for (int k = 1; k < 3; ++k) {
        v[k].x = v[0].x + size * (2.0 * unit(rng) - 1.0);
        v[k].y = v[0].y + size * (2.0 * unit(rng) - 1.0);
      }
      if (polygon == 1) v[1] = v[0];  // a zero-length segment
      if (polygon == 2) {             // a vertex on a pixel centre, an edge through centres
        v[0].x = std::floor(v[0].x) + 0.5;
        v[0].y = std::floor(v[0].y) + 0.5;
        v[1].y = v[0].y;
      }
      if (polygon == 3) {  // a diagonal through centres, q exactly 0 on them (a mesh's grid)
        v[0].x = std::floor(v[0].x) + 0.5;
        v[0].y = std::floor(v[0].y) + 0.5;
        const double m = std::ldexp(1.0, scene % 4);  // 1, 2, 4, 8 px: t = k / m exact
        v[1].x = v[0].x + (unit(rng) < 0.5 ? m : -m);
        v[1].y = v[0].y + (unit(rng) < 0.5 ? m : -m);
      }
      double reach[3] = {0.0, 0.0, 0.0};
      if (scene % 2 == 1)
        for (double& r : reach) r = 0.3 * unit(rng) * unit(rng);
      oracle(want, v, 3, reach);
      ref::addEdgeDistances(v, 3, clip, kW, kH, got.data(), reach);
      batch.add(v, 3, reach);
      narrow_batch.add(v, 3, reach);
    }
    batch.apply(clip, kW, kH, batched.data());
    narrow_batch.apply(clip, kW, kH, narrow.data());
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(got[i]), std::bit_cast<std::uint32_t>(want[i]))
          << "scene " << scene << " pixel " << i % kW << "," << i / kW << ": " << got[i] << " want "
          << want[i];
      ASSERT_EQ(std::bit_cast<std::uint32_t>(batched[i]), std::bit_cast<std::uint32_t>(want[i]))
          << "batched, scene " << scene << " pixel " << i;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(narrow[i]), std::bit_cast<std::uint32_t>(want[i]))
          << "batched four at a time, scene " << scene << " pixel " << i;
      lowered += want[i] < 1.0f;
    }
  }
  EXPECT_GT(lowered, 5000);  // the segments came near many centres
  if (!ref::EdgeDistanceBatch::wideLanesAvailable())
    std::cout << "[ NOTE ] no AVX-512 here: the batch ran four centres at a time both ways\n";
}

// A triangle cut by the near plane becomes a quadrilateral drawn as a fan; edge_dist
// follows the four boundary edges and ignores the fan's internal diagonal.
TEST(EdgeDist, ClippedPolygonBoundaryOnlyNotTheFanDiagonal) {
  Scene s = test::windowScene(64, 64);
  // Window depth 1 - z: the vertex at z = 1.5 lies in front of the near plane (depth < 0),
  // both edges to it are cut where z = 1, at y = 32.
  test::addTriangle(s, {4, 4, 0.5f}, {60, 4, 0.5f}, {32, 60, 1.5f});
  const Frame f = renderReference(s);
  const glm::dvec2 A(4, 4), B(60, 4), P(46, 32), Q(18, 32);
  int near_diagonal = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const glm::dvec2 c(x + 0.5, 63 - y + 0.5);
      const double d =
          std::min({segDist(c, A, B), segDist(c, B, P), segDist(c, P, Q), segDist(c, Q, A), 1.0});
      // The cut vertices P, Q come from float32-sized intersection errors: reach < 1e-3 px.
      ASSERT_NEAR(f.edge_dist[f.index(x, y)], d, d < 1.0 ? 1e-3 : 0.0) << x << "," << y;
      const bool inside = c.y > 4 && c.y < 32 && segDist(c, A, P) < 0.5 && d == 1.0;
      near_diagonal += inside;
      // Coverage of the trapezoid (no centre lies on its edges here).
      const bool covered = c.y > 4 && c.y < 32 && (c.x - 4) * 28 > (c.y - 4) * 14 &&
                           (60 - c.x) * 28 > (c.y - 4) * 14;
      ASSERT_EQ(f.id[f.index(x, y)] != 0, covered) << x << "," << y;
    }
  EXPECT_GT(near_diagonal, 10);  // pixels within 0.5 px of the diagonal A-P, edge_dist 1
}

// Where clip-space magnitudes dwarf the result, a float32 driver may put a near-plane cut
// pixels away: an orthographic camera with near 0.001 and far 1e5 has z_clip = -1 + 2e-5 *
// depth, whose float ulp is 3e-3 world units of depth. A quad tilted by 0.01 in depth per
// world unit across the screen crosses the near plane: its cut edge moves by about
// 3e-3 / 0.01 = 0.3 world units (here 0.3 * 64 / 2 = 10 px). Its edge_dist is 0 there,
// while the same geometry with near 1 and far 3 keeps it within 0.01 px of the exact one
// (the plane is so tilted in depth that even there the cut is uncertain by ~0.006 px).
TEST(EdgeDist, NearPlaneCutsAreAsUncertainAsTheirClipSpaceMagnitudes) {
  auto render = [](double near, double far) {
    Scene s = test::windowScene(64, 64);
    s.camera.projection = Projection::Orthographic;
    s.camera.bounds = {-1.0, 1.0, -1.0, 1.0};
    s.camera.eye = {0.0, 0.0, 1.0};
    s.camera.near = near;
    s.camera.far = far;
    // Depth below the eye is 1 - z: the plane z = 1 - near + 0.01 x reaches the near plane
    // (depth = near) at x = 0, and is clipped right of it.
    const float n = static_cast<float>(near);
    test::addRect(s, -2.0f, -2.0f, 2.0f, 2.0f, 0.0f);
    Mesh& m = s.objects.back().mesh;
    for (glm::vec3& p : m.positions) p.z = 1.0f - n + 0.01f * p.x;
    return renderReference(s);
  };
  // Column 32 (window x 32.5, world x 0.016): just inside the cut at x = 0 (world),
  // 0.5 px from it.
  const Frame extreme = render(0.001, 1e5);
  const Frame tame = render(1.0, 3.0);
  int zero = 0;
  for (int x = 30; x < 40; ++x) zero += extreme.edge_dist[extreme.index(x, 20)] == 0.0f;
  EXPECT_GE(zero, 8);  // the cut is uncertain by about 10 px on either side
  EXPECT_NEAR(tame.edge_dist[tame.index(32, 20)], 0.5, 0.01);
}

TEST(EdgeDist, CulledTrianglesCountOnlyWhenTheCullDecisionCouldFlip) {
  Scene s = test::windowScene(16, 16);
  s.state.cull = Cull::Back;
  test::addTriangle(s, {2, 2, 0.5f}, {2, 14, 0.5f}, {14, 2, 0.5f});  // clockwise: culled
  // A clockwise sliver 1/64 px thick: culled too, but its area could flip sign.
  test::addTriangle(s, {2, 8.5f, 0.5f}, {14, 8.5f + 1.0f / 64, 0.5f}, {14, 8.5f, 0.5f});
  const Frame f = renderReference(s);
  for (std::uint32_t id : f.id) EXPECT_EQ(id, 0u);
  const auto at = [&](int x, int gl_y) { return f.edge_dist[f.index(x, 15 - gl_y)]; };
  EXPECT_FLOAT_EQ(at(1, 4), 1.0f);   // 0.5 from the culled big triangle's edge x = 2: ignored
  EXPECT_NEAR(at(8, 8), 0.0, 1e-6);  // centre (8.5, 8.5) lies on the sliver's bottom edge
  EXPECT_NEAR(at(8, 9), 1.0 - (6.5 / 12.0) / 64.0, 1e-3);  // below its top edge
}

// depth_reach against an independent float32 vertex transform, as a GL driver runs it
// (shaders.cpp: world positions as float attributes, view_projection as a float uniform,
// gl_Position = u_view_projection * vec4(p, 1)): the four sums of each clip component
// in three orders (GLSL fixes none), then the divide and viewport in double, so that only
// the vertex transform's error is measured. Cameras from 1 to 1e4 units from the origin,
// near 1e-3 to 1, far to 1e5, points between near and 50 units in front: the float32
// window depth must stay within windowDepthError() of the exact one, and the bound must
// not be loose by more than a factor of 20 (its 8 ulps against the observed worst).
TEST(DepthReach, BoundsTheWindowDepthOfAFloat32VertexTransform) {
  std::mt19937 rng(20261202);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> exponent(0.0, 4.0);
  double worst_ratio = 0.0;
  int trials = 0;
  for (int c = 0; c < 200; ++c) {
    Scene s = test::windowScene(256, 192);
    s.camera.projection = c % 4 == 0 ? Projection::Orthographic : Projection::Perspective;
    s.camera.bounds = {-2.0, 2.0, -1.5, 1.5};
    const glm::dvec3 dir = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
    s.camera.eye = std::pow(10.0, exponent(rng)) * dir;
    s.camera.target = s.camera.eye - glm::dvec3(unit(rng), unit(rng), 1.5 + unit(rng));
    s.camera.near = std::pow(10.0, -3.0 * std::fabs(unit(rng)));
    s.camera.far = std::pow(10.0, 1.0 + 4.0 * std::fabs(unit(rng)));
    const ref::CameraTransform cam = ref::cameraTransform(s);
    const glm::dvec3 forward = glm::normalize(s.camera.target - s.camera.eye);
    Object object;
    for (int k = 0; k < 20; ++k) {
      const double depth = s.camera.near + (50.0 - s.camera.near) * 0.5 * (1.0 + unit(rng));
      object.mesh.positions.emplace_back(glm::vec3(
          s.camera.eye + depth * forward + 0.3 * depth * glm::dvec3(unit(rng), unit(rng), 0.0)));
    }
    std::vector<ref::TransformedVertex> out;
    ref::transformObject(object, cam, out, false, true);
    const glm::mat4 vp(cam.view_projection);
    for (const ref::TransformedVertex& v : out) {
      if (!(v.clip.w > 0.0)) continue;
      const double exact = v.clip.z / v.clip.w * 0.5 + 0.5;
      const glm::vec4 p(glm::vec3(v.world), 1.0f);
      const double bound = ref::windowDepthError(ref::ClipVertex{v.clip, {}, v.clip_err});
      for (int order = 0; order < 3; ++order) {
        auto sum = [&](int row) {
          const float t[4] = {vp[0][row] * p.x, vp[1][row] * p.y, vp[2][row] * p.z, vp[3][row]};
          if (order == 0) return ((t[0] + t[1]) + t[2]) + t[3];
          if (order == 1) return ((t[3] + t[2]) + t[1]) + t[0];
          return (t[0] + t[1]) + (t[2] + t[3]);
        };
        const double z = sum(2);
        const double w = sum(3);
        const double err = std::fabs(z / w * 0.5 + 0.5 - exact);
        ASSERT_LE(err, bound * (1.0 + 1e-6)) << "camera " << c << " order " << order;
        worst_ratio = std::max(worst_ratio, err / bound);
        ++trials;
      }
    }
  }
  EXPECT_GT(trials, 10000);
  EXPECT_GT(worst_ratio, 0.05) << "the 8-ulp bound is far looser than float32 transforms get";
}

// The channel in a rendered frame: a triangle 0.4 units in front of a camera 1.9e3 units
// from the origin (a random scene's, where llvmpipe and zink stored d32f depth 1477 steps
// from the reference) has a depth_reach of thousands of steps; the same triangle moved
// with its camera to the origin has a small one, below the d24/d32f base threshold.
TEST(DepthReach, FollowsTheMagnitudeOfTheWorldCoordinates) {
  auto render = [](const glm::dvec3& offset) {
    Scene s = test::windowScene(64, 48);
    s.state.depth_format = DepthFormat::D32F;
    s.camera.projection = Projection::Perspective;
    s.camera.fovy_deg = 31.6;
    s.camera.near = 0.001;
    s.camera.far = 1e5;
    s.camera.eye = offset;
    s.camera.target = offset + glm::dvec3(-1.0, 0.2, 0.05);
    const glm::dvec3 a = offset + glm::dvec3(-0.4, -0.08, -0.1);
    const glm::dvec3 b = offset + glm::dvec3(-0.45, 0.1, 0.05);
    const glm::dvec3 c = offset + glm::dvec3(-0.4, 0.05, 0.15);
    test::addTriangle(s, glm::vec3(a), glm::vec3(b), glm::vec3(c));
    return renderReference(s);
  };
  const Frame far = render({1872.88, -393.969, -91.988});
  const Frame near = render({0.0, 0.0, 0.0});
  float far_max = 0.0f;
  float near_max = 0.0f;
  int drawn = 0;
  for (std::size_t i = 0; i < far.pixelCount(); ++i) {
    if (far.id[i] != 0) ++drawn;
    far_max = std::max(far_max, far.depth_reach[i]);
    near_max = std::max(near_max, near.depth_reach[i]);
    if (far.id[i] == 0) {
      EXPECT_EQ(far.depth_reach[i], 0.0f) << "nothing tested there";
    }
  }
  EXPECT_GT(drawn, 100);
  EXPECT_GT(far_max, 1477.0f);  // what the drivers measured must be inside it
  EXPECT_LT(near_max, 16.0f);
  EXPECT_GT(near_max, 0.0f);
}

// The reach is interpolated over each triangle in screen space, as GL interpolates window
// z: a triangle whose one vertex lies behind the camera is cut at the near plane (near
// 0.01), where a vertex's window depth is as uncertain as its clip coordinates' error
// divided by w = near; pixels far from the cut get a much smaller share of it.
TEST(DepthReach, IsInterpolatedAcrossTheTriangleNotItsLargestVertex) {
  Scene s = test::windowScene(64, 64);
  s.state.depth_format = DepthFormat::D24;
  s.camera.projection = Projection::Perspective;
  s.camera.fovy_deg = 60.0;
  s.camera.near = 0.01;
  s.camera.far = 100.0;
  s.camera.eye = {0.0, 0.0, 0.0};
  s.camera.target = {0.0, 0.0, -1.0};
  // A floor-like triangle 0.002 below the eye, from 5 units ahead to 1 unit behind it: the
  // near-plane cut is in view at the bottom of the image.
  test::addTriangle(s, {-3.0f, -0.002f, -5.0f}, {3.0f, -0.002f, -5.0f}, {0.0f, -0.002f, 1.0f});
  const Frame f = renderReference(s);
  float lo = std::numeric_limits<float>::infinity();
  float hi = 0.0f;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    if (f.id[i] == 0) continue;
    lo = std::min(lo, f.depth_reach[i]);
    hi = std::max(hi, f.depth_reach[i]);
  }
  ASSERT_GT(hi, 0.0f);
  // Measured: 304 to 6492 d24 steps (screen-space weights give the cut's corner a share
  // even near the horizon, as they do to its error in a driver).
  EXPECT_GT(hi, 10.0f * lo) << "the cut's reach is not spread over the whole triangle";
  std::cout << "depth_reach on the floor: " << lo << " to " << hi << " d24 steps\n";
}

// planeSetupError() against an independent float32 set-up of the depth plane, as a GL
// implementation computes it from its window vertices: edge vectors from a reference vertex
// a (any of the three, either winding), the cross products, the quotient by the area, then
// z = z_a + gx (x - x_a) + gy (y - y_a), every operation in float. Ordinary triangles and
// slivers down to 1e-4 of their length wide, up to 2048 px, z from the whole range to
// near-constant, evaluated at pixel centres inside or within a pixel: the float32 depth
// must be within the bound of the exact plane (plus two float32 ulps of the result: its
// last roundings, which the base thresholds cover), and the bound must not be loose by
// more than a factor of 50. The sliver of campaign s20261226 (78 px long, 0.045 px wide,
// seen edge-on), where llvmpipe stored depth 144 d24 steps from the exact plane and the
// slope and vertex terms allowed 119, gets a bound above it.
TEST(DepthReach, PlaneSetUpBoundsAFloat32SetUpFromAnyVertex) {
  auto exactAt = [](const ref::WindowVertex* v, double x, double y) {
    const double det =
        (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
    const double gx =
        ((v[1].z - v[0].z) * (v[2].y - v[0].y) - (v[2].z - v[0].z) * (v[1].y - v[0].y)) / det;
    const double gy =
        ((v[1].x - v[0].x) * (v[2].z - v[0].z) - (v[2].x - v[0].x) * (v[1].z - v[0].z)) / det;
    return v[0].z + gx * (x - v[0].x) + gy * (y - v[0].y);
  };
  auto float32At = [](const ref::WindowVertex& a, const ref::WindowVertex& b,
                      const ref::WindowVertex& c, double x, double y) {
    const float ax = static_cast<float>(a.x), ay = static_cast<float>(a.y);
    const float az = static_cast<float>(a.z);
    const float ux = static_cast<float>(b.x) - ax, uy = static_cast<float>(b.y) - ay;
    const float uz = static_cast<float>(b.z) - az;
    const float vx = static_cast<float>(c.x) - ax, vy = static_cast<float>(c.y) - ay;
    const float vz = static_cast<float>(c.z) - az;
    const float area = ux * vy - vx * uy;
    const float gx = (uz * vy - vz * uy) / area;
    const float gy = (ux * vz - vx * uz) / area;
    return static_cast<double>(az + gx * (static_cast<float>(x) - ax) +
                               gy * (static_cast<float>(y) - ay));
  };
  auto vertex = [](double x, double y, double z) {
    // float32 positions: what a driver sets up from (their own rounding is a vertex move)
    return ref::WindowVertex{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                             1.0, glm::dvec3(0.0)};
  };
  std::mt19937 rng(20261226);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double worst_ratio = 0.0;
  int checks = 0;
  for (int t = 0; t < 4000; ++t) {
    const double x0 = 2048.0 * uni(rng), y0 = 2048.0 * uni(rng);
    double x1, y1, x2, y2;
    if (t % 2 == 0) {  // a sliver: c near the line a-b
      const double len = std::pow(10.0, 3.3 * uni(rng));
      const double ang = 6.283185307179586 * uni(rng);
      const double width = len * std::pow(10.0, -4.0 * uni(rng));
      const double along = -0.5 + 2.0 * uni(rng);
      x1 = x0 + len * std::cos(ang);
      y1 = y0 + len * std::sin(ang);
      x2 = x0 + along * len * std::cos(ang) - width * std::sin(ang);
      y2 = y0 + along * len * std::sin(ang) + width * std::cos(ang);
    } else {
      x1 = 2048.0 * uni(rng), y1 = 2048.0 * uni(rng), x2 = 2048.0 * uni(rng),
      y2 = 2048.0 * uni(rng);
    }
    double z[3] = {uni(rng), uni(rng), uni(rng)};
    if (t % 3 == 0)
      for (double& zi : z) zi = z[0] + 1e-4 * (uni(rng) - 0.5);  // nearly flat
    const ref::WindowVertex v[3] = {vertex(x0, y0, z[0]), vertex(x1, y1, z[1]),
                                    vertex(x2, y2, z[2])};
    const double bound = ref::planeSetupError(v[0], v[1], v[2]);
    const double det =
        (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
    if (det == 0.0) {
      EXPECT_EQ(bound, std::numeric_limits<double>::infinity());
      continue;
    }
    ASSERT_TRUE(std::isfinite(bound)) << t;
    for (int k = 0; k < 8; ++k) {
      // A pixel centre near a random point of the triangle (barycentrics in [0, 1]).
      const double l1 = uni(rng), l2 = (1.0 - l1) * uni(rng), l0 = 1.0 - l1 - l2;
      const double x = std::floor(l0 * v[0].x + l1 * v[1].x + l2 * v[2].x) + 0.5;
      const double y = std::floor(l0 * v[0].y + l1 * v[1].y + l2 * v[2].y) + 0.5;
      const double exact = exactAt(v, x, y);
      for (int a = 0; a < 3; ++a) {
        const ref::WindowVertex& p = v[a];
        const ref::WindowVertex& q = v[(a + 1) % 3];
        const ref::WindowVertex& r = v[(a + 2) % 3];
        for (const double z32 : {float32At(p, q, r, x, y), float32At(p, r, q, x, y)}) {
          const double err = std::fabs(z32 - exact) - 2.0 * 0x1p-24;  // its last roundings
          ASSERT_LE(err, bound) << "triangle " << t << " at " << x << "," << y;
          worst_ratio = std::max(worst_ratio, err / bound);
          ++checks;
        }
      }
    }
  }
  EXPECT_GT(checks, 100000);
  EXPECT_GT(worst_ratio, 0.02) << "the bound is far looser than float32 set-ups get";
  std::cout << "worst error / bound: " << worst_ratio << "\n";

  const ref::WindowVertex sliver[3] = {vertex(95.871534, 65.310913, 0.944722694),
                                       vertex(141.584338, 128.654394, 0.866853385),
                                       vertex(141.625944, 128.635161, 0.866872035)};
  constexpr double kD24Steps = 16777215.0;
  const double setup_err = std::fabs(float32At(sliver[0], sliver[1], sliver[2], 141.5, 128.5) -
                                     exactAt(sliver, 141.5, 128.5)) *
                           kD24Steps;
  EXPECT_GT(setup_err, 144.0 - 119.0) << "the set-up alone exceeds what the other terms allowed";
  EXPECT_GT(ref::planeSetupError(sliver[0], sliver[1], sliver[2]) * kD24Steps, setup_err);
}

}  // namespace
}  // namespace rc

namespace rc {
namespace {

// sideClipSetupError(): nothing for a triangle inside the viewport; for the triangle of
// campaign s20261324 scene 00526 (113 px long, its apex 0.455 px below the viewport where it
// is 0.02 px wide), whose side-clipped piece along the long edge put llvmpipe's depth 329 d24
// steps from the plane, a bound above that; for a large, well-shaped triangle crossing a side,
// pieces about as well conditioned as the triangle (a few d24 steps).
TEST(DepthReach, SideClippedPiecesBoundTheSliverAClipLeaves) {
  auto wv = [](double x, double y, double z) {
    ref::WindowVertex v{};
    v.x = x;
    v.y = y;
    v.z = z;
    v.inv_w = 1.0;
    return v;
  };
  constexpr double kD24 = 16777215.0;
  const ref::WindowVertex a = wv(29.225206996492517, -0.4549373766449816, 0.7874220122120903);
  const ref::WindowVertex b = wv(84.71212565114877, 97.57807406802384, 0.8506422508377185);
  const ref::WindowVertex c = wv(87.6196278832844, 94.33251561948947, 0.8609734928998194);
  const double own = ref::planeSetupError(a, b, c) * kD24;
  const double side = ref::sideClipSetupError(a, b, c, 149.0, 100.0) * kD24;
  EXPECT_LT(own, 60.0);
  EXPECT_GT(side, 329.0) << "the piece llvmpipe drew";
  // Moved up by a pixel, the apex is inside: no side clip.
  auto up = [](ref::WindowVertex v) {
    v.y += 1.0;
    return v;
  };
  EXPECT_EQ(ref::sideClipSetupError(up(a), up(b), up(c), 149.0, 100.0), 0.0);
  // A floor-like triangle far larger than the image, cut on all sides.
  const ref::WindowVertex p = wv(-300.0, -200.0, 0.2);
  const ref::WindowVertex q = wv(500.0, -150.0, 0.4);
  const ref::WindowVertex r = wv(60.0, 400.0, 0.9);
  EXPECT_LT(ref::sideClipSetupError(p, q, r, 149.0, 100.0) * kD24, 5.0);
  EXPECT_GT(ref::sideClipSetupError(p, q, r, 149.0, 100.0), 0.0);
}

}  // namespace
}  // namespace rc
