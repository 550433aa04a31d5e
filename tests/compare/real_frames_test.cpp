// The comparator on real frames: catalog fixtures rendered by the reference in this
// process, then one fault injected at a time (ids blanked or changed in a block, depth
// offset by N steps, colour offset by N/255). Exactly the injected class must fail, with
// the injected count, in the injected block, and every other number must stay where the
// unmodified pair has it. Also ambiguity end to end on crafted geometry rendered two ways
// (subpixel precision, painter's order). Expected counts come from the injection and the
// band formula, never from running the comparator first.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "fixtures/loader.h"
#include "fixtures/mipmaps.h"
#include "fixtures/scene_logic.h"
#include "reference/reference_renderer.h"
#include "reference/texture_lod.h"

namespace rc {
namespace {
namespace fs = std::filesystem;

constexpr double kD24 = 16777215.0;

Frame render(const fs::path& fixture, const ReferenceOptions& options = {},
             const char* backend = "ref") {
  const Scene scene = loadScene(fixture);
  Frame f = renderReference(scene, options);
  f.meta["backend"] = backend;
  f.meta["fixture"] = scene.name;
  return f;
}

fs::path catalog(const char* rel) { return fs::path(RC_SOURCE_DIR) / "fixtures/scenes" / rel; }
fs::path crafted(const char* rel) { return fs::path(RC_SOURCE_DIR) / "tests/compare/data" / rel; }

struct Block {
  int x0 = 0, y0 = 0, size = 0;
  int count() const { return size * size; }
  bool contains(PixelRef p) const {
    return p.x >= x0 && p.x < x0 + size && p.y >= y0 && p.y < y0 + size;
  }
  template <typename F>
  void each(F f) const {
    for (int y = y0; y < y0 + size; ++y)
      for (int x = x0; x < x0 + size; ++x) f(x, y);
  }
};

// The first size x size block (scanning in steps of `size`) whose every pixel passes.
std::optional<Block> findBlock(const Frame& f, int size,
                               const std::function<bool(std::size_t)>& ok) {
  for (int y0 = 0; y0 + size <= f.height; y0 += size) {
    for (int x0 = 0; x0 + size <= f.width; x0 += size) {
      Block b{x0, y0, size};
      bool all = true;
      b.each([&](int x, int y) { all = all && ok(f.index(x, y)); });
      if (all) return b;
    }
  }
  return std::nullopt;
}

class RealFramesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ref_ = render(catalog("shading/teapot.json"));
    actual_ = ref_;
    actual_.clearUncertainty();
    actual_.meta["backend"] = "ref+fault";
    tol_ = tolerancesForFrames(ref_, actual_);
    baseline_ = compareFrames(ref_, actual_, ref_, tol_);
    // The band the comparator must use, from the formula (8 subpixel bits both sides).
    band_ = snapMovePx(8) + 16.0 * std::ldexp(1.0, -24) * std::max(ref_.width, ref_.height);
    slope_band_ = 2.0 * snapMovePx(8) + 16.0 * std::ldexp(1.0, -24) * ref_.width;
  }
  PairResult compare(ClassMaps* maps = nullptr) {
    return compareFrames(ref_, actual_, ref_, tol_, maps);
  }
  // A drawn block away from every edge (edge_dist beyond the band).
  Block interiorBlock(int size, const std::function<bool(std::size_t)>& extra = {}) {
    const std::optional<Block> b = findBlock(ref_, size, [&](std::size_t i) {
      return ref_.id[i] != 0 && ref_.edge_dist[i] > band_ && (!extra || extra(i));
    });
    EXPECT_TRUE(b.has_value()) << "no such block in " << ref_.meta["fixture"];
    return b.value_or(Block{});
  }
  void expectVisibilityUnmoved(const PairResult& r) {
    EXPECT_EQ(r.visibility.mismatched, 0u);
    EXPECT_EQ(r.visibility.status, Status::Pass);
    EXPECT_FALSE(r.visibility.worst.valid());
  }
  void expectDepthUnmoved(const PairResult& r) {
    EXPECT_EQ(r.depth.max_steps, 0.0);
    EXPECT_EQ(r.depth.over_tolerance, 0u);
    EXPECT_EQ(r.depth.status, Status::Pass);
  }
  void expectShadingUnmoved(const PairResult& r) {
    EXPECT_EQ(r.shading.max_abs, 0.0);
    EXPECT_EQ(r.shading.over_tolerance, 0u);
    EXPECT_EQ(r.shading.status, Status::Pass);
  }

