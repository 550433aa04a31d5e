// Variant detection (debug/variants.h) without a GL driver: the reference stands in for
// a driver whose variant is known (it follows its own documented rules, and
// ref:subpixel=N snaps to N bits), and injected faults (a frame edited to follow another
// rule) must be told apart. The probes' analytic facts are checked independently.
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "debug/variants.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace {

namespace fs = std::filesystem;
using namespace rc::variants;

Frame renderAt(const Scene& scene, int bits) {
  ReferenceOptions options;
  options.subpixel_bits = bits;
  options.uncertainty = false;
  Frame f = renderReference(scene, options);
  f.meta["subpixel_bits"] = bits;
  return f;
}

std::map<int, Frame> candidates(const Scene& scene) {
  std::map<int, Frame> out;
  for (int n = kMinCandidateBits; n <= kMaxCandidateBits; ++n) out[n] = renderAt(scene, n);
  return out;
}

fs::path tempDir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_variants_" + name + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

TEST(Variants, ProbesSurviveTheFixtureFileBitForBit) {
  // GL renders the probes from a fixture file; the analysis assumes the same vertices.
  const fs::path dir = tempDir("roundtrip");
  const std::vector<Scene> probes = {subpixelProbe(), tieBreakProbe().scene, depthProbe().scene,
                                     lineProbe().scene};
  for (const Scene& probe : probes) {
    SCOPED_TRACE(probe.name);
    const fs::path file = dir / "probe.json";
    writeSceneFile(probe, file);
    const Scene loaded = loadScene(file);
    ASSERT_EQ(loaded.objects.size(), probe.objects.size());
    for (std::size_t o = 0; o < probe.objects.size(); ++o) {
      EXPECT_EQ(loaded.objects[o].mesh.positions, probe.objects[o].mesh.positions);
      EXPECT_EQ(loaded.objects[o].mesh.triangles, probe.objects[o].mesh.triangles);
      EXPECT_EQ(loaded.objects[o].mesh.lines, probe.objects[o].mesh.lines);
      EXPECT_EQ(loaded.objects[o].model, probe.objects[o].model);
    }
    EXPECT_EQ(renderAt(loaded, 8).id, renderAt(probe, 8).id);
  }
  fs::remove_all(dir);
}

TEST(Variants, SubpixelProbeSinglesOutEveryCandidatePrecision) {
  const Scene probe = subpixelProbe();
  const std::map<int, Frame> refs = candidates(probe);
  for (int truth : {1, 3, 4, 6, 8, 10, 12}) {
    SCOPED_TRACE("driver snapping to " + std::to_string(truth) + " bits");
    const SubpixelResult r = analyseSubpixel(refs.at(truth), refs);
    EXPECT_EQ(r.queried, truth);
    EXPECT_EQ(r.best, truth);
    EXPECT_TRUE(r.exact);
    EXPECT_TRUE(r.confirmed);
    // Every other precision differs in a clear number of pixels: the probe separates them.
    for (const auto& [bits, n] : r.mismatches) {
      if (bits != truth) {
        EXPECT_GE(n, 10u) << bits << " bits";
      }
    }
  }
}

TEST(Variants, SubpixelQueryThatTheProbeContradictsIsNotConfirmed) {
  const Scene probe = subpixelProbe();
  const std::map<int, Frame> refs = candidates(probe);
  Frame lying = refs.at(8);
  lying.meta["subpixel_bits"] = 4;  // the query says 4, the rasterizer snaps to 8
  const SubpixelResult r = analyseSubpixel(lying, refs);
  EXPECT_EQ(r.queried, 4);
  EXPECT_EQ(r.best, 8);
  EXPECT_TRUE(r.exact);
  EXPECT_FALSE(r.confirmed);
  EXPECT_GT(r.mismatches.at(4), 100u);
  EXPECT_NE(describeSubpixel(r).find("NOT confirmed"), std::string::npos);
}

