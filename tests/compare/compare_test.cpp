// The comparator against injected faults on reference-like frames: every fault must be
// caught in exactly its pixels and class, and nothing else may move. Expected numbers
// come from the injection (block sizes, offsets) and from the band formula, never from
// running the comparator first.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "fixtures/errors.h"
#include "synthetic_frames.h"
#include "tests/support/printers.h"

namespace rc {
namespace {

constexpr int kW = 256;
constexpr int kH = 256;
constexpr double kD24 = 16777215.0;

struct Block {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1), image coordinates
  int size() const { return (x1 - x0) * (y1 - y0); }
  bool contains(PixelRef p) const { return p.x >= x0 && p.x < x1 && p.y >= y0 && p.y < y1; }
};
// Inside the back rectangle, above its diagonal (id 1), > 4 px from any edge.
constexpr Block kBackBlock{70, 25, 100, 45};
// Background, > 2 px from any rectangle.
constexpr Block kEmptyBlock{20, 240, 40, 252};
// Inside the steep rectangle.
constexpr Block kSteepBlock{185, 30, 205, 50};

// A d24 depth moved by `steps` steps.
float quantized(float depth, double steps) {
  return static_cast<float>((std::nearbyint(depth * kD24) + steps) / kD24);
}

template <typename F>
void forBlock(const Block& b, F f) {
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) f(x, y);
}

class CompareTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ref_ = testing::renderRects(kW, kH, testing::defaultRects(kW, kH));
    gl_ = ref_;
    gl_.clearUncertainty();
    gl_.meta["backend"] = "gl:test";
    tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
    baseline_ = compareFrames(ref_, ref_, ref_, tol_);
  }
  PairResult compare(ClassMaps* maps = nullptr) {
    return compareFrames(ref_, gl_, ref_, tol_, maps);
  }
  // Pixels over fail when, over `block`, the reference's `channel` holds `value` and the
  // driver's colour channel `c` is `units` (8-bit) above the reference's (from `original`).
  std::uint64_t overFailWith(const Frame& original, const Block& block,
                             std::vector<float> Frame::*channel, float value, double units, int c) {
    gl_ = original;
    forBlock(block, [&](int x, int y) {
      const std::size_t i = ref_.index(x, y);
      (ref_.*channel)[i] = value;
      gl_.color[i * 4 + c] = ref_.color[i * 4 + c] + static_cast<float>(units / 255.0);
    });
    return compare().shading.over_fail;
  }

  Frame ref_;
  Frame gl_;
  Tolerances tol_;
  PairResult baseline_;
};

void expectNoVisibilityChange(const PairResult& r) {
  EXPECT_EQ(r.visibility.mismatched, 0u);
  EXPECT_EQ(r.visibility.missing, 0u);
  EXPECT_EQ(r.visibility.extra, 0u);
  EXPECT_EQ(r.visibility.wrong_primitive, 0u);
  EXPECT_EQ(r.visibility.status, Status::Pass);
}

TEST_F(CompareTest, SceneHasAllKindsOfPixels) {
  // Guards the fixture the other tests rely on.
  const std::size_t i = ref_.index(kBackBlock.x0, kBackBlock.y0);
  EXPECT_EQ(ref_.id[i], 1u);
  EXPECT_FLOAT_EQ(ref_.edge_dist[i], 1.0f);
  EXPECT_EQ(ref_.id[ref_.index(kEmptyBlock.x0, kEmptyBlock.y0)], 0u);
  EXPECT_NE(ref_.id[ref_.index(kSteepBlock.x0, kSteepBlock.y0)], 0u);
  EXPECT_GT(baseline_.depth.compared, 30000u);
  EXPECT_LT(baseline_.depth.compared, baseline_.pixels);
}

TEST_F(CompareTest, IdenticalFramesGiveZerosAndPass) {
  const PairResult& r = baseline_;
  EXPECT_EQ(r.status, Status::Pass);
  expectNoVisibilityChange(r);
  EXPECT_EQ(r.visibility.ambiguous, 0u);
  EXPECT_EQ(r.visibility.hard, 0u);
  EXPECT_EQ(r.depth.status, Status::Pass);
  EXPECT_EQ(r.depth.max_steps, 0.0);
  EXPECT_EQ(r.depth.mean_steps, 0.0);
  EXPECT_EQ(r.depth.p99_steps, 0.0);
  EXPECT_EQ(r.depth.over_tolerance, 0u);
  EXPECT_EQ(r.shading.status, Status::Pass);
  EXPECT_EQ(r.shading.max_abs, 0.0);
  EXPECT_EQ(r.shading.mean_abs, 0.0);
  EXPECT_EQ(r.shading.rmse, 0.0);
  EXPECT_EQ(r.shading.psnr_db, kPsnrCapDb);  // identical: the documented cap
  EXPECT_EQ(r.shading.over_tolerance, 0u);
  EXPECT_FALSE(r.depth.worst.valid());  // nothing differs: no worst pixel
  EXPECT_FALSE(r.shading.worst.valid());
  EXPECT_FALSE(r.visibility.worst.valid());
  EXPECT_EQ(r.nonfinite_expected.total(), 0u);
  EXPECT_EQ(r.pixels, static_cast<std::uint64_t>(kW * kH));
  EXPECT_EQ(r.depth.compared, r.shading.compared);
  EXPECT_EQ(r.fixture, "synthetic/rects");
  EXPECT_EQ(r.expected, "ref");
}

TEST_F(CompareTest, BlankIdsAreExactlyThatManyMissing) {
  forBlock(kBackBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.id[i] = 0;
    gl_.depth[i] = 1.0f;
    for (int c = 0; c < 4; ++c) gl_.color[i * 4 + c] = 0.0f;
  });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  EXPECT_EQ(r.visibility.missing, n);
  EXPECT_EQ(r.visibility.missing_hard, n);
  EXPECT_EQ(r.visibility.hard, n);
  EXPECT_EQ(r.visibility.mismatched, n);
  EXPECT_EQ(r.visibility.ambiguous, 0u);
  EXPECT_EQ(r.visibility.extra, 0u);
  EXPECT_EQ(r.visibility.wrong_primitive, 0u);
  EXPECT_EQ(r.visibility.status, Status::Fail);
  EXPECT_TRUE(kBackBlock.contains(r.visibility.worst));
  // Nothing else moves: those pixels simply leave the depth/shading comparison.
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared - n);
  EXPECT_EQ(r.depth.max_steps, 0.0);
  EXPECT_EQ(r.shading.max_abs, 0.0);
  EXPECT_EQ(r.depth.status, Status::Pass);
  EXPECT_EQ(r.shading.status, Status::Pass);
  EXPECT_EQ(r.status, Status::Fail);
}

TEST_F(CompareTest, SwappedIdsAreWrongPrimitive) {
  forBlock(kBackBlock, [&](int x, int y) { gl_.id[gl_.index(x, y)] = 4; });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  EXPECT_EQ(r.visibility.wrong_primitive, n);
  EXPECT_EQ(r.visibility.wrong_primitive_hard, n);  // one fragment there: depth_gap = inf
  EXPECT_EQ(r.visibility.missing, 0u);
  EXPECT_EQ(r.visibility.extra, 0u);
  EXPECT_EQ(r.visibility.status, Status::Fail);
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared - n);
  EXPECT_EQ(r.shading.max_abs, 0.0);
}

TEST_F(CompareTest, DrawnBackgroundIsExtra) {
  forBlock(kEmptyBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.id[i] = 7;
    gl_.depth[i] = 0.5f;
    gl_.color[i * 4] = 1.0f;
  });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(kEmptyBlock.size());
  EXPECT_EQ(r.visibility.extra, n);
  EXPECT_EQ(r.visibility.extra_hard, n);
  EXPECT_EQ(r.visibility.missing, 0u);
  EXPECT_EQ(r.visibility.wrong_primitive, 0u);
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared);
  EXPECT_TRUE(kEmptyBlock.contains(r.visibility.worst));
}