  Frame ref_;
  Frame actual_;
  Tolerances tol_;
  PairResult baseline_;
  double band_ = 0.0;
  double slope_band_ = 0.0;
};

TEST_F(RealFramesTest, AFrameComparedWithItselfGivesZeros) {
  const PairResult& r = baseline_;
  EXPECT_EQ(r.status, Status::Pass);
  expectVisibilityUnmoved(r);
  expectDepthUnmoved(r);
  expectShadingUnmoved(r);
  EXPECT_GT(r.depth.compared, 10000u);  // the teapot covers a good part of the frame
  EXPECT_EQ(r.depth.compared, r.shading.compared);
  EXPECT_EQ(r.shading.psnr_db, kPsnrCapDb);
  EXPECT_EQ(r.nonfinite_expected.total() + r.nonfinite_actual.total(), 0u);
  EXPECT_NEAR(r.visibility.band_px, band_, 1e-12);
  EXPECT_NEAR(r.depth.band_px, slope_band_, 1e-12);
}

TEST_F(RealFramesTest, BlankedIdsAreExactlyThatManyHardMissingPixels) {
  const Block b = interiorBlock(6);
  b.each([&](int x, int y) {
    const std::size_t i = actual_.index(x, y);
    actual_.id[i] = 0;
    actual_.depth[i] = 1.0f;
    for (int c = 0; c < 4; ++c) actual_.color[i * 4 + c] = 0.0f;
  });
  ClassMaps maps;
  const PairResult r = compare(&maps);
  const auto n = static_cast<std::uint64_t>(b.count());
  EXPECT_EQ(r.visibility.missing, n);
  EXPECT_EQ(r.visibility.missing_hard, n);
  EXPECT_EQ(r.visibility.hard, n);
  EXPECT_EQ(r.visibility.mismatched, n);
  EXPECT_EQ(r.visibility.extra + r.visibility.wrong_primitive, 0u);
  EXPECT_EQ(r.visibility.status, Status::Fail);
  EXPECT_TRUE(b.contains(r.visibility.worst))
      << r.visibility.worst.x << "," << r.visibility.worst.y;
  // Where: the class map marks the block and nothing else.
  std::uint64_t marked = 0;
  for (int y = 0; y < ref_.height; ++y)
    for (int x = 0; x < ref_.width; ++x) {
      const PixelClass c = maps.pixel_class[ref_.index(x, y)];
      if (c != PixelClass::Match && c != PixelClass::Background) {
        ++marked;
        EXPECT_TRUE(b.contains({x, y})) << x << "," << y;
        EXPECT_EQ(c, PixelClass::MissingHard);
      }
    }
  EXPECT_EQ(marked, n);
  // The other classes only lose the pixels that left the comparison.
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared - n);
  expectDepthUnmoved(r);
  expectShadingUnmoved(r);
  EXPECT_EQ(r.status, Status::Fail);
}

TEST_F(RealFramesTest, ChangedIdsWithOneFragmentAreHardWrongPrimitives) {
  // Far from any edge and no second surface within any possible depth tolerance: the
  // largest allowance a d24 slope can give is the whole range per px times the band.
  const double gap_bound = 2.0 * (tol_.depth.fail + slope_band_ * kD24);
  const Block b = interiorBlock(5, [&](std::size_t i) { return ref_.depth_gap[i] > gap_bound; });
  b.each([&](int x, int y) { actual_.id[actual_.index(x, y)] += 100000; });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(b.count());
  EXPECT_EQ(r.visibility.wrong_primitive, n);
  EXPECT_EQ(r.visibility.wrong_primitive_hard, n);
  EXPECT_EQ(r.visibility.ambiguous, 0u);
  EXPECT_EQ(r.visibility.missing + r.visibility.extra, 0u);
  EXPECT_TRUE(b.contains(r.visibility.worst));
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared - n);
  expectDepthUnmoved(r);
  expectShadingUnmoved(r);
}

