// The reference renderer: the scalar CPU ground truth the harness compares GL against.
// It follows DESIGN.md "Rendering semantics" stage by stage (one file per stage, see
// docs/reference.md): vertex stage (double) -> clipper (near/far + guard band) ->
// viewport -> snap + cull -> rasterizer (integer edge functions, llvmpipe's tie-break) ->
// interpolation (perspective-correct, from unsnapped coordinates) -> shading ->
// texture sampling -> fragment ops (depth quantize/test, blend, colour format), with
// the uncertainty channels (edge_dist, depth_gap) alongside. Single-threaded and
// bit-identical on every run and build type.
//
// Multisampling (scene.state.samples > 1) renders the scene once per sample with the
// rasterizer and the depth plane moved to that sample position, the colour shaded at
// the pixel centre (GL without sample shading), and resolves (reference/multisample
// notes in docs/reference.md "Multisampling").
//
// It does not: sample-shade, mipmap, clamp depth, do two-sided lighting, run shaders,
// or clip against the viewport (the bounding box does that; the guard band only bounds
// the fixed-point range).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "reference/shading.h"

namespace rc {

struct ReferenceOptions {
  int subpixel_bits = 8;       // vertex snapping grid: 1 / 2^bits px, in [0, 12]
  bool force_painter = false;  // `ref:painter`: draw far-to-near with no depth test
  bool uncertainty = true;     // compute edge_dist and depth_gap
  // Multisampled scenes: the sample positions (fixtures/multisample.h convention), one per
  // sample, e.g. a GL frame's frame.json "multisample" positions; empty: the standard
  // pattern for the scene's sample count. Ignored when the scene has one sample.
  std::vector<glm::dvec2> sample_positions;
  // `ref:abuffer` (last: positional initialisers keep their meaning): exact order-independent
  // transparency. Every fragment of a blending pass that passes its depth test (against the opaque
  // depth: that pass does not write depth) is kept in its pixel's list; after the last pass each
  // list is sorted far to near (window depth, ties in draw order) and blended in that order, and
  // the pixel's id is its nearest blended fragment. Opaque passes are unchanged. Multisampled,
  // each sample keeps its own lists.
  bool abuffer = false;
  // Every fragment through the fragment loop's scalar definition (fragmentColor() and
  // writeColor() in reference/fragment_loop.cpp) instead of its specialised forms (one stored
  // colour per flat triangle, Gouraud written out, Phong eight fragments at a time in vector
  // lanes). The same bits, slower: tests render both ways and compare (FragmentLoop.*).
  bool fragment_definition_only = false;
  // When set (the target passes of a multi-pass scene), filled with one byte per pixel (the
  // frame's pixel order): 1 where a primitive may be drawn in another implementation and
  // not here, or here and not there (markAmbiguous: a point whose centre is outside the view
  // volume, drawn as its square's part inside; vertices and edges made by clipping at the
  // viewport; a polygon whose facing float32 may flip). A target may hold anything there,
  // which the frame's channels (edge_dist 0) say for the frame but not what it stored.
  std::vector<std::uint8_t>* optional_cover = nullptr;
};

// Renders the scene. Throws InputError for options out of range (subpixel_bits outside
// [0, 12]), images larger than 16384 px a side or 2^26 px in all, and inconsistent
// scenes (material index, normal/uv counts, vertex indices, texture sizes). NaN or
// infinite geometry is not an error: those triangles are dropped.
// frame.drawn: the scene's formats and texture facts (fixtures/frame.h).
// frame.meta: {"renderer", "subpixel_bits", "painter_forced", "triangles_rasterized" (fan
// triangles, after clipping and culling, that covered a pixel centre's bounding box),
// "fragments" (covered pixel centres, whether they passed the depth test or not),
// "timing_ms": {"render"}}; multisampled, also "multisample": {"samples", "positions",
// "positions_source", "positions_on_grid"}, and fragments count covered samples; with
// options.abuffer also "abuffer" (docs/reference.md section 10; multisampled, its fragment count is
// over samples and a pixel counts when any of its samples does).
Frame renderReference(const Scene& scene, const ReferenceOptions& options = {});

// One fragment that reached a pixel, in draw order (`rastercheck explain`).
// How a fragment of a line or point came about (explain): the primitive's window
// positions, where the fragment lies along it, and how close its pixel came to going the
// other way.
struct LineTrace {
  enum class Kind { None, Segment, Point };
  Kind kind = Kind::None;
  bool polygon_edge = false;  // an edge of a triangle drawn in polygon mode line or point
  glm::dvec2 a{0.0};          // window position of the segment's start, or the point
  glm::dvec2 b{0.0};          // of its end (segments)
  double size = 1.0;          // line width (rounded) or point size, px
  double t = 0.0;             // the fragment centre projected onto a -> b (0 at a, 1 at b)
  double margin = 0.0;        // px its pixel centre is from the rule's boundary (0: a line end
                              // or a clipped point, where GL leaves the pixel to the driver)
};

struct FragmentTrace {
  std::uint32_t primitive = 0;  // primitive id (1-based)
  std::uint32_t object = 0;     // index into Scene::objects
  glm::dvec3 barycentric{0.0};  // w.r.t. the ORIGINAL triangle, perspective-correct
  double window_z = 0.0;        // interpolated window z, clamped to [0, 1]
  double stored_z = 0.0;        // window_z quantized to the depth format
  bool depth_pass = false;
  double depth_against = 0.0;     // the stored depth it was tested against
  ShadingTerms shading;           // every term of its colour (computed even if it failed)
  glm::dvec4 color_written{0.0};  // the colour buffer after this fragment (blended and
                                  // converted; unchanged when the depth test failed)
  // The general fragment operations (scenes with per-fragment state beyond LESS), in GL's
  // order; the defaults where a scene has none of them.
  bool scissor_pass = true;  // false: outside the scissor box, nothing else happened
  int stencil_before = -1;   // the stored stencil value it was tested against (-1: no test)
  bool stencil_pass = true;
  int stencil_after = -1;  // the stencil value after its op
  double offset = 0.0;     // polygon offset added to window_z (window-z units)
  LineTrace line;          // lines and points (kind None for filled triangles)
};

// A blended fragment of the A-buffer's sorted list at one pixel (`explain`).
struct SortedFragment {
  std::uint32_t primitive = 0;   // primitive id (1-based)
  std::uint32_t draw_order = 0;  // its position in the blending pass (0 = drawn first)
  double window_z = 0.0;         // clamped, unquantized window depth: the sort key
  glm::dvec4 color{0.0};         // the fragment's colour and alpha
  glm::dvec4 color_after{0.0};   // the colour buffer after blending it (stored form)
};

// The sorted list of image pixel (x, y_image) under options.abuffer (forced on), far to
// near, exactly as renderReference() blends it there (a multisampled scene as if it had one
// sample, as tracePixel()). Errors as tracePixel().
std::vector<SortedFragment> abufferPixel(const Scene& scene, ReferenceOptions options, int x,
                                         int y_image);

// Every fragment that covers image pixel (x, y_image) at its centre (a multisampled scene
// is traced as if it had one sample) (top-left origin, y down), in draw
// order, rendered exactly as renderReference() renders it (the same passes and depth
// buffer history, restricted to that one pixel). Throws InputError when the pixel is
// outside the image (and for everything renderReference() rejects).
std::vector<FragmentTrace> tracePixel(const Scene& scene, const ReferenceOptions& options, int x,
                                      int y_image);

}  // namespace rc