TEST_F(CompareTest, VisibilityThresholdsGiveWarnThenFail) {
  forBlock(kEmptyBlock, [&](int x, int y) { gl_.id[gl_.index(x, y)] = 7; });
  const auto n = static_cast<double>(kEmptyBlock.size());
  tol_.visibility = {n - 1, n};
  EXPECT_EQ(compare().visibility.status, Status::Warn);
  tol_.visibility = {n, n + 1};
  EXPECT_EQ(compare().visibility.status, Status::Pass);
  tol_.visibility = {0, n - 1};
  EXPECT_EQ(compare().visibility.status, Status::Fail);
}

TEST_F(CompareTest, DepthOffsetIsCaughtInExactlyItsBlock) {
  constexpr int kN = 100;  // steps, far above the fail threshold on a gentle slope
  forBlock(kBackBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + kN) / kD24);
  });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  EXPECT_EQ(r.depth.over_tolerance, n);
  EXPECT_EQ(r.depth.over_fail, n);
  EXPECT_EQ(r.depth.max_steps, kN);
  EXPECT_TRUE(kBackBlock.contains(r.depth.worst)) << r.depth.worst.x << "," << r.depth.worst.y;
  EXPECT_EQ(r.depth.worst_steps, kN);
  EXPECT_EQ(r.depth.status, Status::Fail);
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared);
  EXPECT_DOUBLE_EQ(r.depth.mean_steps, kN * static_cast<double>(n) / r.depth.compared);
  // Nearest-rank p99: N exactly when the block holds more than the top 1% of pixels.
  const auto rank = static_cast<std::uint64_t>(std::ceil(0.99 * r.depth.compared));
  EXPECT_EQ(r.depth.p99_steps, n > r.depth.compared - rank ? kN : 0.0);
  // The slope there is sqrt(20^2 + 10^2) steps/px: the allowance is that times the band.
  EXPECT_NEAR(r.depth.worst_allowance, std::hypot(20.0, 10.0) * r.depth.band_px,
              2.0 * r.depth.band_px);
  expectNoVisibilityChange(r);
  EXPECT_EQ(r.shading.max_abs, 0.0);
  EXPECT_EQ(r.status, Status::Fail);
}

TEST_F(CompareTest, DepthThresholdsGiveWarnThenFail) {
  auto offset = [&](int steps) {
    gl_ = ref_;
    forBlock(kBackBlock, [&](int x, int y) {
      const std::size_t i = gl_.index(x, y);
      gl_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + steps) / kD24);
    });
    return compare();
  };
  tol_.depth = {4.0, 16.0};
  EXPECT_EQ(offset(4).depth.status, Status::Pass);  // the allowance here is ~0.13 steps
  const PairResult warn = offset(5);
  EXPECT_EQ(warn.depth.status, Status::Warn);
  EXPECT_EQ(warn.depth.over_tolerance, static_cast<std::uint64_t>(kBackBlock.size()));
  EXPECT_EQ(warn.depth.over_fail, 0u);
  EXPECT_EQ(offset(16).depth.status, Status::Warn);
  EXPECT_EQ(offset(17).depth.status, Status::Fail);
  EXPECT_EQ(offset(-17).depth.status, Status::Fail);  // |dZ|: nearer is as wrong as farther
}

TEST_F(CompareTest, DepthToleranceGrowsWithTheSlope) {
  // The steep rectangle changes by 0.5 / (0.3 * 256) of the range per px in x.
  const double slope = 0.5 / (0.30 * kW) * kD24;
  const int steps = 200;
  forBlock(kSteepBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + steps) / kD24);
  });
  const PairResult r = compare();
  const double allowance = slope * r.depth.band_px;
  ASSERT_GT(allowance, steps + tol_.depth.fail);  // the premise of this test
  EXPECT_EQ(r.depth.over_tolerance, 0u);
  EXPECT_EQ(r.depth.max_steps, steps);
  EXPECT_TRUE(kSteepBlock.contains(r.depth.worst));
  EXPECT_NEAR(r.depth.worst_allowance, allowance, 0.01 * allowance);
  EXPECT_NEAR(r.depth.max_slope, slope, 0.01 * slope);

  // Without the slope allowance the same offset fails.
  tol_.depth_slope_factor = 0.0;
  EXPECT_EQ(compare().depth.over_fail, static_cast<std::uint64_t>(kSteepBlock.size()));
}

TEST_F(CompareTest, ColourOffsetIsCaughtInExactlyItsBlock) {
  constexpr int kN = 9;
  forBlock(kBackBlock, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4 + 1] += kN / 255.0f; });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  EXPECT_NEAR(r.shading.max_abs, kN, 1e-4);
  EXPECT_NEAR(r.shading.max_abs_rgba[1], kN, 1e-4);
  EXPECT_EQ(r.shading.max_abs_rgba[0], 0.0);
  EXPECT_EQ(r.shading.over_tolerance, n);
  EXPECT_EQ(r.shading.over_fail, n);
  EXPECT_TRUE(kBackBlock.contains(r.shading.worst));
  EXPECT_EQ(r.shading.status, Status::Fail);
  const double values = 4.0 * static_cast<double>(r.shading.compared);
  EXPECT_NEAR(r.shading.mean_abs, kN * static_cast<double>(n) / values, 1e-6);
  const double rmse = std::sqrt(kN * kN * static_cast<double>(n) / values);
  EXPECT_NEAR(r.shading.rmse, rmse, 1e-4);
  EXPECT_NEAR(r.shading.psnr_db, 20.0 * std::log10(255.0 / rmse), 1e-3);
  expectNoVisibilityChange(r);
  EXPECT_EQ(r.depth.max_steps, 0.0);
}

TEST_F(CompareTest, Rgba8ColourDifferencesAreExactIntegers) {
  auto quantize = [](Frame& f) {
    for (float& c : f.color) c = std::nearbyint(std::clamp(c, 0.0f, 1.0f) * 255.0f) / 255.0f;
  };
  quantize(ref_);
  gl_ = ref_;
  forBlock(kBackBlock, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4] -= 3.0f / 255.0f; });
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA8);
  const PairResult r = compare();
  EXPECT_EQ(r.shading.max_abs, 3.0);
  const auto rank = static_cast<std::uint64_t>(std::ceil(0.99 * r.shading.compared));
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  EXPECT_EQ(r.shading.p99_abs, n > r.shading.compared - rank ? 3.0 : 0.0);
  EXPECT_EQ(r.shading.over_fail, n);
}

TEST_F(CompareTest, D16DepthCountsD16Steps) {
  auto to16 = [](float z) { return static_cast<float>(std::nearbyint(z * 65535.0) / 65535.0); };
  for (float& z : ref_.depth) z = to16(z);
  gl_ = ref_;
  forBlock(kBackBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * 65535.0) + 3) / 65535.0);
  });
  tol_ = defaultTolerances(DepthFormat::D16, ColorFormat::RGBA32F);
  const PairResult r = compare();
  EXPECT_EQ(r.depth.max_steps, 3.0);
  EXPECT_EQ(r.depth.status, Status::Fail);
}

TEST_F(CompareTest, MismatchNearAnEdgeIsAmbiguousFarFromItHard) {
  const std::size_t near_px = ref_.index(80, 30);
  const std::size_t far_px = ref_.index(90, 40);
  ref_.edge_dist[near_px] = 0.001f;
  ref_.edge_dist[far_px] = 0.5f;
  gl_.id[near_px] = 0;
  gl_.id[far_px] = 0;
  const PairResult r = compare();
  EXPECT_EQ(r.visibility.missing, 2u);
  EXPECT_EQ(r.visibility.ambiguous, 1u);
  EXPECT_EQ(r.visibility.hard, 1u);
  EXPECT_EQ(r.visibility.worst.x, 90);
  EXPECT_EQ(r.visibility.worst.y, 40);
  EXPECT_FLOAT_EQ(static_cast<float>(r.visibility.worst_edge_dist), 0.5f);
}

