// Per-vertex window set-up: what drawing an unclipped triangle needs of each of its
// vertices (the perspective divide and viewport of viewport.h, snapping, and the clip
// tests of classifyTriangle()), computed once per mesh vertex instead of once per
// triangle corner, four vertices a vector. A vertex is shared by about six triangles of a
// closed mesh; a triangle soup still gains the vectors. The renderer draws a triangle whose
// three vertices are all inside every clip plane from these; every other one goes through
// the clipper and computes its polygon's vertices itself, with the same functions.
#pragma once

#include <cstddef>
#include <cstdint>

#include "reference/clipper.h"
#include "reference/rasterizer.h"
#include "reference/vertex_stage.h"

namespace rc::ref {

struct VertexWindow {  // plain data: setUpVertexWindows() sets every field but the reaches
  static constexpr std::uint8_t kFinite = 1;    // clip coordinates finite
  static constexpr std::uint8_t kInside = 2;    // inside all six clip planes (classifyTriangle())
  static constexpr std::uint8_t kDrawable = 4;  // also w > 0 and a finite window position
  static constexpr int kRejectShift = 3;        // 4 bits: beyond the reject band, +x -x +y -y
  // toWindow() of the vertex (drawable vertices; unspecified otherwise).
  double x;
  double y;
  double z;
  double inv_w;
  FixedVertex fixed;   // snapVertexScaled(x, y) less the sample shift (drawable vertices)
  double reach;        // the renderer's: windowErrorPx(), capped (uncertainty channels)
  double depth_reach;  // the renderer's: windowDepthError() in steps (uncertainty channels)
  std::uint8_t flags;
};

struct WindowSetup {
  int width = 0;
  int height = 0;
  double snap_scale = 1.0;  // 2^subpixel_bits
  ClipVolume volume;
  std::int64_t shift_x = 0;  // multisampling: subtracted from the snapped position
  std::int64_t shift_y = 0;
};

// VertexWindow of verts[0 .. count) into out (reach and depth_reach left as they were).
// Bit for bit what toWindow(), snapVertexScaled() and classifyTriangle()'s per-vertex tests
// give for each vertex (tests/reference hold them equal).
void setUpVertexWindows(const TransformedVertex* verts, std::size_t count, const WindowSetup& setup,
                        VertexWindow* out);

// The definition of one VertexWindow, scalar: the clip tests classifyTriangle() makes of a
// vertex, and toWindow() and snapVertexScaled() (less the sample shift) of a drawable one;
// fields setUpVertexWindows() leaves unspecified are zero here, the reaches always. The
// renderer does not call it; the tests hold both builds below equal to it bit for bit
// (tests/reference/test_vertex_stage.cpp).
VertexWindow vertexWindowDefinition(const glm::dvec4& clip, const WindowSetup& setup);

namespace detail {
// The two builds setUpVertexWindows() chooses between, for the tests to run each (the AVX2
// one only where the CPU has AVX2).
void setUpVertexWindowsBaseline(const TransformedVertex* verts, std::size_t count,
                                const WindowSetup& setup, VertexWindow* out);
void setUpVertexWindowsAvx2(const TransformedVertex* verts, std::size_t count,
                            const WindowSetup& setup, VertexWindow* out);
}  // namespace detail

}  // namespace rc::ref