TEST(Variants, ZinkLikeFrameSeparatesGlAnswerFromSnapBand) {
  // zink's frames: GL_SUBPIXEL_BITS 4 in gl_subpixel_bits, the Vulkan device's 8 in
  // subpixel_bits (the comparator's band). The probe must name the GL answer as the one
  // contradicted, confirm the band, and say so as a finding.
  const Scene probe = subpixelProbe();
  const std::map<int, Frame> refs = candidates(probe);
  Frame zink = refs.at(8);
  zink.meta["gl_subpixel_bits"] = 4;
  zink.meta["subpixel_bits"] = 8;
  zink.meta["subpixel_bits_source"] = "VkPhysicalDeviceLimits::subPixelPrecisionBits";
  const SubpixelResult r = analyseSubpixel(zink, refs);
  EXPECT_EQ(r.queried, 4);
  EXPECT_EQ(r.band, 8);
  EXPECT_EQ(r.best, 8);
  EXPECT_FALSE(r.confirmed);
  EXPECT_TRUE(r.band_confirmed);
  EXPECT_EQ(r.finding, "GL_SUBPIXEL_BITS says 4 but the driver rasterizes like 8 bits");
  EXPECT_NE(describeSubpixel(r).find("snap band: 8 bits from "
                                     "VkPhysicalDeviceLimits::subPixelPrecisionBits (confirmed"),
            std::string::npos)
      << describeSubpixel(r);
  EXPECT_EQ(toJson(r).at("finding"), r.finding);

  // A band the rasterizer does not follow is not confirmed (injected: it really snaps to 6).
  Frame wrong_band = refs.at(6);
  wrong_band.meta = zink.meta;
  const SubpixelResult w = analyseSubpixel(wrong_band, refs);
  EXPECT_FALSE(w.band_confirmed);
  EXPECT_NE(describeSubpixel(w).find("NOT confirmed by the probe"), std::string::npos);

  // A driver whose answer is right has no finding.
  EXPECT_TRUE(analyseSubpixel(refs.at(8), refs).finding.empty());
}

TEST(Variants, TieBreakCentresLieExactlyOnTheirEdges) {
  // Independent of how the probe enumerated them: each centre is on the line through two
  // vertices of its triangle, strictly between them, and not a vertex.
  const TieBreakProbe probe = tieBreakProbe();
  ASSERT_FALSE(probe.centres.empty());
  for (const EdgeCentre& c : probe.centres) {
    const Object& obj = probe.scene.objects[c.primitive - 1];
    const glm::dvec2 p(c.x + 0.5, probe.scene.height - 1 - c.y + 0.5);  // window
    int on_edges = 0;
    for (int e = 0; e < 3; ++e) {
      const glm::dvec2 a(obj.mesh.positions[e]);
      const glm::dvec2 b(obj.mesh.positions[(e + 1) % 3]);
      const double cross = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
      const double along = glm::dot(p - a, b - a) / glm::dot(b - a, b - a);
      if (cross == 0.0 && along > 0.0 && along < 1.0) ++on_edges;
    }
    EXPECT_EQ(on_edges, 1) << c.x << "," << c.y;
  }
}

TEST(Variants, ReferenceFollowsItsOwnTieBreakRule) {
  const TieBreakProbe probe = tieBreakProbe();
  const TieBreakResult r = analyseTieBreak(probe, renderAt(probe.scene, 8));
  EXPECT_EQ(r.rule, "left+bottom");
  EXPECT_TRUE(r.matches_reference);
  EXPECT_TRUE(r.consistent);
  EXPECT_EQ(r.disagreements, 0);
  EXPECT_EQ(r.sides.size(), static_cast<std::size_t>(kEdgeSideCount));  // every orientation
  EXPECT_GE(probe.shared.size(), 30u);
  EXPECT_EQ(r.shared_centres, static_cast<int>(probe.shared.size()));
  EXPECT_EQ(r.shared_gaps, 0);
  for (const auto& [side, s] : r.sides) {
    EXPECT_GT(s.total, 0) << toString(side);
    EXPECT_EQ(s.included, referenceIncludes(side) ? s.total : 0) << toString(side);
  }
}