TEST_F(CompareTest, BandComesFromBothSidesSubpixelBits) {
  // Two pixels just inside and just outside the band of an 8-bit vs 4-bit pair: edge_dist
  // is to the exact edge, which each side moves by at most its own snap.
  gl_.meta["subpixel_bits"] = 4;
  const double band = snapMovePx(4) + 16.0 * std::ldexp(1.0, -24) * kW;
  const std::size_t inside = ref_.index(80, 30);
  const std::size_t outside = ref_.index(90, 40);
  ref_.edge_dist[inside] = static_cast<float>(band * 0.99);
  ref_.edge_dist[outside] = static_cast<float>(band * 1.01);
  gl_.id[inside] = 0;
  gl_.id[outside] = 0;
  const PairResult r = compare();
  EXPECT_NEAR(r.visibility.band_px, band, 1e-12);
  EXPECT_EQ(r.visibility.ambiguous, 1u);
  EXPECT_EQ(r.visibility.hard, 1u);
  EXPECT_EQ(r.actual_subpixel_bits, 4);
  EXPECT_EQ(r.expected_subpixel_bits, 8);
  // With 8 bits on both sides the same pixel is hard.
  gl_.meta["subpixel_bits"] = 8;
  EXPECT_EQ(compare().visibility.hard, 2u);
}

TEST_F(CompareTest, GlAgainstGlUsesTheReferenceUncertainty) {
  Frame a = gl_;
  Frame b = gl_;
  a.meta["subpixel_bits"] = 8;
  b.meta["subpixel_bits"] = 4;
  const double band = std::max(snapMovePx(8), snapMovePx(4)) + 16.0 * std::ldexp(1.0, -24) * kW;
  const std::size_t inside = ref_.index(80, 30);
  const std::size_t outside = ref_.index(90, 40);
  ref_.edge_dist[inside] = static_cast<float>(band * 0.99);
  ref_.edge_dist[outside] = static_cast<float>(band * 1.01);
  b.id[inside] = 0;
  b.id[outside] = 0;
  const PairResult r = compareFrames(a, b, ref_, tol_);
  EXPECT_NEAR(r.visibility.band_px, band, 1e-12);
  EXPECT_TRUE(r.visibility.uncertainty_available);
  EXPECT_EQ(r.visibility.ambiguous, 1u);
  EXPECT_EQ(r.visibility.hard, 1u);
}

TEST_F(CompareTest, WithoutUncertaintyEveryMismatchIsHard) {
  Frame plain = ref_;
  plain.clearUncertainty();
  ref_.edge_dist[ref_.index(80, 30)] = 0.0f;
  gl_.id[ref_.index(80, 30)] = 0;
  const PairResult r = compareFrames(plain, gl_, plain, tol_);
  EXPECT_FALSE(r.visibility.uncertainty_available);
  EXPECT_EQ(r.visibility.hard, 1u);
}

TEST_F(CompareTest, DepthTieExcusesWrongPrimitiveOnlyWithinTheDepthTolerance) {
  const std::size_t tie = ref_.index(80, 30);
  const std::size_t clear_win = ref_.index(90, 40);
  ref_.depth_gap[tie] = 0.5f;
  ref_.depth_gap[clear_win] = 1000.0f;
  gl_.id[tie] = 3;
  gl_.id[clear_win] = 3;
  const PairResult r = compare();
  EXPECT_EQ(r.visibility.wrong_primitive, 2u);
  EXPECT_EQ(r.visibility.ambiguous, 1u);
  EXPECT_EQ(r.visibility.ambiguous_by_depth_gap, 1u);
  EXPECT_EQ(r.visibility.wrong_primitive_hard, 1u);
  EXPECT_EQ(r.visibility.worst.x, 90);
  // A gap is not an excuse for a missing pixel.
  gl_.id[tie] = 0;
  EXPECT_EQ(compare().visibility.missing_hard, 1u);
}

// rgba32f overflow the reference predicts (both sides the same infinity) agrees; an
// infinity of the other sign, or NaN on both sides, does not.
TEST_F(CompareTest, TheSameInfinityOnBothSidesAgrees) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t i = gl_.index(75, 30) * 4 + 1;
  ref_.color[i] = gl_.color[i] = inf;
  PairResult r = compare();
  EXPECT_EQ(r.shading.nonfinite, 0u);
  EXPECT_EQ(r.shading.status, Status::Pass);
  EXPECT_EQ(r.nonfinite_actual.inf[1], 1u);  // still tallied
  gl_.color[i] = -inf;
  r = compare();
  EXPECT_EQ(r.shading.nonfinite, 1u);
  EXPECT_EQ(r.shading.status, Status::Fail);
  ref_.color[i] = gl_.color[i] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(compare().shading.status, Status::Fail);
}

TEST_F(CompareTest, NonFiniteValuesAreCountedNeverCompared) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  gl_.color[gl_.index(75, 30) * 4 + 0] = nan;
  gl_.color[gl_.index(76, 30) * 4 + 0] = nan;
  gl_.color[gl_.index(77, 30) * 4 + 2] = -inf;
  gl_.depth[gl_.index(78, 30)] = inf;
  gl_.depth[gl_.index(79, 30)] = nan;
  // Background on both sides: counted, and not the clear colour (a cleared-buffer failure).
  gl_.color[gl_.index(kEmptyBlock.x0, kEmptyBlock.y0) * 4 + 1] = inf;
  ref_.color[ref_.index(80, 31) * 4 + 3] = nan;
  const PairResult r = compare();
  EXPECT_EQ(r.nonfinite_actual.nan[0], 2u);
  EXPECT_EQ(r.nonfinite_actual.inf[1], 1u);
  EXPECT_EQ(r.nonfinite_actual.inf[2], 1u);
  EXPECT_EQ(r.nonfinite_actual.inf[4], 1u);
  EXPECT_EQ(r.nonfinite_actual.nan[4], 1u);
  EXPECT_EQ(r.nonfinite_actual.total(), 6u);
  EXPECT_EQ(r.nonfinite_expected.nan[3], 1u);
  EXPECT_EQ(r.nonfinite_expected.total(), 1u);
  EXPECT_EQ(r.shading.nonfinite, 4u);  // three actual pixels and one expected pixel
  EXPECT_EQ(r.shading.cleared_mismatched, 1u);
  EXPECT_EQ(r.shading.over_fail, 5u);
  EXPECT_EQ(r.shading.status, Status::Fail);
  EXPECT_EQ(r.shading.max_abs, 0.0);  // the finite pixels still agree
  EXPECT_EQ(r.shading.worst.y, 30);
  EXPECT_EQ(r.shading.worst.x, 75);
  EXPECT_EQ(r.depth.nonfinite, 2u);
  EXPECT_EQ(r.depth.over_fail, 2u);
  EXPECT_EQ(r.depth.max_steps, 0.0);
  EXPECT_EQ(r.depth.worst.x, 78);
  EXPECT_TRUE(std::isnan(r.depth.worst_steps));
  EXPECT_EQ(r.status, Status::Fail);
}

TEST_F(CompareTest, ClassMapsHoldThePerPixelResults) {
  constexpr int kN = 50;
  forBlock(kBackBlock, [&](int x, int y) {
    const std::size_t i = gl_.index(x, y);
    gl_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + kN) / kD24);
  });
  const std::size_t missing = gl_.index(kBackBlock.x0 - 5, kBackBlock.y0);
  gl_.id[missing] = 0;
  gl_.color[gl_.index(60, 60) * 4 + 2] += 2.0f / 255.0f;
  ClassMaps maps;
  const PairResult with_maps = compare(&maps);
  const PairResult without = compare();
  EXPECT_EQ(with_maps.depth.over_tolerance, without.depth.over_tolerance);
  EXPECT_EQ(with_maps.shading.max_abs, without.shading.max_abs);
  ASSERT_EQ(maps.pixel_class.size(), static_cast<std::size_t>(kW * kH));
  EXPECT_EQ(maps.pixel_class[missing], PixelClass::MissingHard);
  EXPECT_EQ(maps.pixel_class[gl_.index(0, 0)], PixelClass::Background);
  EXPECT_EQ(maps.pixel_class[gl_.index(kBackBlock.x0, kBackBlock.y0)], PixelClass::Match);
  EXPECT_EQ(maps.depth_steps[gl_.index(kBackBlock.x0, kBackBlock.y0)], kN);
  EXPECT_EQ(maps.depth_steps[gl_.index(kBackBlock.x0 - 1, kBackBlock.y0)], 0.0f);
  EXPECT_NEAR(maps.shading_abs[gl_.index(60, 60)], 2.0f, 1e-4);
  // Tolerances are kept where the error is over warn (where the allowance decides).
  EXPECT_GT(maps.depth_tolerance[gl_.index(kBackBlock.x0, kBackBlock.y0)], tol_.depth.warn);
  EXPECT_EQ(maps.depth_tolerance[gl_.index(60, 60)], 0.0f);
  EXPECT_GT(maps.shading_tolerance[gl_.index(60, 60)], tol_.shading.warn);
  EXPECT_EQ(maps.shading_tolerance[gl_.index(kBackBlock.x0, kBackBlock.y0)], 0.0f);
}

