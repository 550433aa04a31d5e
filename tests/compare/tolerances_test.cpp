// Tolerance defaults, overrides, the snap band formula, and the error histogram whose
// percentiles the reports print (checked against sorting, an independent oracle).
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "compare/histogram.h"
#include "compare/tolerances.h"
#include "fixtures/errors.h"

namespace rc {
namespace {

TEST(Thresholds, EqualPassesAboveWarnWarnsAboveFailFails) {
  const Thresholds t{2.0, 5.0};
  EXPECT_EQ(t.verdict(0.0), Status::Pass);
  EXPECT_EQ(t.verdict(2.0), Status::Pass);
  EXPECT_EQ(t.verdict(2.5), Status::Warn);
  EXPECT_EQ(t.verdict(5.0), Status::Warn);
  EXPECT_EQ(t.verdict(5.01), Status::Fail);
  EXPECT_EQ(t.verdict(std::nan("")), Status::Fail);
  EXPECT_EQ(worse(Status::Warn, Status::Fail), Status::Fail);
  EXPECT_EQ(worse(Status::Error, Status::Pass), Status::Error);
  EXPECT_STREQ(toString(Status::Warn), "warn");
}

TEST(Tolerances, DefaultsDependOnTheFormats) {
  const Tolerances d16 = defaultTolerances(DepthFormat::D16, ColorFormat::RGBA8);
  const Tolerances d24 = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  EXPECT_LT(d16.depth.fail, d24.depth.fail);  // a d16 step hides float error entirely
  EXPECT_LE(d16.depth.warn, d16.depth.fail);
  EXPECT_LE(d24.depth.warn, d24.depth.fail);
  EXPECT_LE(d24.shading.warn, d24.shading.fail);
  EXPECT_EQ(d24.visibility.fail, 0.0);
  EXPECT_EQ(d16.color_format, ColorFormat::RGBA8);
}

TEST(Tolerances, OverridesReplaceOnlyWhatTheySet) {
  Tolerances t = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  const Tolerances before = t;
  ToleranceOverrides o;
  o.shading.fail = 10.0;
  o.visibility.warn = 5.0;  // above the default fail (0): fail follows
  o.depth_slope_factor = 2.0;
  applyOverrides(t, o);
  EXPECT_EQ(t.shading.fail, 10.0);
  EXPECT_EQ(t.shading.warn, before.shading.warn);
  EXPECT_EQ(t.visibility.warn, 5.0);
  EXPECT_EQ(t.visibility.fail, 5.0);
  EXPECT_EQ(t.depth.warn, before.depth.warn);
  EXPECT_EQ(t.depth.fail, before.depth.fail);
  EXPECT_EQ(t.depth_slope_factor, 2.0);

  ToleranceOverrides low;
  low.depth.fail = 1.0;  // below the default warn: warn follows
  applyOverrides(t, low);
  EXPECT_EQ(t.depth.fail, 1.0);
  EXPECT_EQ(t.depth.warn, 1.0);
}

TEST(Tolerances, BadOverridesAreInputErrors) {
  Tolerances t = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  ToleranceOverrides inverted;
  inverted.depth.warn = 8.0;
  inverted.depth.fail = 4.0;
  EXPECT_THROW(applyOverrides(t, inverted), InputError);
  ToleranceOverrides negative;
  negative.shading.warn = -1.0;
  EXPECT_THROW(applyOverrides(t, negative), InputError);
  ToleranceOverrides nan;
  nan.depth_slope_factor = std::nan("");
  EXPECT_THROW(applyOverrides(t, nan), InputError);
}

TEST(SnapBand, HalfDiagonalOfTheSnapGridPerSide) {
  EXPECT_DOUBLE_EQ(snapMovePx(8), std::sqrt(2.0) / 2.0 / 256.0);
  EXPECT_DOUBLE_EQ(snapMovePx(4), std::sqrt(2.0) / 2.0 / 16.0);
  Tolerances t = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  t.window_error_ulps = 0.0;
  BandInputs in;
  in.expected_bits = 8;
  in.actual_bits = 4;
  in.width = 640;
  in.height = 480;
  // Coverage: each side within its own snap of the exact edge edge_dist is measured to.
  EXPECT_DOUBLE_EQ(snapBandPx(t, in), snapMovePx(4));
  // Planes: each side's own plane moves with its own vertices.
  EXPECT_DOUBLE_EQ(slopeBandPx(t, in), snapMovePx(8) + snapMovePx(4));
  in.actual_bits = 8;
  EXPECT_DOUBLE_EQ(snapBandPx(t, in), snapMovePx(8));
  EXPECT_DOUBLE_EQ(slopeBandPx(t, in), 2.0 * snapMovePx(8));
  t.window_error_ulps = 16.0;
  EXPECT_DOUBLE_EQ(snapBandPx(t, in), snapMovePx(8) + 16.0 * 640.0 / 16777216.0);
  EXPECT_DOUBLE_EQ(slopeBandPx(t, in), 2.0 * snapMovePx(8) + 16.0 * 640.0 / 16777216.0);
  t.band_px = 0.25;
  EXPECT_EQ(snapBandPx(t, in), 0.25);
}

TEST(DepthSteps, OneStepPerFormat) {
  EXPECT_EQ(depthStepsPerUnit(DepthFormat::D16), 65535.0);
  EXPECT_EQ(depthStepsPerUnit(DepthFormat::D24), 16777215.0);
  EXPECT_EQ(depthStepsPerUnit(DepthFormat::D32F), 16777216.0);
}

double sortedPercentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::max<std::size_t>(rank, 1) - 1];
}

