// Lines and points through the comparator, frames from the reference (docs/tolerances.md
// "Lines and points"): what GL leaves open must pass (a segment drawn the other way round,
// whose ends the diamond-exit rule decides differently; another subpixel grid; a width of
// k + 1/2 drawn either way), and what it does not must fail in visibility (an end moved a
// pixel across the segment, a point moved a pixel).
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace {

// Segments at 24 angles from a centre off the grid, and points of several sizes, in world
// = window coordinates (orthographic camera bounded by the image).
Scene lineScene(bool reversed, double end_shift_px, double point_shift_px, int subpixel_moved,
                double width = 1.0) {
  Scene s;
  s.name = "lines";
  s.width = 128;
  s.height = 96;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 5.0};
  s.camera.bounds = {0.0, 128.0, 0.0, 96.0};
  s.camera.near = 1.0;
  s.camera.far = 10.0;
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.name = "m";
  m.ambient = glm::dvec3(0.8, 0.6, 0.3);
  m.diffuse = glm::dvec3(0.0);
  s.materials.push_back(m);
  s.state.shading = Shading::Flat;
  Object star;
  star.name = "star";
  star.primitive = PrimitiveKind::Lines;
  const glm::dvec2 c(50.37, 48.21);
  for (int k = 0; k < 24; ++k) {
    const double a = 2.0 * 3.14159265358979323846 * (k + 0.31) / 24.0;
    const glm::dvec2 d(std::cos(a), std::sin(a));
    glm::dvec2 end = c + 40.0 * d;
    // The fault: segment 5's end moved a pixel in its minor direction.
    if (k == 5) {
      if (std::fabs(d.x) >= std::fabs(d.y))
        end.y += end_shift_px;
      else
        end.x += end_shift_px;
    }
    // Another grid: the end moved by less than a 256th of a pixel.
    if (subpixel_moved != 0) end += glm::dvec2(0.003, -0.002) * static_cast<double>(subpixel_moved);
    const auto base = static_cast<std::uint32_t>(star.mesh.positions.size());
    star.mesh.positions.emplace_back(static_cast<float>(c.x), static_cast<float>(c.y),
                                     -0.3f * (k % 3));
    star.mesh.positions.emplace_back(static_cast<float>(end.x), static_cast<float>(end.y), 0.0f);
    star.mesh.lines.push_back(reversed ? std::array{base + 1, base} : std::array{base, base + 1});
  }
  star.mesh.normals.assign(star.mesh.positions.size(), glm::vec3(0, 0, 1));
  star.state.line_width = width;
  s.objects.push_back(star);
  Object dots;
  dots.name = "dots";
  dots.primitive = PrimitiveKind::Points;
  for (int k = 0; k < 6; ++k) {
    const float x = 100.3f + static_cast<float>(k % 2) * 14.0f +
                    (k == 3 ? static_cast<float>(point_shift_px) : 0.0f);
    dots.mesh.positions.emplace_back(x, 12.2f + 14.0f * static_cast<float>(k / 2), 0.0f);
  }
  dots.mesh.normals.assign(dots.mesh.positions.size(), glm::vec3(0, 0, 1));
  dots.state.point_size = 3.4;
  s.objects.push_back(dots);
  return s;
}

Frame render(const Scene& s, bool channels) {
  ReferenceOptions o;
  o.uncertainty = channels;
  return renderReference(s, o);
}

PairResult compareTo(const Scene& expected, const Scene& actual) {
  const Frame e = render(expected, true);
  return compareFrames(e, render(actual, false), e, tolerancesForFrames(e, e));
}

TEST(LineAllowance, SegmentsDrawnTheOtherWayRoundPass) {
  // Each segment reversed: the diamond-exit rule's start and end fragments trade places.
  const PairResult r = compareTo(lineScene(false, 0, 0, 0), lineScene(true, 0, 0, 0));
  EXPECT_GT(r.visibility.mismatched, 0u) << "the reversed star must differ somewhere";
  EXPECT_EQ(r.visibility.hard, 0u);
  EXPECT_EQ(r.visibility.status, Status::Pass);
}

TEST(LineAllowance, WideSegmentsOfAHalfWidthPassDrawnEitherWidth) {
  // 2.5 rounds to 3 here; a driver rounding halves down draws 2.
  Scene half = lineScene(false, 0, 0, 0, 2.5);
  Scene narrow = lineScene(false, 0, 0, 0, 2.0);
  narrow.objects.back().state.point_size = 3.4;
  const PairResult r = compareTo(half, narrow);
  EXPECT_GT(r.visibility.mismatched, 100u);
  EXPECT_EQ(r.visibility.hard, 0u);
  // A whole pixel wider is not a rounding: 2.5 against 4.
  const PairResult wider = compareTo(half, lineScene(false, 0, 0, 0, 4.0));
  EXPECT_GT(wider.visibility.hard, 100u);
}

TEST(LineAllowance, AnEndMovedAPixelAcrossIsHard) {
  const PairResult r = compareTo(lineScene(false, 0, 0, 0), lineScene(false, 1.0, 0, 0));
  EXPECT_GE(r.visibility.hard, 5u);
  EXPECT_EQ(r.visibility.status, Status::Fail);
  // Within snapping of the end: nothing hard.
  const PairResult snapped = compareTo(lineScene(false, 0, 0, 0), lineScene(false, 0, 0, 1));
  EXPECT_EQ(snapped.visibility.hard, 0u);
}

TEST(LineAllowance, APointMovedAPixelIsHard) {
  const PairResult r = compareTo(lineScene(false, 0, 0, 0), lineScene(false, 0, 1.0, 0));
  EXPECT_GE(r.visibility.hard, 4u);  // a column of 3 or 4 in and out
  EXPECT_EQ(r.visibility.status, Status::Fail);
}

}  // namespace
}  // namespace rc