// Maps reserved ahead (reserveMaps(), as `compare` does while it reads) hold what it left
// there, here garbage; the comparison's maps must be the same as from empty buffers.
TEST_F(CompareTest, ReservedMapsGiveTheSameMaps) {
  gl_.id[gl_.index(kBackBlock.x0 - 5, kBackBlock.y0)] = 0;
  gl_.color[gl_.index(60, 60) * 4 + 2] += 2.0f / 255.0f;
  ClassMaps fresh;
  compare(&fresh);
  ClassMaps reserved;
  reserveMaps(reserved, kW, kH);
  ASSERT_EQ(reserved.pixel_class.size(), static_cast<std::size_t>(kW * kH));
  std::fill(reserved.pixel_class.begin(), reserved.pixel_class.end(), PixelClass::ExtraHard);
  for (auto* m : {&reserved.depth_steps, &reserved.depth_tolerance, &reserved.shading_abs,
                  &reserved.shading_tolerance})
    std::fill(m->begin(), m->end(), 1234.5f);
  compare(&reserved);
  EXPECT_EQ(reserved.pixel_class, fresh.pixel_class);
  EXPECT_EQ(reserved.depth_steps, fresh.depth_steps);
  EXPECT_EQ(reserved.depth_tolerance, fresh.depth_tolerance);
  EXPECT_EQ(reserved.shading_abs, fresh.shading_abs);
  EXPECT_EQ(reserved.shading_tolerance, fresh.shading_tolerance);
}

