// One-pixel-wide line segments as GL 4.6 rasterizes them (section 14.5.1, "Basic Line
// Segment Rasterization"): the diamond-exit rule, on the same snapped grid as triangles
// (rasterizer.h: pixel (px, py)'s centre is (px << bits, py << bits)).
//
//   R_f = { (x, y) : |x - x_f| + |y - y_f| < 1/2 }, the open diamond around pixel f's centre.
//   The segment from pa to pb produces fragment f iff the segment from pa' to pb' meets R_f
//   and pb' is not in R_f, where pa' = pa - (e, e^2), pb' = pb - (e, e^2) for an e small
//   enough that every smaller one gives the same fragments.
//
// The perturbation is kept symbolic: every quantity is a + b e + c e^2 with integer a, b, c
// and compared lexicographically, so ties (an endpoint on a diamond's border, a segment
// through a diamond's corner) are decided exactly as the spec's limit decides them. In the
// rotated coordinates u = x + y, v = x - y the diamond is an open square, and the segment
// meets it iff the parameter intervals of its four sides overlap (Liang-Barsky clipping).
//
// Consequences the tests check: a segment ending on a pixel centre does not produce that
// pixel, so the segments of a strip share no fragment and leave no gap; an x-major segment
// produces one fragment per column it crosses.
#pragma once

#include <cstdint>
#include <vector>

#include "reference/rasterizer.h"

namespace rc::ref {

struct LinePixel {
  int x;  // GL window coordinates (y up), as the triangle rasterizer's pixels
  int y;
};

// Whether the segment a -> b (snapped, `subpixel_bits` fractional bits) produces the
// fragment of the pixel whose centre is (cx, cy) (also snapped units).
bool lineProducesFragment(const FixedVertex& a, const FixedVertex& b, std::int64_t cx,
                          std::int64_t cy, int subpixel_bits);

// Every fragment of the segment a -> b within `clip`, in row-major order (y, then x).
// Coordinates within +/- 2^29 units (the triangle rasterizer's budget).
std::vector<LinePixel> rasterizeLine(const FixedVertex& a, const FixedVertex& b, int subpixel_bits,
                                     const PixelRect& clip);

// GL's width of a non-antialiased line: the nearest integer, halves up (2.5 draws 3, as
// Mesa's drivers round), 0 counting as 1.
double roundedLineWidth(double width);
// A width of k + 1/2 above 1: GL says only "the nearest integer", so the other width is the
// driver's choice (reference/line_loop.cpp marks the rows between).
bool halfLineWidth(double width);

// A non-antialiased wide line by GL's column rule (14.5.2.1): w = the width rounded to the
// nearest integer, halves up (0 counts as 1); the segment moved by -(w - 1) / 2 px in its minor
// direction (y for an x-major segment, |dx| >= |dy|; else x) is rasterized by the one-pixel
// rule, and each of its fragments becomes a column (x-major) or row of w fragments, the
// fragment itself the lowest (leftmost). GL also lets an implementation draw a wide line as
// the rectangle around the segment; which one a driver follows is a variant to probe.
std::vector<LinePixel> rasterizeWideLine(const FixedVertex& a, const FixedVertex& b, double width,
                                         int subpixel_bits, const PixelRect& clip);

// A point (GL 4.6 core, 14.4: always a point sprite): the pixels whose centres lie in the
// square of side `size` px centred at the snapped `center`. GL leaves centres on the
// square's border to the implementation; this takes the triangles' rule (rasterizer.h:
// left and bottom edges covered, right and top not), as a driver that draws a point as two
// triangles does. For an integer size every position gives size x size pixels.
std::vector<LinePixel> rasterizePoint(const FixedVertex& center, double size, int subpixel_bits,
                                      const PixelRect& clip);

}  // namespace rc::ref