TEST_F(RealFramesTest, DepthOffsetFailsInExactlyItsBlock) {
  // 50000 steps: beyond warn/fail plus any slope allowance a visible triangle can have
  // here (that would need more than 8e6 steps/px).
  constexpr int kN = 50000;
  const Block b = interiorBlock(6);
  b.each([&](int x, int y) {
    const std::size_t i = actual_.index(x, y);
    actual_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + kN) / kD24);
  });
  ClassMaps maps;
  const PairResult r = compare(&maps);
  const auto n = static_cast<std::uint64_t>(b.count());
  EXPECT_EQ(r.depth.over_tolerance, n);
  EXPECT_EQ(r.depth.over_fail, n);
  EXPECT_EQ(r.depth.max_steps, kN);
  EXPECT_EQ(r.depth.worst_steps, kN);
  EXPECT_TRUE(b.contains(r.depth.worst)) << r.depth.worst.x << "," << r.depth.worst.y;
  EXPECT_EQ(r.depth.status, Status::Fail);
  EXPECT_EQ(r.depth.compared, baseline_.depth.compared);
  EXPECT_DOUBLE_EQ(r.depth.mean_steps, kN * static_cast<double>(n) / r.depth.compared);
  for (int y = 0; y < ref_.height; ++y)
    for (int x = 0; x < ref_.width; ++x) {
      const float steps = maps.depth_steps[ref_.index(x, y)];
      EXPECT_EQ(steps, b.contains({x, y}) ? kN : 0.0f) << x << "," << y;
    }
  expectVisibilityUnmoved(r);
  expectShadingUnmoved(r);
  EXPECT_EQ(r.status, Status::Fail);

  // Within warn (3 steps <= 4) the same block passes, and the numbers still say 3.
  actual_ = ref_;
  b.each([&](int x, int y) {
    const std::size_t i = actual_.index(x, y);
    actual_.depth[i] = static_cast<float>((std::nearbyint(ref_.depth[i] * kD24) + 3) / kD24);
  });
  const PairResult small = compare();
  EXPECT_EQ(small.depth.max_steps, 3.0);
  EXPECT_EQ(small.depth.over_tolerance, 0u);
  EXPECT_EQ(small.status, Status::Pass);
}

TEST_F(RealFramesTest, ColourOffsetFailsInExactlyItsBlockAndChannel) {
  constexpr float kN = 4.0f;  // 8-bit units, far above fail (0.5) + allowance
  const Block b = interiorBlock(6);
  b.each([&](int x, int y) { actual_.color[actual_.index(x, y) * 4 + 1] += kN / 255.0f; });
  const PairResult r = compare();
  const auto n = static_cast<std::uint64_t>(b.count());
  EXPECT_EQ(r.shading.over_tolerance, n);
  EXPECT_EQ(r.shading.over_fail, n);
  EXPECT_NEAR(r.shading.max_abs, kN, 1e-3);
  EXPECT_NEAR(r.shading.max_abs_rgba[1], kN, 1e-3);
  EXPECT_EQ(r.shading.max_abs_rgba[0], 0.0);
  EXPECT_EQ(r.shading.max_abs_rgba[2], 0.0);
  EXPECT_EQ(r.shading.max_abs_rgba[3], 0.0);
  EXPECT_TRUE(b.contains(r.shading.worst)) << r.shading.worst.x << "," << r.shading.worst.y;
  EXPECT_NEAR(r.shading.worst_abs, kN, 1e-3);
  EXPECT_LT(r.shading.worst_allowance, 1.0);
  const double values = 4.0 * static_cast<double>(r.shading.compared);
  EXPECT_NEAR(r.shading.mean_abs, kN * static_cast<double>(n) / values, 1e-5);
  EXPECT_EQ(r.shading.status, Status::Fail);
  expectVisibilityUnmoved(r);
  expectDepthUnmoved(r);
}