TEST_F(CompareTest, SizeMismatchIsAnInputErrorNamingBothSides) {
  Frame small = testing::renderRects(128, 128, testing::defaultRects(128, 128));
  small.meta["backend"] = "gl:small";
  try {
    compareFrames(ref_, small, ref_, tol_);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("256x256"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gl:small"), std::string::npos) << e.what();
  }
  try {
    checkSameSize(ref_, small, "out/ref", "out/gl");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("out/ref"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("out/gl"), std::string::npos) << e.what();
  }
  Frame broken = gl_;
  broken.color.resize(10);
  EXPECT_THROW(compareFrames(ref_, broken, ref_, tol_), InputError);
  gl_.meta["subpixel_bits"] = "eight";
  EXPECT_THROW(compare(), InputError);
}

TEST_F(CompareTest, FormatsComeFromTheFramesDrawFacts) {
  EXPECT_EQ(tolerancesForFrames(ref_, gl_).depth_format, DepthFormat::D24);
  gl_.drawn.color_format = ColorFormat::RGBA8;
  ref_.drawn.color_format = ColorFormat::RGBA8;
  ref_.drawn.depth_format = DepthFormat::D16;
  gl_.drawn.depth_format.reset();  // a frame that does not say takes the other's
  const Tolerances t = tolerancesForFrames(ref_, gl_);
  EXPECT_EQ(t.depth_format, DepthFormat::D16);
  EXPECT_EQ(t.color_format, ColorFormat::RGBA8);
  EXPECT_EQ(compareFrames(ref_, gl_).tolerances.depth_format, DepthFormat::D16);
  gl_.drawn.depth_format = DepthFormat::D24;
  EXPECT_THROW(tolerancesForFrames(ref_, gl_), InputError);
  // Linear filtering widens the shading allowance only on a textured material.
  gl_.drawn = ref_.drawn;
  EXPECT_EQ(tolerancesForFrames(ref_, gl_).texture_weight_error, 0.0);
  gl_.drawn.texture_filter = TextureFilter::Linear;
  EXPECT_EQ(tolerancesForFrames(ref_, gl_).texture_weight_error, 0.0);
  gl_.drawn.textured = true;
  const Tolerances linear = tolerancesForFrames(ref_, gl_);
  EXPECT_GT(linear.texture_weight_error, 0.0);
  EXPECT_EQ(linear.texture_weight_error,
            defaultTolerances(DepthFormat::D16, ColorFormat::RGBA8, DrawnWith{true})
                .texture_weight_error);
}

// The comparator has a vector path (whole chunks of matching pixels, no maps) and a
// general path (everything else, and every pixel when maps are asked for). On a noisy
// frame with every class, an odd width and NaNs, both must give the same answer.
void expectSameResults(const PairResult& fast, const PairResult& general) {
  EXPECT_EQ(fast.status, general.status);
  EXPECT_EQ(fast.visibility.missing_hard, general.visibility.missing_hard);
  EXPECT_EQ(fast.visibility.extra_hard, general.visibility.extra_hard);
  EXPECT_EQ(fast.visibility.wrong_primitive_hard, general.visibility.wrong_primitive_hard);
  EXPECT_EQ(fast.visibility.ambiguous, general.visibility.ambiguous);
  EXPECT_EQ(fast.depth.compared, general.depth.compared);
  EXPECT_EQ(fast.depth.max_steps, general.depth.max_steps);
  EXPECT_NEAR(fast.depth.mean_steps, general.depth.mean_steps, 1e-9 * general.depth.mean_steps);
  EXPECT_EQ(fast.depth.p99_steps, general.depth.p99_steps);
  EXPECT_EQ(fast.depth.over_tolerance, general.depth.over_tolerance);
  EXPECT_EQ(fast.depth.over_fail, general.depth.over_fail);
  EXPECT_EQ(fast.depth.nonfinite, general.depth.nonfinite);
  EXPECT_EQ(fast.depth.worst.x, general.depth.worst.x);
  EXPECT_EQ(fast.depth.worst.y, general.depth.worst.y);
  EXPECT_EQ(fast.shading.compared, general.shading.compared);
  EXPECT_EQ(fast.shading.max_abs, general.shading.max_abs);
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(fast.shading.max_abs_rgba[c], general.shading.max_abs_rgba[c]);
  EXPECT_NEAR(fast.shading.mean_abs, general.shading.mean_abs, 1e-6 * general.shading.mean_abs);
  EXPECT_NEAR(fast.shading.rmse, general.shading.rmse, 1e-6 * general.shading.rmse);
  EXPECT_EQ(fast.shading.p99_abs, general.shading.p99_abs);
  EXPECT_EQ(fast.shading.over_tolerance, general.shading.over_tolerance);
  EXPECT_EQ(fast.shading.over_fail, general.shading.over_fail);
  EXPECT_EQ(fast.shading.nonfinite, general.shading.nonfinite);
  EXPECT_EQ(fast.shading.worst.x, general.shading.worst.x);
  EXPECT_EQ(fast.shading.worst.y, general.shading.worst.y);
  EXPECT_EQ(fast.nonfinite_actual.nan, general.nonfinite_actual.nan);
  EXPECT_EQ(fast.nonfinite_actual.inf, general.nonfinite_actual.inf);
  EXPECT_EQ(fast.nonfinite_expected.nan, general.nonfinite_expected.nan);
  const auto hf = fast.shading.histogram.coarse(fast.shading.max_abs);
  const auto hg = general.shading.histogram.coarse(general.shading.max_abs);
  EXPECT_EQ(hf.counts, hg.counts);
  EXPECT_EQ(fast.depth.histogram.count(), general.depth.histogram.count());
}

class FastPathTest : public ::testing::TestWithParam<std::tuple<DepthFormat, ColorFormat>> {};

TEST_P(FastPathTest, VectorAndGeneralPathsAgree) {
  // Plain variables, not a structured binding: the lambda below captures them.
  const DepthFormat depth_format = std::get<0>(GetParam());
  const ColorFormat color_format = std::get<1>(GetParam());
  constexpr int kOddW = 251;
  constexpr int kOddH = 97;
  Frame ref = testing::renderRects(kOddW, kOddH, testing::defaultRects(kOddW, kOddH));
  const double steps = depthStepsPerUnit(depth_format);
  auto requantize = [&](Frame& f) {
    if (depth_format != DepthFormat::D32F)
      for (float& z : f.depth) z = static_cast<float>(std::nearbyint(z * steps) / steps);
    if (color_format == ColorFormat::RGBA8)
      for (float& c : f.color) c = std::nearbyint(std::clamp(c, 0.0f, 1.0f) * 255.0f) / 255.0f;
  };
  requantize(ref);
  Frame gl = ref;
  gl.clearUncertainty();
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> dz(-30, 30);
  std::uniform_real_distribution<float> dc(-6.0f / 255.0f, 6.0f / 255.0f);
  std::uniform_int_distribution<int> pick(0, 400);
  for (std::size_t i = 0; i < gl.pixelCount(); ++i) {
    if (gl.id[i] == 0) continue;
    gl.depth[i] = static_cast<float>(gl.depth[i] + dz(rng) / steps);
    for (int c = 0; c < 4; ++c) gl.color[i * 4 + c] += dc(rng);
    const int p = pick(rng);  // sprinkle every other class
    if (p == 0) gl.id[i] = 0;
    if (p == 1) gl.id[i] = gl.id[i] % 6 + 1;
    if (p == 2) gl.color[i * 4 + 1] = std::numeric_limits<float>::quiet_NaN();
    if (p == 3) gl.depth[i] = std::numeric_limits<float>::infinity();
    if (p == 4) gl.depth[i] += 5000.0f / static_cast<float>(steps);
  }
  gl.id[gl.index(3, kOddH - 2)] = 9;  // extra
  requantize(gl);
  const Tolerances tol = defaultTolerances(depth_format, color_format);
  ClassMaps maps;
  const PairResult general = compareFrames(ref, gl, ref, tol, &maps);
  const PairResult fast = compareFrames(ref, gl, ref, tol);
  ASSERT_GT(general.visibility.hard, 0u);
  ASSERT_GT(general.depth.over_fail, 0u);
  ASSERT_GT(general.shading.nonfinite, 0u);
  ASSERT_GT(general.shading.mean_abs, 0.0);
  expectSameResults(fast, general);
}

INSTANTIATE_TEST_SUITE_P(
    Formats, FastPathTest,
    ::testing::Combine(::testing::Values(DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F),
                       ::testing::Values(ColorFormat::RGBA32F, ColorFormat::RGBA8)));

TEST(CompareEdgeCases, DegenerateFramesNeverCrash) {
  const float clear[4] = {0, 0, 0, 0};
  const Tolerances tol = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  Frame empty;
  empty.allocate(0, 0, clear, 1.0f, true);
  PairResult r = compareFrames(empty, empty, empty, tol);
  EXPECT_EQ(r.status, Status::Pass);
  EXPECT_EQ(r.pixels, 0u);

  Frame one;
  one.allocate(1, 1, clear, 1.0f, true);
  one.id[0] = 0xFFFFFFFFu;
  one.depth[0] = 0.5f;
  Frame other = one;
  other.depth[0] = 1e30f;  // absurd but finite
  other.color[0] = -1e30f;
  one.edge_dist[0] = std::numeric_limits<float>::quiet_NaN();
  one.depth_gap[0] = std::numeric_limits<float>::quiet_NaN();
  ClassMaps maps;
  r = compareFrames(one, other, one, tol, &maps);
  EXPECT_EQ(r.depth.status, Status::Fail);  // depth_slope 0: the reference says it is flat
  EXPECT_EQ(r.shading.status, Status::Fail);
  one.depth_slope[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(compareFrames(one, other, one, tol).depth.status, Status::Fail);  // NaN excuses nothing
  one.depth_slope[0] = 0.0f;
  other.id[0] = 0;
  r = compareFrames(one, other, one, tol);
  EXPECT_EQ(r.visibility.hard, 1u);  // NaN edge_dist excuses nothing
  other = one;
  other.id[0] = 2;
  r = compareFrames(one, other, one, tol);
  EXPECT_EQ(r.visibility.wrong_primitive_hard, 1u);  // NaN depth_gap excuses nothing

  // Every value NaN: counted, classified, no crash.
  Frame nan_frame = one;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::fill(nan_frame.color.begin(), nan_frame.color.end(), nan);
  std::fill(nan_frame.depth.begin(), nan_frame.depth.end(), nan);
  r = compareFrames(one, nan_frame, one, tol);
  EXPECT_EQ(r.nonfinite_actual.total(), 5u);
  EXPECT_EQ(r.status, Status::Fail);
}

// Nearest texture filtering: a sample within the slope band of a texel boundary may take
// the texel across it; the reference says so at the pixel (texel_dist) with the colour
// change that makes (texel_alt). Exactly that much passes there; more, or the same change
// at a pixel whose boundary is farther than the band, fails.
TEST_F(CompareTest, TexelChoiceAllowsTheOtherTexelOnlyWithinTheBand) {
  const double band = baseline_.depth.band_px;  // the slope band
  const Block near_edge{70, 25, 74, 29};
  const Block far_edge{80, 25, 84, 29};
  const float alt = 40.0f;  // units
  forBlock(near_edge, [&](int x, int y) {
    ref_.texel_dist[ref_.index(x, y)] = static_cast<float>(band * 0.99);
    ref_.texel_alt[ref_.index(x, y)] = alt;
  });
  forBlock(far_edge, [&](int x, int y) {
    ref_.texel_dist[ref_.index(x, y)] = static_cast<float>(band * 1.01);
    ref_.texel_alt[ref_.index(x, y)] = alt;
  });
  auto offset = [&](const Block& b, float units) {
    forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4] += units / 255.0f; });
  };
  offset(near_edge, alt);  // the other texel, exactly
  PairResult r = compare();
  EXPECT_EQ(r.shading.status, Status::Pass);
  EXPECT_EQ(r.shading.texel_choice, static_cast<std::uint64_t>(near_edge.size()));
  offset(near_edge, 1.0f);  // one unit beyond it: every pixel fails
  r = compare();
  EXPECT_EQ(r.shading.over_fail, static_cast<std::uint64_t>(near_edge.size()));
  offset(near_edge, -1.0f);
  offset(far_edge, alt);  // the boundary is farther than the band: not a legal choice
  r = compare();
  EXPECT_EQ(r.shading.over_fail, static_cast<std::uint64_t>(far_edge.size()));
  EXPECT_TRUE(far_edge.contains(r.shading.worst));
  // The texture does not change alpha.
  offset(far_edge, -alt);
  forBlock(near_edge, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4 + 3] += 5.0f / 255.0f; });
  EXPECT_EQ(compare().shading.over_fail, static_cast<std::uint64_t>(near_edge.size()));
}