TEST(ErrorHistogram, IntegerPercentilesAreExact) {
  std::mt19937 rng(7);
  std::geometric_distribution<int> geo(0.05);
  std::vector<double> values;
  ErrorHistogram h(1.0, true);
  for (int i = 0; i < 20000; ++i) {
    const double v = geo(rng);
    values.push_back(v);
    h.add(v);
  }
  const double max = *std::max_element(values.begin(), values.end());
  ASSERT_LT(max, 1024.0);
  for (double p : {0.0, 0.5, 0.9, 0.99, 0.999, 1.0})
    EXPECT_EQ(h.percentile(p, max), sortedPercentile(values, p)) << "p=" << p;
  EXPECT_EQ(h.count(), values.size());
}

TEST(ErrorHistogram, ContinuousPercentilesAreTightUpperBounds) {
  std::mt19937 rng(11);
  std::lognormal_distribution<double> dist(0.0, 3.0);  // spans many octaves
  std::vector<double> values;
  ErrorHistogram h(1.0 / 64.0, false);
  for (int i = 0; i < 20000; ++i) {
    const double v = dist(rng);
    values.push_back(v);
    h.add(v);
  }
  const double max = *std::max_element(values.begin(), values.end());
  for (double p : {0.5, 0.9, 0.99}) {
    const double truth = sortedPercentile(values, p);
    const double got = h.percentile(p, max);
    EXPECT_GE(got, truth) << "p=" << p;
    EXPECT_LE(got, std::max(truth * (1.0 + 1.0 / 64.0), truth + 1.0 / 64.0)) << "p=" << p;
  }
  EXPECT_EQ(h.percentile(1.0, max), max);
}

TEST(ErrorHistogram, CoarseBinsCoverEveryValueOnce) {
  ErrorHistogram h(1.0, true);
  const std::vector<double> values = {0, 0, 0, 1, 2, 3, 4, 7, 8, 1000, 5000};
  for (double v : values) h.add(v);
  const ErrorHistogram::Coarse c = h.coarse(5000);
  ASSERT_EQ(c.counts.size() + 1, c.edges.size());
  EXPECT_EQ(c.edges[0], 0.0);
  EXPECT_EQ(c.edges[1], 1.0);
  EXPECT_GT(c.edges.back(), 5000.0);
  EXPECT_EQ(c.counts[0], 3u);  // exactly zero
  EXPECT_EQ(c.counts[1], 1u);  // [1, 2)
  EXPECT_EQ(c.counts[2], 2u);  // [2, 4)
  EXPECT_EQ(c.counts[3], 2u);  // [4, 8)
  EXPECT_EQ(c.counts[4], 1u);  // [8, 16)
  std::uint64_t total = 0;
  for (auto n : c.counts) total += n;
  EXPECT_EQ(total, values.size());
}

TEST(ErrorHistogram, AbsurdValuesLandInTheLastBin) {
  ErrorHistogram h(1.0, true);
  h.add(1e300);
  h.add(std::numeric_limits<double>::infinity());
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.percentile(0.5, 1e300), 1e300);
}

}  // namespace
}  // namespace rc

namespace rc {
namespace {

TEST(ToleranceJson, RoundTripsAndRejectsWhatIsNotANumber) {
  ToleranceOverrides o;
  o.depth.warn = 2.0;
  o.shading.fail = 0.25;
  o.depth_slope_factor = 1.5;
  const nlohmann::json j = toleranceJson(o);
  EXPECT_FALSE(j.contains("visibility"));  // only what is set
  const ToleranceOverrides back = toleranceFromJson(j, "frame.json");
  EXPECT_EQ(back.depth.warn, 2.0);
  EXPECT_FALSE(back.depth.fail.has_value());
  EXPECT_EQ(back.shading.fail, 0.25);
  EXPECT_EQ(back.depth_slope_factor, 1.5);
  EXPECT_FALSE(back.visibility.warn.has_value());
  for (const char* bad :
       {R"({"depth": {"warn": -1}})", R"({"depth": {"warn": "4"}})", R"({"colour": {}})",
        R"({"shading": {"slope_factor": 1}})", R"({"depth": 4})", R"([])"}) {
    try {
      toleranceFromJson(nlohmann::json::parse(bad), "x/frame.json");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("x/frame.json: tolerance"), std::string::npos)
          << e.what();
    }
  }
}

TEST(ToleranceDefaults, LinearTexturesGetTheFilteringAllowanceOnly) {
  const Tolerances plain = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F);
  DrawnWith drawn;
  drawn.linear_textures = true;
  const Tolerances textured = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA32F, drawn);
  EXPECT_EQ(plain.texture_weight_error, 0.0);
  EXPECT_EQ(plain.texture_rounding_units, 0.0);
  EXPECT_EQ(textured.texture_weight_error, 2.0 / 256.0);
  EXPECT_EQ(textured.texture_rounding_units, 1.0);
  // The texel choice applies wherever the reference's texel_alt says so, whatever the
  // frames' metadata: always on.
  EXPECT_EQ(plain.texel_choice, 1.0);
  EXPECT_EQ(textured.texel_choice, 1.0);
  EXPECT_EQ(plain.blend_rounding_units, 0.0);
  EXPECT_EQ(textured.shading.fail, plain.shading.fail);
  EXPECT_EQ(plain.shading_relative, 1.0 / 1024.0);
  // rgba8: one unit of rounding passes, two fail.
  const Tolerances rgba8 = defaultTolerances(DepthFormat::D24, ColorFormat::RGBA8);
  EXPECT_EQ(rgba8.shading.verdict(1.0), Status::Pass);
  EXPECT_EQ(rgba8.shading.verdict(2.0), Status::Fail);
}

}  // namespace
}  // namespace rc
