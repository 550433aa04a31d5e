// The comparator on multisampled frames the reference renders in this process: a frame
// against itself; faults that must be caught (sample positions mirrored, one sample never
// written); legal differences that must not (another subpixel precision: coverage changes
// only at samples within the snap band, the resolved colour within the allowance of
// docs/tolerances.md "Multisampling"); and the not_supported status in every report form.
#include <filesystem>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/report.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/multisample.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace {
namespace fs = std::filesystem;

Frame render(const char* rel, ReferenceOptions options = {}, const char* backend = "ref") {
  const Scene scene = loadScene(fs::path(RC_SOURCE_DIR) / "fixtures/scenes/msaa" / rel);
  Frame f = renderReference(scene, options);
  f.meta["backend"] = backend;
  f.meta["fixture"] = scene.name;
  f.meta["subpixel_bits"] = options.subpixel_bits;
  return f;
}

PairResult compare(const Frame& expected, const Frame& actual) {
  return compareFrames(expected, actual, expected, tolerancesForFrames(expected, actual));
}

TEST(MultisampleCompare, FrameAgainstItselfPasses) {
  for (const char* f :
       {"edge_slopes.json", "shared_fan.json", "interpenetrating.json", "zfight_4x.json"}) {
    const Frame ref = render(f);
    const PairResult r = compare(ref, ref);
    EXPECT_EQ(r.status, Status::Pass) << f;
    EXPECT_EQ(r.visibility.samples, 4);
    EXPECT_EQ(r.visibility.mismatched_samples, 0u);
    EXPECT_GT(r.shading.compared, 0u);
  }
}

// Mirrored sample positions move the samples near every edge: hard coverage errors.
TEST(MultisampleCompare, WrongSamplePositionsAreHardVisibilityErrors) {
  const Frame ref = render("edge_slopes.json");
  ReferenceOptions mirrored;
  for (const glm::dvec2& p : standardSamplePositions(4))
    mirrored.sample_positions.emplace_back(p.x, 1.0 - p.y);
  const Frame wrong = render("edge_slopes.json", mirrored, "mirrored");
  const PairResult r = compare(ref, wrong);
  EXPECT_EQ(r.status, Status::Fail);
  EXPECT_GT(r.visibility.hard, 0u);
  EXPECT_GT(r.visibility.mismatched_samples, r.visibility.hard);
}

// A driver that never writes sample 3: every covered pixel misses one sample, far from any
// edge inside the triangles, so hard; and the resolved colour is darker.
TEST(MultisampleCompare, DroppedSampleIsCaught) {
  const Frame ref = render("shared_fan.json");
  Frame dropped = ref;
  dropped.meta["backend"] = "dropped";
  const std::size_t n = ref.pixelCount();
  std::uint64_t covered = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = ref.sampleIndex(3, i);
    covered += ref.sample_id[k] != 0 ? 1 : 0;
    dropped.sample_id[k] = 0;
    dropped.sample_depth[k] = 1.0f;
  }
  resolveSampleOwners(dropped);
  const PairResult r = compare(ref, dropped);
  EXPECT_EQ(r.status, Status::Fail);
  EXPECT_EQ(r.visibility.mismatched_samples, covered);
  EXPECT_EQ(r.visibility.mismatched, covered);  // one sample per pixel
  EXPECT_GT(r.visibility.hard, covered * 3 / 4);
  EXPECT_GT(r.visibility.missing, 0u);
}

// Snapping to 4 bits instead of 8 moves edges by up to 1/32 px: samples that change hands
// are within the band (ambiguous), and the resolved colours that differ by a sample's share
// of two primitives' colours are within the coverage allowance.
TEST(MultisampleCompare, CoarserSnappingIsAmbiguousAndWithinTheColourAllowance) {
  const Frame ref = render("edge_slopes.json");
  ReferenceOptions four;
  four.subpixel_bits = 4;
  Frame coarse = render("edge_slopes.json", four, "ref:subpixel=4");
  coarse.clearUncertainty();
  coarse.sample_edge_dist.clear();
  coarse.sample_alt.clear();
  const PairResult r = compare(ref, coarse);
  EXPECT_GT(r.visibility.mismatched_samples, 0u);
  EXPECT_EQ(r.visibility.hard, 0u);
  EXPECT_NE(r.status, Status::Fail);
  EXPECT_EQ(r.shading.over_tolerance, 0u);
  // The allowance was needed: some pixel's resolved colour differs by more than warn.
  const Tolerances tol = tolerancesForFrames(ref, coarse);
  double largest = 0.0;
  for (std::size_t k = 0; k < ref.color.size(); ++k)
    largest = std::max(largest, 255.0 * std::fabs(ref.color[k] - coarse.color[k]));
  EXPECT_GT(largest, tol.shading.warn);
}

TEST(MultisampleCompare, DifferentSampleCountsAreAnInputError) {
  const Frame ref = render("edge_slopes.json");
  Frame other = ref;
  other.samples = 1;
  other.sample_id.clear();
  other.sample_depth.clear();
  other.coverage.clear();
  other.sample_edge_dist.clear();
  other.sample_alt.clear();
  EXPECT_THROW(compare(ref, other), InputError);
}

TEST(NotSupported, IsNeitherPassNorFailureInEveryReport) {
  const std::optional<std::string> reason =
      notSupportedReason("rastercheck: not supported: f: gl:egl:softpipe: 4 samples");
  ASSERT_TRUE(reason.has_value());
  EXPECT_EQ(*reason, "f: gl:egl:softpipe: 4 samples");
  EXPECT_FALSE(notSupportedReason("backend error: crashed").has_value());

  Report report;
  report.results.push_back(notSupportedResult("msaa/x", "ref", "gl:egl:softpipe", *reason));
  EXPECT_EQ(exitCodeFor(report), 0);
  const ReportSummary s = report.summary();
  EXPECT_EQ(s.not_supported, 1u);
  EXPECT_EQ(s.total(), 1u);
  const nlohmann::json j = toJson(report, fs::temp_directory_path());
  EXPECT_EQ(j["results"][0]["status"], "not_supported");
  EXPECT_EQ(j["results"][0]["not_supported"], *reason);
  EXPECT_EQ(j["results"][0]["visibility"]["status"], "not_supported");
  EXPECT_EQ(j["summary"]["not_supported"], 1);
  const std::string junit = junitXml(report);
  EXPECT_NE(junit.find("<skipped type=\"not supported\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("skipped=\"1\""), std::string::npos) << junit;
  EXPECT_EQ(junit.find("<error"), std::string::npos);
  EXPECT_EQ(junit.find("<failure"), std::string::npos);
  const std::string html = reportHtml(report, fs::temp_directory_path());
  EXPECT_NE(html.find("badge not_supported"), std::string::npos);
  EXPECT_NE(describe(report.results[0]).find("NOT_SUPPORTED"), std::string::npos);
}

}  // namespace
}  // namespace rc