// Linear filtering: quantised weights may move the value by 2^-7 of the footprint's colour
// range (texel_alt) and the 8-bit filtered texel by one unit times the light on it
// (texel_gain). Exactly that passes; a unit more fails; without linear filtering (the
// frames say nearest) neither term applies.
TEST_F(CompareTest, LinearFilteringAllowsTheFootprintAndTheFilteredTexelsRounding) {
  const Block b = kBackBlock;
  forBlock(b, [&](int x, int y) {
    ref_.texel_alt[ref_.index(x, y)] = 128.0f;  // 2^-7 of it: 1 unit
    ref_.texel_gain[ref_.index(x, y)] = 1.5f;   // 1.5 units
  });
  DrawnWith linear;
  linear.linear_textures = true;
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F, linear);
  const double allowed = 128.0 * tol_.texture_weight_error + 1.5 * tol_.texture_rounding_units;
  ASSERT_DOUBLE_EQ(allowed, 2.5);
  const auto offset = static_cast<float>(allowed + tol_.shading.fail * 0.9);
  forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4] += offset / 255.0f; });
  EXPECT_EQ(compare().shading.over_fail, 0u);
  forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4] += 1.0f / 255.0f; });
  EXPECT_EQ(compare().shading.over_fail, static_cast<std::uint64_t>(b.size()));
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);  // not linear
  forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4] -= 1.0f / 255.0f; });
  EXPECT_EQ(compare().shading.over_fail, static_cast<std::uint64_t>(b.size()));
}

// Linear filtering at a sample float32 interpolation may move (texel_reach texels): the
// colour range of the footprints within the reach (texel_alt) times min(1, reach) more.
// With reach 0.25 and texel_alt 40: (2^-7 + 0.25) * 40 = 10.3125 units pass, a unit more
// fails; a reach above 1 texel never allows more than the whole range (plus the weights').
TEST_F(CompareTest, TexelReachWidensLinearFilteringByItsShare) {
  const Block b = kBackBlock;
  DrawnWith linear;
  linear.linear_textures = true;
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F, linear);
  auto run = [&](float reach, double units) {
    forBlock(b, [&](int x, int y) {
      const std::size_t i = ref_.index(x, y);
      ref_.texel_alt[i] = 40.0f;
      ref_.texel_reach[i] = reach;
      gl_.color[i * 4] = ref_.color[i * 4] + static_cast<float>(units / 255.0);
    });
    return compare().shading.over_fail;
  };
  const auto n = static_cast<std::uint64_t>(b.size());
  const double fail = tol_.shading.fail;
  const double share = (tol_.texture_weight_error + 0.25) * 40.0;
  EXPECT_EQ(run(0.25f, share + fail * 0.9), 0u);
  EXPECT_EQ(run(0.25f, share + fail + 1.0), n);
  EXPECT_EQ(run(0.0f, share + fail * 0.9), n) << "without the reach";
  const double whole = (tol_.texture_weight_error + 1.0) * 40.0;
  EXPECT_EQ(run(1e6f, whole + fail * 0.9), 0u);
  EXPECT_EQ(run(1e6f, whole + fail + 1.0), n);
}

// shade_reach (docs/tolerances.md (b)): the attribute-plane term is the slope band times the
// larger of the neighbours' gradient and the reference's shade_reach, on R, G and B. With
// 1e5 units/px the band's share passes on green, a percent more (plus fail) fails; without
// the channel, or on alpha (no interpolated attribute moves it), the same error fails.
TEST_F(CompareTest, ShadeReachWidensTheAttributePlaneTerm) {
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  const Block b = kBackBlock;
  const double band = compare().depth.band_px;
  ASSERT_GT(band, 0.0);
  const double share = tol_.shading_slope_factor * band * 1e5;
  const Frame original = gl_;
  auto run = [&](float reach, double units, int channel) {
    return overFailWith(original, b, &Frame::shade_reach, reach, units, channel);
  };
  const auto n = static_cast<std::uint64_t>(b.size());
  const double fail = tol_.shading.fail;
  EXPECT_EQ(run(1e5f, share, 1), 0u);
  EXPECT_EQ(run(1e5f, 1.01 * share + fail + 1.0, 1), n);
  EXPECT_EQ(run(0.0f, share, 1), n) << "without shade_reach";
  EXPECT_EQ(run(1e5f, share, 3), n) << "alpha";
}

// normal_reach (docs/tolerances.md (a)): added as it stands to R, G and B, not to alpha.
TEST_F(CompareTest, NormalReachWidensRgbByItsUnits) {
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  const Block b = kBackBlock;
  const Frame original = gl_;
  auto run = [&](float reach, double units, int channel) {
    return overFailWith(original, b, &Frame::normal_reach, reach, units, channel);
  };
  const auto n = static_cast<std::uint64_t>(b.size());
  const double fail = tol_.shading.fail;
  EXPECT_EQ(run(40.0f, 40.0, 2), 0u);
  EXPECT_EQ(run(40.0f, 40.0 + fail + 2.0, 2), n);
  EXPECT_EQ(run(0.0f, 40.0, 2), n) << "without normal_reach";
  EXPECT_EQ(run(40.0f, 40.0, 3), n) << "alpha";
}

// rgba8 blending: each blended fragment may round its way (2 units, docs/tolerances.md).
TEST_F(CompareTest, Rgba8BlendsEachAddTheirRounding) {
  tol_ = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA8);
  for (Frame* f : {&ref_, &gl_})
    for (float& c : f->color) c = std::nearbyint(c * 255.0f) / 255.0f;  // 8-bit values
  const Block b = kBackBlock;
  forBlock(b, [&](int x, int y) { ref_.blend_count[ref_.index(x, y)] = 3.0f; });
  // Up to 1 (the final rounding) + 2 x 3 units passes; 8 fails.
  forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4 + 1] += 7.0f / 255.0f; });
  EXPECT_EQ(compare().shading.status, Status::Pass);
  forBlock(b, [&](int x, int y) { gl_.color[gl_.index(x, y) * 4 + 1] += 1.0f / 255.0f; });
  const PairResult r = compare();
  EXPECT_EQ(r.shading.over_fail, static_cast<std::uint64_t>(b.size()));
  // In rgba32f blends add no allowance (float arithmetic: the relative term covers them).
  EXPECT_EQ(defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F).blend_rounding_units, 0.0);
}

// A blended pixel whose lower fragments may legally differ (an edge within the band, or a
// blended fragment's depth test within tolerance of flipping) is not held to the depth
// and shading tolerances; just outside either condition it is.
TEST_F(CompareTest, BlendedPixelsWithAnUncertainFragmentSetAreExcused) {
  const double band = baseline_.visibility.band_px;
  const Block edge{70, 25, 74, 29};
  const Block tie{80, 25, 84, 29};
  const Block neither{90, 25, 94, 29};
  const double tie_limit = 2.0 * tol_.depth.fail;  // blend_slope 0
  forBlock(edge, [&](int x, int y) {
    ref_.blend_count[ref_.index(x, y)] = 1.0f;
    ref_.edge_dist[ref_.index(x, y)] = static_cast<float>(band * 0.99);
  });
  forBlock(tie, [&](int x, int y) {
    ref_.blend_count[ref_.index(x, y)] = 2.0f;
    ref_.blend_gap[ref_.index(x, y)] = static_cast<float>(tie_limit * 0.99);
  });
  forBlock(neither, [&](int x, int y) {
    const std::size_t i = ref_.index(x, y);
    ref_.blend_count[i] = 1.0f;
    ref_.edge_dist[i] = static_cast<float>(band * 1.01);
    ref_.blend_gap[i] = static_cast<float>(tie_limit * 1.01);
  });
  for (const Block& b : {edge, tie, neither})
    forBlock(b, [&](int x, int y) {
      const std::size_t i = gl_.index(x, y);
      gl_.color[i * 4 + 2] += 12.0f / 255.0f;
      gl_.depth[i] = quantized(gl_.depth[i], 500.0);
    });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(neither.size());
  EXPECT_EQ(r.shading.over_fail, n);
  EXPECT_EQ(r.depth.over_fail, n);
  EXPECT_EQ(r.shading.blend_uncertain, 2 * n);
  EXPECT_EQ(r.depth.blend_uncertain, 2 * n);
  EXPECT_TRUE(neither.contains(r.shading.worst));
  // Without a blend the same pixels are plain opaque ones: nothing is excused.
  forBlock(edge, [&](int x, int y) { ref_.blend_count[ref_.index(x, y)] = 0.0f; });
  EXPECT_EQ(compare().shading.over_fail, 2 * n);
}