TEST_F(RealFramesTest, OneUnitInADarkCornerStillFailsAHundredthDoesNot) {
  // Float32 lighting error is relative to the value; a whole 8-bit unit is not.
  const Block b = interiorBlock(4);
  b.each([&](int x, int y) { actual_.color[actual_.index(x, y) * 4] += 1.0f / 255.0f; });
  EXPECT_EQ(compare().shading.over_fail, static_cast<std::uint64_t>(b.count()));
  actual_ = ref_;
  b.each([&](int x, int y) { actual_.color[actual_.index(x, y) * 4] += 0.01f / 255.0f; });
  EXPECT_EQ(compare().shading.over_tolerance, 0u);
}

// ---- Ambiguity end to end ----

TEST(Ambiguity, AnEdgeThroughPixelCentresIsAmbiguousBetweenSubpixelPrecisions) {
  const fs::path fixture = crafted("edge_through_centres.json");
  const Frame fine = render(fixture);
  ReferenceOptions coarse_options;
  coarse_options.subpixel_bits = 4;
  const Frame coarse = render(fixture, coarse_options, "ref:subpixel=4");
  const Tolerances tol = tolerancesForFrames(fine, coarse);
  const PairResult r = compareFrames(fine, coarse, fine, tol);
  // 4 bits move the diagonal and the left side onto a row and a column of centres.
  EXPECT_GE(r.visibility.mismatched, 100u);
  EXPECT_EQ(r.visibility.hard, 0u);
  EXPECT_EQ(r.visibility.ambiguous, r.visibility.mismatched);
  EXPECT_EQ(r.visibility.status, Status::Pass);
  EXPECT_NEAR(r.visibility.band_px, snapMovePx(4) + 16.0 * std::ldexp(1.0, -24) * 64, 1e-12);
  // The same pair with 8 bits on both sides: nothing to excuse.
  EXPECT_EQ(compareFrames(fine, fine, fine, tol).visibility.mismatched, 0u);
  // The band is what excuses them: with a band below their distance they are hard.
  Tolerances narrow = tol;
  narrow.band_px = 1e-4;
  const PairResult n = compareFrames(fine, coarse, fine, narrow);
  EXPECT_EQ(n.visibility.hard, r.visibility.mismatched);
}

TEST(Ambiguity, ACoplanarZFightIsAmbiguousByDepthGap) {
  const fs::path fixture = crafted("coplanar_zfight.json");
  const Frame zbuffer = render(fixture);
  ReferenceOptions painter_options;
  painter_options.force_painter = true;
  const Frame painter = render(fixture, painter_options, "ref:painter");
  const PairResult r =
      compareFrames(zbuffer, painter, zbuffer, tolerancesForFrames(zbuffer, painter));
  // The z-buffer keeps the first quad, painter's order the second, over the whole overlap.
  EXPECT_GT(r.visibility.wrong_primitive, 1000u);
  EXPECT_EQ(r.visibility.hard, 0u);
  // Interior pixels are excused by the depth gap (0 steps), edge pixels by the band.
  EXPECT_GT(r.visibility.ambiguous_by_depth_gap, r.visibility.wrong_primitive * 9 / 10);
  EXPECT_EQ(r.status, Status::Pass);
}