TEST(Variants, TieBreakTellsARightEdgeRuleApart) {
  // Injected fault: a "driver" that gives centres on right edges to the triangle and
  // takes them away from left edges.
  const TieBreakProbe probe = tieBreakProbe();
  Frame f = renderAt(probe.scene, 8);
  int moved = 0;
  auto isLeft = [](EdgeSide s) {
    return s == EdgeSide::Left || s == EdgeSide::BottomLeft || s == EdgeSide::TopLeft;
  };
  auto isRight = [](EdgeSide s) {
    return s == EdgeSide::Right || s == EdgeSide::BottomRight || s == EdgeSide::TopRight;
  };
  // Take first, then give: on a shared edge the right-edge triangle must end up with it.
  for (const EdgeCentre& c : probe.centres) {
    if (isLeft(c.side)) {
      f.id[f.index(c.x, c.y)] = 0;
      ++moved;
    }
  }
  for (const EdgeCentre& c : probe.centres) {
    if (isRight(c.side)) {
      f.id[f.index(c.x, c.y)] = c.primitive;
      ++moved;
    }
  }
  const TieBreakResult r = analyseTieBreak(probe, f);
  EXPECT_EQ(r.rule, "right+bottom");
  EXPECT_FALSE(r.matches_reference);
  EXPECT_EQ(r.disagreements, moved);
  EXPECT_TRUE(r.consistent);
  EXPECT_EQ(r.shared_gaps, 0);  // still one owner per shared centre
  // A rule that covers neither side of a shared edge leaves gaps.
  Frame gaps = renderAt(probe.scene, 8);
  for (const SharedCentre& c : probe.shared) gaps.id[gaps.index(c.x, c.y)] = 0;
  const TieBreakResult holes = analyseTieBreak(probe, gaps);
  EXPECT_EQ(holes.shared_gaps, static_cast<int>(probe.shared.size()));
  EXPECT_NE(describeTieBreak(holes).find("left uncovered"), std::string::npos)
      << describeTieBreak(holes);
  // Half of the left centres only: inconsistent.
  Frame g = renderAt(probe.scene, 8);
  bool flip = false;
  for (const EdgeCentre& c : probe.centres)
    if (c.side == EdgeSide::Left && (flip = !flip)) g.id[g.index(c.x, c.y)] = 0;
  EXPECT_FALSE(analyseTieBreak(probe, g).consistent);
}

TEST(Variants, DepthConversionCandidatesHaveTheAnalyticValues) {
  // z = (2j + 1) / 128: z * (2^24 - 1) = (2j + 1) * 2^17 - z exactly, fraction 1 - z.
  for (int j = 0; j < 64; ++j) {
    const double z = (2.0 * j + 1.0) / 128.0;
    const auto whole = static_cast<std::uint32_t>((2 * j + 1) << 17);
    EXPECT_EQ(convertDepth(z, DepthRounding::Truncate), whole - 1) << j;
    EXPECT_EQ(convertDepth(z, DepthRounding::Nearest), z < 0.5 ? whole : whole - 1) << j;
  }
}

TEST(Variants, ReferenceRoundsDepthToNearest) {
  const DepthProbe probe = depthProbe();
  ASSERT_EQ(probe.samples.size(), 64u);
  const DepthRoundingResult r = analyseDepthRounding(probe, renderAt(probe.scene, 8));
  EXPECT_EQ(r.rule, "nearest");
  EXPECT_TRUE(r.matches_reference);
  EXPECT_EQ(r.agree.at(DepthRounding::Nearest), 64);
  EXPECT_EQ(r.agree.at(DepthRounding::Truncate), 32);  // the probe separates the two
  EXPECT_TRUE(r.readback_exact);
  EXPECT_TRUE(r.uniform);
  EXPECT_EQ(r.uncovered, 0);
}