// A visible fragment that writes no depth over a fragment GL leaves to the driver (edge_dist
// 0: a line's end) shows the same primitive whether or not that fragment was drawn; a driver
// that left it out holds the clear depth there. That is excused; the same depth away from
// the band, another depth than the clear one, or a fragment only the driver drew (the
// reference's clear depth) is not (campaign s20261355 scene 00027).
TEST_F(CompareTest, ADriverMayLeaveOutAnOptionalFragmentUnderOneThatWritesNoDepth) {
  ref_.meta["clear_depth"] = 1.0;
  const double band = baseline_.visibility.band_px;
  const Block optional{70, 25, 74, 29};
  const Block away{80, 25, 84, 29};
  const Block other{90, 25, 94, 29};
  forBlock(optional, [&](int x, int y) { ref_.edge_dist[ref_.index(x, y)] = 0.0f; });
  forBlock(away, [&](int x, int y) {
    ref_.edge_dist[ref_.index(x, y)] = static_cast<float>(band * 1.01);
  });
  forBlock(other, [&](int x, int y) { ref_.edge_dist[ref_.index(x, y)] = 0.0f; });
  for (const Block& b : {optional, away})
    forBlock(b, [&](int x, int y) { gl_.depth[gl_.index(x, y)] = 1.0f; });
  forBlock(other, [&](int x, int y) {
    gl_.depth[gl_.index(x, y)] = quantized(gl_.depth[gl_.index(x, y)], 5000.0);
  });
  const auto n = static_cast<std::uint64_t>(optional.size());
  PairResult r = compare();
  EXPECT_EQ(r.depth.over_fail, 2 * n) << "away from the band and a depth other than the clear";
  EXPECT_EQ(r.depth.blend_uncertain, n);
  // The other way round: the reference kept the clear depth, the driver drew a fragment.
  std::swap(ref_.depth, gl_.depth);
  r = compare();
  EXPECT_EQ(r.depth.blend_uncertain, 0u);
  EXPECT_EQ(r.depth.over_fail, 3 * n);
  // Frames that do not say their clear depth excuse nothing.
  std::swap(ref_.depth, gl_.depth);
  ref_.meta.erase("clear_depth");
  EXPECT_EQ(compare().depth.over_fail, 3 * n);
}

// The depth slope allowance comes from the reference's depth_slope at the pixel, however
// few pixels the primitive shows: a one-pixel-wide sliver gets its true steep slope.
TEST(DepthSlope, TheAllowanceIsTheReferencesSlopeAtThePixel) {
  Frame f;
  const float clear[4] = {0, 0, 0, 0};
  f.allocate(64, 16, clear, 1.0f, true);
  f.meta = {{"backend", "ref"}, {"subpixel_bits", 8}};
  const double slope = std::hypot(3000.0, 40000.0);  // steps/px
  for (int x = 2; x < 60; ++x) {                     // a one-pixel row
    const std::size_t i = f.index(x, 7);
    f.id[i] = 7;
    f.depth[i] = static_cast<float>(std::nearbyint(2e6 + 3000.0 * x) / kD24);
    f.color[i * 4 + 3] = 1.0f;
    f.depth_slope[i] = static_cast<float>(slope);
  }
  Frame g = f;
  g.clearUncertainty();
  const Tolerances tol = tolerancesForFrames(f, g);
  const std::size_t probe = f.index(31, 7);
  const double allowance = slope * compareFrames(f, f, f, tol).depth.band_px;
  auto off = [&](double steps) {
    g.depth[probe] = static_cast<float>((std::nearbyint(f.depth[probe] * kD24) + steps) / kD24);
    return compareFrames(f, g, f, tol);
  };
  const PairResult within = off(std::floor(tol.depth.warn + allowance));
  EXPECT_EQ(within.depth.status, Status::Pass);
  EXPECT_NEAR(within.depth.worst_allowance, allowance, 1e-3 * allowance);
  EXPECT_EQ(off(std::ceil(tol.depth.fail + allowance) + 1.0).depth.over_fail, 1u);
}

// A reference frame with its uncertainty channels and an llvmpipe frame, w x h, cleared to
// transparent black at depth 1: the two sides of a driver-against-driver comparison whose
// uncertainty frame is the reference.
struct DriverPairFrames {
  Frame ref;
  Frame gl;
};
DriverPairFrames driverPairFrames(int w, int h, int subpixel_bits) {
  const float clear[4] = {0, 0, 0, 0};
  DriverPairFrames f;
  f.ref.allocate(w, h, clear, 1.0f, true);
  f.ref.meta = {{"backend", "ref"}, {"subpixel_bits", subpixel_bits}};
  f.gl.allocate(w, h, clear, 1.0f, false);
  f.gl.meta = {{"backend", "gl:egl:llvmpipe"}, {"subpixel_bits", subpixel_bits}};
  return f;
}

// Driver against driver with the reference as the uncertainty frame: where both drivers
// cover a pixel with primitive 7 but the reference shows primitive 9 there (an edge the
// reference snapped the other way), primitive 7's slope comes from the neighbour where the
// reference shows 7; with no such neighbour nothing is excused.
TEST(DepthSlope, DriverAgainstDriverTakesThePrimitivesSlopeFromANeighbour) {
  auto [ref, gl] = driverPairFrames(64, 16, 8);
  const double slope = 40000.0;  // steps/px
  auto depthAt = [](int x) { return static_cast<float>(std::nearbyint(2e6 + 40000.0 * x) / kD24); };
  for (int x = 2; x <= 60; ++x) {
    const std::size_t i = ref.index(x, 7);
    gl.id[i] = 7;
    gl.depth[i] = depthAt(x);
    gl.color[i * 4 + 3] = 1.0f;
    ref.id[i] = x < 60 ? 7 : 9;  // the reference shows another primitive at x = 60
    ref.depth[i] = gl.depth[i];
    ref.color[i * 4 + 3] = 1.0f;
    ref.depth_slope[i] = x < 60 ? static_cast<float>(slope) : 0.0f;
  }
  const Tolerances tol = tolerancesForFrames(gl, gl);
  const double band = compareFrames(gl, gl, ref, tol).depth.band_px;
  const double allowance = slope * band;
  ASSERT_GT(allowance, tol.depth.fail + 2.0) << "the test needs a slope allowance to show";
  Frame other = gl;
  const std::size_t probe = ref.index(60, 7);
  other.depth[probe] = static_cast<float>(
      (std::nearbyint(gl.depth[probe] * kD24) + std::floor(tol.depth.warn + allowance)) / kD24);
  const PairResult within = compareFrames(gl, other, ref, tol);
  EXPECT_EQ(within.depth.status, Status::Pass) << "allowance " << allowance;
  // The same pixel alone, no neighbour where the reference shows primitive 7: strict.
  for (int x = 2; x < 60; ++x) ref.id[ref.index(x, 7)] = 9;
  EXPECT_EQ(compareFrames(gl, other, ref, tol).depth.over_fail, 1u);
}

// Driver against driver with the reference as the uncertainty frame: at a pixel both
// drivers and the reference show as primitive 7, whose neighbours the expected driver frame
// shows as another primitive (edges that went the other way there, legally) while the
// reference shows one of them as 7 with a colour gradient, the shading allowance includes
// that gradient, as the comparison with the reference would (without the rule the first
// comparison fails); where the reference is flat as well, nothing is excused.
TEST(ShadingSlope, DriverAgainstDriverTakesTheGradientTheReferenceShows) {
  auto [ref, gl] = driverPairFrames(16, 16, 4);
  const int px = 7;
  const int py = 7;
  const double gradient = 200.0;  // 8-bit units per px, the reference's, to the right
  for (int y = py - 1; y <= py + 1; ++y) {
    for (int x = px - 1; x <= px + 1; ++x) {
      const std::size_t i = gl.index(x, y);
      const bool centre = x == px && y == py;
      gl.id[i] = centre ? 7 : 8;
      ref.id[i] = centre || (x == px + 1 && y == py) ? 7 : 8;
      for (Frame* f : {&gl, &ref}) {
        f->depth[i] = 0.5f;
        for (int c = 0; c < 3; ++c) f->color[i * 4 + c] = 0.2f;
        f->color[i * 4 + 3] = 1.0f;
      }
    }
  }
  ref.color[ref.index(px + 1, py) * 4] = static_cast<float>(0.2 + gradient / 255.0);
  const Tolerances tol = tolerancesForFrames(gl, gl);
  const double band = compareFrames(gl, gl, ref, tol).depth.band_px;
  const double allowance = tol.shading_slope_factor * gradient * band;
  ASSERT_GT(allowance, 1.0) << "the test needs a gradient allowance to show";
  Frame other = gl;
  other.color[other.index(px, py) * 4] =
      static_cast<float>(0.2 + (tol.shading.fail + 0.5 * allowance) / 255.0);
  const PairResult with = compareFrames(gl, other, ref, tol);
  EXPECT_EQ(with.shading.over_fail, 0u) << "allowance " << allowance;
  EXPECT_NEAR(with.shading.worst_allowance, allowance, 0.01 * allowance + 0.1);
  // Where the reference is flat too, nothing is excused.
  ref.color[ref.index(px + 1, py) * 4] = 0.2f;
  EXPECT_EQ(compareFrames(gl, other, ref, tol).shading.over_fail, 1u);
}