TEST(Ambiguity, AClearOcclusionErrorIsHard) {
  const fs::path fixture = crafted("interpenetrating.json");
  const Frame zbuffer = render(fixture);
  ReferenceOptions painter_options;
  painter_options.force_painter = true;
  const Frame painter = render(fixture, painter_options, "ref:painter");
  const Tolerances tol = tolerancesForFrames(zbuffer, painter);
  ClassMaps maps;
  const PairResult r = compareFrames(zbuffer, painter, zbuffer, tol, &maps);
  EXPECT_GT(r.visibility.wrong_primitive_hard, 200u);
  EXPECT_EQ(r.visibility.status, Status::Fail);
  // Every hard pixel is one the reference is sure about: away from edges, and the other
  // surface much farther than the depth tolerance.
  for (std::size_t i = 0; i < maps.pixel_class.size(); ++i) {
    if (maps.pixel_class[i] != PixelClass::WrongHard) continue;
    EXPECT_GT(zbuffer.edge_dist[i], r.visibility.band_px) << i;
    EXPECT_GT(zbuffer.depth_gap[i], 2.0 * tol.depth.fail) << i;
  }
  EXPECT_GT(zbuffer.depth_gap[zbuffer.index(r.visibility.worst.x, r.visibility.worst.y)], 100.0f);
}

}  // namespace
}  // namespace rc

namespace rc {
namespace {

// Blend functions in rgba8 (docs/tolerances.md section 8): every equation's blended pixels
// carry blend_count; a colour error of the allowance (a unit of final rounding plus
// blend_rounding_units per blend) passes and one unit more fails, and a cleared pixel is
// held to a unit. Catalog scenes that blend with additive, constant, saturate, subtract
// and reverse_subtract functions, and min/max (rgba32f: no per-blend units, the relative
// term).
TEST(BlendFunctions, AFaultJustBeyondTheAllowanceFails) {
  for (const char* rel :
       {"fragment-ops/blend_constant_saturate.json", "fragment-ops/additive_particles.json"}) {
    SCOPED_TRACE(rel);
    const Frame ref = render(catalog(rel));
    const Tolerances tol = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA8);
    // Interior pixels (no edge within the band, no depth tie) with blends on them.
    std::vector<std::size_t> blended;
    for (std::size_t i = 0; i < ref.pixelCount(); ++i)
      if (ref.blend_count[i] >= 1.0f && ref.edge_dist[i] >= 1.0f && ref.blend_gap[i] > 1000.0f &&
          ref.color[4 * i + 1] < 0.5f)
        blended.push_back(i);
    ASSERT_GE(blended.size(), 20u);
    auto shifted = [&](double extra_units) {
      Frame gl = ref;
      gl.meta["backend"] = "gl:test";
      for (std::size_t i : blended) {
        const double allowance = 1.0 + tol.blend_rounding_units * ref.blend_count[i];
        gl.color[4 * i + 1] = static_cast<float>(
            std::nearbyint(ref.color[4 * i + 1] * 255.0 + allowance + extra_units) / 255.0);
      }
      return compareFrames(ref, gl, ref, tol);
    };
    EXPECT_EQ(shifted(0.0).shading.over_fail, 0u);
    EXPECT_EQ(shifted(1.0).shading.over_fail, blended.size());
  }
}

TEST(ClearedBuffers, AnUnclearedPixelFailsInItsClass) {
  const Frame ref = render(catalog("fragment-ops/scissored_out.json"));
  for (std::uint32_t id : ref.id) ASSERT_EQ(id, 0u);
  const Tolerances tol = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA8);
  EXPECT_EQ(compareFrames(ref, ref, ref, tol).status, Status::Pass);
  Frame depth = ref;
  depth.depth[5] = 1.0f;  // the clear depth is 0.75: a driver that did not clear depth
  const PairResult d = compareFrames(ref, depth, ref, tol);
  EXPECT_EQ(d.depth.status, Status::Fail);
  EXPECT_EQ(d.depth.cleared_mismatched, 1u);
  EXPECT_EQ(d.shading.status, Status::Pass);
  Frame colour = ref;
  colour.color[4 * 7 + 2] += 2.0f / 255.0f;  // two units: beyond the clear's rounding
  EXPECT_EQ(compareFrames(ref, colour, ref, tol).shading.cleared_mismatched, 1u);
  colour.color[4 * 7 + 2] -= 1.0f / 255.0f;  // one unit: rounding of the clear colour
  EXPECT_EQ(compareFrames(ref, colour, ref, tol).shading.status, Status::Pass);
  Frame stencil = ref;
  stencil.stencil[9] = 8;  // clear.stencil is 7
  const PairResult s = compareFrames(ref, stencil, ref, tol);
  EXPECT_EQ(s.depth.stencil.hard, 1u);
  EXPECT_EQ(s.depth.status, Status::Fail);
}

}  // namespace
}  // namespace rc