TEST(Variants, DepthRoundingTellsTruncationAndInexactReadbackApart) {
  const DepthProbe probe = depthProbe();
  const Frame ref = renderAt(probe.scene, 8);
  Frame truncated = ref;
  for (const DepthSample& s : probe.samples)
    for (int y = s.y0; y < s.y1; ++y)
      for (int x = s.x0; x < s.x1; ++x)
        truncated.depth[truncated.index(x, y)] =
            static_cast<float>(std::floor(s.window_z * 16777215.0) / 16777215.0);
  const DepthRoundingResult t = analyseDepthRounding(probe, truncated);
  EXPECT_EQ(t.rule, "truncate");
  EXPECT_FALSE(t.matches_reference);

  Frame off = ref;
  for (float& z : off.depth) z = std::nextafter(z, 2.0f);
  const DepthRoundingResult o = analyseDepthRounding(probe, off);
  EXPECT_FALSE(o.readback_exact);
  EXPECT_EQ(o.rule, "none");
}

// ---- (d) lines and points ----

TEST(Variants, LineProbeTellsTheRulesApart) {
  const LineProbe probe = lineProbe();
  const Frame reference = renderAt(probe.scene, 8);
  // The reference against itself: every rule its own.
  const LineRuleResult same = analyseLines(probe, reference, reference);
  EXPECT_EQ(same.line_rule, "diamond-exit");
  EXPECT_EQ(same.wide_lines, "column");
  EXPECT_EQ(same.point_rule, "square");
  EXPECT_TRUE(same.matches_reference);
  EXPECT_GT(same.thin_pixels, 16 * 10);
  EXPECT_GT(same.point_pixels, 8 * 9);
  EXPECT_NEAR(same.wide_per_column, 4.0, 0.01);

  // A driver whose one-pixel segments sit a row off inside (softpipe's truncated ends),
  // whose wide lines are rectangles (a fifth fragment every other column) and whose points
  // lose a column: each rule reported as another.
  Frame other = reference;
  const int h = probe.scene.height;
  auto at = [&](int x, int gy) -> std::uint32_t& { return other.id[other.index(x, h - 1 - gy)]; };
  const LineProbeItem& thin = probe.items[0];
  const LineProbeItem& wide = probe.items[16];
  const LineProbeItem& point = probe.items.back();
  ASSERT_EQ(thin.kind, LineProbeItem::Kind::Thin);
  ASSERT_EQ(wide.kind, LineProbeItem::Kind::Wide);
  ASSERT_EQ(point.kind, LineProbeItem::Kind::Point);
  for (int x = 0; x < probe.scene.width; ++x) {
    for (int gy = h - 1; gy > 0; --gy) {
      // Thin segment 0 (x-major or not, its pixels move up one row in its middle third).
      const double mid = (thin.a.x + thin.b.x) / 2.0;
      if (reference.id[reference.index(x, h - 1 - gy)] == thin.primitive &&
          std::abs(x + 0.5 - mid) < 2.0) {
        at(x, gy) = 0;
        at(x, gy + 1) = thin.primitive;
      }
    }
    // The wide segment: one more fragment on top of every column.
    int top = -1;
    for (int gy = 0; gy < h; ++gy)
      if (reference.id[reference.index(x, h - 1 - gy)] == wide.primitive) top = gy;
    if (top >= 0 && top + 1 < h) at(x, top + 1) = wide.primitive;
  }
  for (int x = 0; x < probe.scene.width; ++x)
    for (int gy = 0; gy < h; ++gy)
      if (reference.id[reference.index(x, h - 1 - gy)] == point.primitive &&
          x == static_cast<int>(std::floor(point.a.x + point.size / 2.0 - 0.5)))
        at(x, gy) = 0;
  const LineRuleResult r = analyseLines(probe, other, reference);
  EXPECT_EQ(r.line_rule, "other");
  EXPECT_GT(r.thin_interior_off, 0);
  EXPECT_NE(r.wide_lines, "column");
  EXPECT_EQ(r.point_rule, "other");
  EXPECT_FALSE(r.matches_reference);
  EXPECT_NE(describeLines(r).find("lines: other"), std::string::npos);
}

}  // namespace
}  // namespace rc