// Driver against driver where both drivers show a transparent primitive 5 over a pixel
// whose reference shows the opaque primitive 3 (a depth tie the drivers broke the other
// way): what each driver blended there is described by the reference's blend channels at a
// neighbour where it shows primitive 5 (describing()); when its blend test there was within
// tolerance of flipping, the colours may legally differ (blend_uncertain), as at any
// blend-uncertain pixel. With the neighbour's blend decided (a large blend_gap) the same
// difference fails.
TEST(BlendUncertain, DriverAgainstDriverReadsTheBlendOfTheExpectedPrimitiveNextDoor) {
  auto [ref, gl] = driverPairFrames(16, 16, 8);
  for (int y = 6; y <= 8; ++y) {
    for (int x = 6; x <= 8; ++x) {
      const std::size_t i = gl.index(x, y);
      gl.id[i] = 5;
      ref.id[i] = 5;
      for (Frame* f : {&gl, &ref}) {
        f->depth[i] = 0.5f;
        for (int c = 0; c < 3; ++c) f->color[i * 4 + c] = 0.4f;
        f->color[i * 4 + 3] = 0.8f;
      }
      ref.blend_count[i] = 1.0f;
      ref.blend_gap[i] = 0.25f;  // steps: within tolerance of flipping
    }
  }
  const std::size_t probe = ref.index(7, 7);
  ref.id[probe] = 3;  // the reference drew no blend here
  ref.blend_count[probe] = 0.0f;
  ref.blend_gap[probe] = std::numeric_limits<float>::infinity();
  const Tolerances tol = tolerancesForFrames(gl, gl);
  Frame other = gl;
  other.color[probe * 4] = 0.4f + 12.0f / 255.0f;  // one more layer blended: 12 units
  const PairResult excused = compareFrames(gl, other, ref, tol);
  EXPECT_EQ(excused.shading.over_fail, 0u);
  EXPECT_EQ(excused.shading.blend_uncertain, 1u);
  for (int y = 6; y <= 8; ++y)
    for (int x = 6; x <= 8; ++x) ref.blend_gap[ref.index(x, y)] = 1e6f;
  EXPECT_EQ(compareFrames(gl, other, ref, tol).shading.over_fail, 1u);
}

// Missing and extra pixels near the clear depth: the reference's clear_gap says how close
// the fragment's test against the clear depth came to flipping.
TEST_F(CompareTest, ClearGapExcusesMissingOnlyWithinOneDepthTolerance) {
  const Block b{70, 25, 72, 26};
  forBlock(b, [&](int x, int y) { gl_.id[gl_.index(x, y)] = 0; });
  ref_.clear_gap[ref_.index(70, 25)] = static_cast<float>(tol_.depth.fail * 0.99);
  ref_.clear_gap[ref_.index(71, 25)] = static_cast<float>(tol_.depth.fail * 1.01);
  const PairResult r = compare();
  EXPECT_EQ(r.visibility.missing, 2u);
  EXPECT_EQ(r.visibility.missing_hard, 1u);
  EXPECT_EQ(r.visibility.ambiguous_by_depth_gap, 1u);
  EXPECT_EQ(r.visibility.worst.x, 71);
}

// The vertices' float32 reach in window depth (the reference's depth_reach, steps) widens
// the depth tolerance by exactly itself: an offset of fail + reach passes the fail
// threshold, one step more fails, in the depth class only; without the channel the first
// offset fails too.
TEST_F(CompareTest, DepthReachWidensTheDepthToleranceByExactlyItsSteps) {
  constexpr double kReach = 1000.0;
  const auto n = static_cast<std::uint64_t>(kBackBlock.size());
  auto offset = [&](double steps) {
    forBlock(kBackBlock, [&](int x, int y) {
      const std::size_t i = gl_.index(x, y);
      gl_.depth[i] = quantized(ref_.depth[i], steps);
    });
    return compare();
  };
  forBlock(kBackBlock, [&](int x, int y) { ref_.depth_reach[ref_.index(x, y)] = kReach; });
  // The slope allowance in the block is ~0.13 steps (DepthThresholdsGiveWarnThenFail).
  const PairResult within = offset(tol_.depth.fail + kReach);
  EXPECT_EQ(within.depth.over_fail, 0u);
  EXPECT_EQ(within.depth.status, Status::Warn);
  EXPECT_NEAR(within.depth.worst_allowance, kReach, 1.0);
  const PairResult beyond = offset(tol_.depth.fail + kReach + 1.0);
  EXPECT_EQ(beyond.depth.over_fail, n);
  EXPECT_EQ(beyond.depth.status, Status::Fail);
  expectNoVisibilityChange(beyond);
  EXPECT_EQ(beyond.shading.max_abs, 0.0);
  forBlock(kBackBlock, [&](int x, int y) { ref_.depth_reach[ref_.index(x, y)] = 0.0f; });
  EXPECT_EQ(offset(tol_.depth.fail + kReach).depth.over_fail, n);
}

// Both fragments of a depth tie and a fragment against the clear depth may each be off by
// their reach: a gap within 2 (fail + reach) (a tie) or fail + reach (the clear depth) is
// ambiguous, one step beyond it is hard.
TEST_F(CompareTest, DepthReachWidensDepthTiesAndTheClearDepth) {
  constexpr float kReach = 500.0f;
  const double tie_limit = 2.0 * (tol_.depth.fail + kReach);
  const double clear_limit = tol_.depth.fail + kReach;
  const std::size_t tie_in = ref_.index(80, 30);
  const std::size_t tie_out = ref_.index(90, 40);
  const std::size_t clear_in = ref_.index(75, 35);
  const std::size_t clear_out = ref_.index(85, 35);
  for (std::size_t i : {tie_in, tie_out, clear_in, clear_out}) {
    ref_.depth_reach[i] = kReach;
    ref_.gap_slope[i] = 0.0f;
    ref_.clear_slope[i] = 0.0f;
  }
  ref_.depth_gap[tie_in] = static_cast<float>(tie_limit - 1.0);
  ref_.depth_gap[tie_out] = static_cast<float>(tie_limit + 1.0);
  ref_.clear_gap[clear_in] = static_cast<float>(clear_limit - 1.0);
  ref_.clear_gap[clear_out] = static_cast<float>(clear_limit + 1.0);
  gl_.id[tie_in] = 3;
  gl_.id[tie_out] = 3;
  gl_.id[clear_in] = 0;
  gl_.id[clear_out] = 0;
  const PairResult r = compare();
  EXPECT_EQ(r.visibility.wrong_primitive, 2u);
  EXPECT_EQ(r.visibility.wrong_primitive_hard, 1u);
  EXPECT_EQ(r.visibility.missing, 2u);
  EXPECT_EQ(r.visibility.missing_hard, 1u);
  EXPECT_EQ(r.visibility.ambiguous_by_depth_gap, 2u);
}

}  // namespace
}  // namespace rc