namespace rc {
namespace {

// The level-of-detail allowance (docs/tolerances.md section 9) is neither missing nor
// loose, on the level-coloured floor (every level its own colour): a lambda moved by less
// than its precision passes; one level off fails. (Blend weights rounded to 0 or 1 pass
// there: GL's bounds on the scale factor, max(mu, mv) to mu + mv, span up to a whole level
// where mu and mv are alike, and on this floor they are everywhere the chain is not past
// its last level.)
TEST(LevelOfDetail, WithinThePrecisionPassesALevelOffFails) {
  const Scene scene = loadScene(catalog("mipmap/level_colours.json"));
  Frame ref = renderReference(scene);
  ref.meta["backend"] = "ref";
  auto variant = [&](double bias, std::optional<MinFilter> min) {
    Scene s = scene;
    s.state.lod_bias += bias;
    if (min) s.state.texture_min_filter = *min;
    ReferenceOptions o;
    o.uncertainty = false;
    Frame f = renderReference(s, o);
    f.meta["backend"] = "gl:test";
    return compareFrames(ref, f, ref, defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F));
  };
  EXPECT_EQ(variant(0.06, std::nullopt).shading.over_fail, 0u);
  EXPECT_EQ(variant(-0.06, std::nullopt).shading.over_fail, 0u);
  const PairResult off = variant(1.0, std::nullopt);
  EXPECT_GT(off.shading.over_fail, static_cast<std::uint64_t>(ref.pixelCount() / 4));
  EXPECT_EQ(variant(0.0, MinFilter::LinearMipmapNearest).shading.over_fail, 0u);
}

// A driver-like sampler on the level-coloured floor (each level one colour, so a pixel's
// colour tells its lambda and weight alone): derivatives of u, v taken per 2x2 quad from
// the top-left pixel's neighbours (the quad is the driver's choice), rho approximated by
// the largest derivative, log2 by exponent plus mantissa - 1 (off by up to 0.086), weights
// rounded to 8 bits; the texels come from the reference's own sampleAtLod. That stays
// inside the allowance; the same sampler one level off, or with the blend weight between
// two levels inverted (1 - f for f), does not.
struct DriverSampler {
  double lambda_shift = 0.0;
  bool invert_weight = false;
};

double fastLog2(double x) {
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  return (e - 1) + (2.0 * m - 1.0);
}

Frame driverLikeFrame(const Scene& scene, const Frame& ref, const DriverSampler& d) {
  const glm::dmat4 inv = glm::inverse(viewProjectionMatrix(scene));
  const Material& mat = scene.materials.at(0);
  const std::vector<std::shared_ptr<const Texture>> owned = mipChain(mat);
  std::vector<const Texture*> chain;
  for (const auto& t : owned) chain.push_back(t.get());
  const ref::LodState st = ref::lodState(scene.state);
  // The floor's uv at a pixel centre: the ray's hit on y = 0, then the quad's affine map
  // (x -20..20 -> u 0..8, z 5..-60 -> v 0..12); nullopt where the ray misses the plane.
  auto uvAt = [&](double px, double py) -> std::optional<glm::dvec2> {
    const double nx = 2.0 * (px + 0.5) / scene.width - 1.0;
    const double ny = 1.0 - 2.0 * (py + 0.5) / scene.height;
    const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0),
                     b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
    if (p1.y >= p0.y) return std::nullopt;
    const glm::dvec3 hit = p0 + (p1 - p0) * (p0.y / (p0.y - p1.y));
    return glm::dvec2((hit.x + 20.0) / 40.0 * 8.0, (5.0 - hit.z) / 65.0 * 12.0);
  };
  const double size = chain.front()->width;  // square level 0
  Frame out = ref;
  out.meta["backend"] = "gl:driver-like";
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      const std::size_t i = ref.index(x, y);
      if (ref.id[i] == 0) continue;
      const int qx = x & ~1, qy = y & ~1;
      const auto c = uvAt(qx, qy), r = uvAt(qx + 1, qy), b = uvAt(qx, qy + 1), uv = uvAt(x, y);
      if (!c || !r || !b || !uv) continue;
      const glm::dvec2 dx = (*r - *c) * size, dy = (*b - *c) * size;
      const double rho = std::max({std::abs(dx.x), std::abs(dx.y), std::abs(dy.x), std::abs(dy.y)});
      double lambda = std::clamp(fastLog2(rho) + st.bias + d.lambda_shift, st.min_lod, st.max_lod);
      const ref::LodSample plain = ref::sampleAtLod(chain, *uv, lambda, st);
      if (!plain.magnified && plain.level1 != plain.level0) {
        // Between two levels: the weight of the coarser rounded to 8 bits (or inverted),
        // put back as a lambda the reference's sampler then blends with exactly.
        double w = std::nearbyint(plain.weight * 256.0) / 256.0;
        if (d.invert_weight) w = 1.0 - w;
        lambda = plain.level0 + w;
      }
      const glm::dvec4 t = ref::sampleAtLod(chain, *uv, lambda, st).color;
      for (int k = 0; k < 3; ++k) {
        const float v = static_cast<float>(t[k]);
        out.color[4 * i + k] = scene.state.color_format == ColorFormat::RGBA8
                                   ? std::nearbyint(v * 255.0f) / 255.0f
                                   : v;
      }
    }
  }
  return out;
}

TEST(LevelOfDetail, ADriverLikeSamplerPassesOneLevelOffOrInvertedWeightsFail) {
  const Scene scene = loadScene(catalog("mipmap/level_colours.json"));
  ASSERT_EQ(scene.state.texture_min_filter, MinFilter::LinearMipmapLinear);
  const Frame ref = renderReference(scene);
  const Tolerances tol = defaultTolerances(scene.state.depth_format, scene.state.color_format);
  std::size_t floor_pixels = 0;
  for (std::uint32_t id : ref.id) floor_pixels += id != 0 ? 1 : 0;
  ASSERT_GT(floor_pixels, ref.pixelCount() / 3);

  const PairResult like = compareFrames(ref, driverLikeFrame(scene, ref, {}), ref, tol);
  EXPECT_EQ(like.shading.over_fail, 0u);
  EXPECT_EQ(like.status, Status::Pass);
  // The uncertainty channels are what lets it pass: without them the same frame fails.
  ReferenceOptions bare;
  bare.uncertainty = false;
  Frame certain = renderReference(scene, bare);
  certain.meta["backend"] = "ref";
  EXPECT_GT(compareFrames(certain, driverLikeFrame(scene, ref, {}), certain, tol).shading.over_fail,
            floor_pixels / 10);

  const PairResult off = compareFrames(ref, driverLikeFrame(scene, ref, {1.0, false}), ref, tol);
  // (Not all: near the camera both lambdas magnify or reach level 1 alike, far away both
  // are past the last level.)
  EXPECT_GT(off.shading.over_fail, floor_pixels / 3);
  // Inverting f moves lambda by |1 - 2f|: outside GL's interval (up to one level wide where
  // mu and mv are alike) at the pixels whose weight is far from one half.
  const PairResult inverted =
      compareFrames(ref, driverLikeFrame(scene, ref, {0.0, true}), ref, tol);
  EXPECT_EQ(inverted.shading.status, Status::Fail);
  EXPECT_GT(inverted.shading.over_fail, floor_pixels / 10);
  std::printf("floor %zu px; over the allowance: one level off %llu, inverted weights %llu\n",
              floor_pixels, static_cast<unsigned long long>(off.shading.over_fail),
              static_cast<unsigned long long>(inverted.shading.over_fail));
}

}  // namespace
}  // namespace rc
