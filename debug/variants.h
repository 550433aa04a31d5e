// Variant detection: which of the legal rasterization variants a GL driver follows.
// Three small probe scenes with analytically known answers, and pure functions that read
// a driver's frames of them (plus reference frames where the answer is "which reference
// option reproduces it", rendered here: subpixelReferences). Rendering the probes with GL
// is the caller's job (app/variants.cpp: files and worker processes); nothing here spawns
// or touches files. docs/debugging.md explains the probes. (In debug/, not compare/: it
// needs the reference renderer, and DESIGN.md puts the variant probes here.)
//
// Every probe uses an orthographic camera whose bounds are the image (world x, y =
// GL window x, y) and dyadic coordinates, so that GL's float32 vertex pipeline and the
// reference's double one reach exactly the same window coordinates and depths.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc::variants {

// ---- (a) subpixel precision ---------------------------------------------------------------

// 64 isolated right triangles whose near-vertical and near-horizontal edges run along
// rows and columns of pixel centres, each vertex offset from a centre by a random
// +-u * 2^-k px (k in 1..12, an odd multiple of 2^-16 so that no offset is a rounding tie
// at 14 bits or fewer). Snapping to N bits zeroes the offsets below 2^-(N+1), which moves
// whole rows of centres onto or across the edge: the coverage differs clearly between N
// and N+1. At 12 bits no offset vanishes, so no centre lies exactly on an edge and the
// tie-break rule does not enter: a rasterizer without snapping matches ref:subpixel=12.
Scene subpixelProbe(std::uint32_t seed = 1);

// Candidate precisions the reference can reproduce (`ref:subpixel=N`).
inline constexpr int kMinCandidateBits = 0;
inline constexpr int kMaxCandidateBits = 12;

struct SubpixelResult {
  int queried = -1;         // GL_SUBPIXEL_BITS from frame.json gl_subpixel_bits (older frames:
                            // subpixel_bits) (-1: absent)
  int band = -1;            // frame.json subpixel_bits: what the comparator's snap band assumes
                            // (differs from queried where the driver stack knows better, e.g.
                            // zink's Vulkan device) (-1: absent)
  std::string band_source;  // frame.json subpixel_bits_source ("" if absent)
  std::map<int, std::uint64_t> mismatches;  // N -> pixels whose id differs from ref:subpixel=N
  int best = -1;                            // N with the fewest mismatches (smallest N on ties)
  std::uint64_t best_mismatches = 0;
  bool exact = false;           // some N reproduces the driver's coverage exactly
  bool confirmed = false;       // the queried N does
  bool band_confirmed = false;  // the band's N does
  // One sentence when the driver's answer and its rasterization disagree (e.g. "GL_SUBPIXEL_BITS
  // says 4 but the driver rasterizes like 8 bits"), else "".
  std::string finding;
};

// `driver` is the driver's frame of subpixelProbe(); `reference` maps each candidate N to
// the reference's frame of the same scene rendered with ref:subpixel=N. Throws
// InputError when sizes differ.
SubpixelResult analyseSubpixel(const Frame& driver, const std::map<int, Frame>& reference);

// ---- (b) tie-break on edges through pixel centres ------------------------------------------

// An edge's side of its triangle, named by its inward normal (nx, ny) in GL window
// coordinates (y up): nx > 0 is a left edge, ny > 0 a bottom edge; diagonals get both.
enum class EdgeSide { Left, Right, Bottom, Top, BottomLeft, BottomRight, TopLeft, TopRight };
inline constexpr int kEdgeSideCount = 8;
const char* toString(EdgeSide side);

// The reference's documented rule (reference/rasterizer.h): a centre exactly on an edge
// is covered iff nx > 0, or nx == 0 and ny > 0 (left edges, and bottom edges in GL window
// coordinates).
bool referenceIncludes(EdgeSide side);

// One pixel centre that lies exactly on one edge of one probe triangle (not a vertex).
struct EdgeCentre {
  int x = 0;  // image coordinates
  int y = 0;
  std::uint32_t primitive = 0;
  EdgeSide side = EdgeSide::Left;
};

// A pixel centre on an edge shared by two probe triangles (a and b): a rule that covers
// shared edges exactly once gives it to one of them, never to neither.
struct SharedCentre {
  int x = 0;  // image coordinates
  int y = 0;
  std::uint32_t a = 0;
  std::uint32_t b = 0;
};

struct TieBreakProbe {
  Scene scene;
  std::vector<EdgeCentre> centres;   // from the geometry, exactly (integer arithmetic)
  std::vector<SharedCentre> shared;  // the subset on shared edges, by pair
};

// Triangles with every vertex on a pixel centre, so that vertical, horizontal and
// 45-degree edges with every inward normal pass exactly through pixel centres: 16 isolated
// right triangles (four corner orientations x both windings x two sizes) and 8 pairs that
// share an edge (diagonal both ways, vertical, horizontal; both windings). 64x32 px.
TieBreakProbe tieBreakProbe();

struct TieBreakResult {
  struct Side {
    int included = 0;
    int total = 0;
  };
  std::map<EdgeSide, Side> sides;
  int disagreements = 0;   // centres where the driver differs from referenceIncludes()
  int shared_centres = 0;  // centres on shared edges
  int shared_gaps = 0;     // of those, covered by neither triangle of the pair
  bool consistent = true;  // every side is all-included or all-excluded
  std::string rule;        // e.g. "left+bottom", from the four axis-aligned sides
  bool matches_reference = false;
};

TieBreakResult analyseTieBreak(const TieBreakProbe& probe, const Frame& driver);

// ---- (c) depth rounding ----------------------------------------------------------------

// One probe square: its pixels (image coordinates, inclusive-exclusive) and window depth.
struct DepthSample {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
  std::uint32_t primitive = 0;  // the first of its two triangles
  double window_z = 0.0;        // exact (dyadic), so z * (2^24 - 1) is known exactly
};

struct DepthProbe {
  Scene scene;  // d24
  std::vector<DepthSample> samples;
};

// 64 screen-parallel squares at window depths z = (2j + 1) / 128, j = 0..63. Each z is
// exact in float32 all the way through GL's vertex pipeline, and z * (2^24 - 1) =
// (2j + 1) * 2^17 - z: the fraction of a step is 1 - z, from 127/128 down to 1/128, so
// round-to-nearest and truncation differ on half of them and round-up on the other half.
DepthProbe depthProbe();

// Candidate conversions of a window depth z to a d24 value q.
enum class DepthRounding { Nearest, Truncate, NearestFloat32, TruncateFloat32 };
inline constexpr int kDepthRoundingCount = 4;
const char* toString(DepthRounding rule);
std::uint32_t convertDepth(double z, DepthRounding rule);

struct DepthRoundingResult {
  int samples = 0;
  std::map<DepthRounding, int> agree;  // samples each candidate predicts exactly
  std::string rule;                    // the first candidate that predicts every sample, or
                                       // "none"
  bool matches_reference = false;      // Nearest predicts every sample
  bool readback_exact = true;          // every Z is exactly float(q / (2^24 - 1)) for a q
  bool uniform = true;                 // every pixel of a square holds the same q
  int uncovered = 0;                   // probe pixels the driver did not draw
};

DepthRoundingResult analyseDepthRounding(const DepthProbe& probe, const Frame& driver);

// ---- (d) lines and points ---------------------------------------------------------------

// One primitive of the line probe and what it tests.
struct LineProbeItem {
  std::uint32_t primitive = 0;
  enum class Kind { Thin, Wide, Point } kind = Kind::Thin;
  glm::dvec2 a{0.0};  // window position of the segment's start (or the point)
  glm::dvec2 b{0.0};  // of its end
  double size = 1.0;  // line width or point size
};

struct LineProbe {
  Scene scene;
  std::vector<LineProbeItem> items;
};

// One-pixel segments at 16 angles with ends off the pixel grid (the diamond-exit rule's
// ends and interiors), width-4 segments at 30 and 60 degrees (GL's column rule gives 4
// fragments per column or row; a rectangle of that width 4 / cos(angle)), and points of
// size 3.5 and 5 at quarter-pixel positions. Each primitive apart from the others,
// depth test off. 128x96 px.
LineProbe lineProbe();

struct LineRuleResult {
  int thin_pixels = 0;           // the reference's fragments of the one-pixel segments
  int thin_interior_off = 0;     // pixels (either side) where the driver differs, away from ends
  int thin_end_off = 0;          // ... within a pixel of an end (GL leaves those open)
  std::string line_rule;         // "diamond-exit", "diamond-exit, own ends", "other"
  double wide_per_column = 0.0;  // mean fragments per column (row) inside the wide segments
  std::string wide_lines;        // "column", "rectangle", "other"
  int point_pixels = 0;          // the reference's point fragments
  int point_off = 0;             // pixels where the driver's points differ
  std::string point_rule;        // "square", "other"
  // The reference's rules where GL fixes them: the diamond-exit interior (ends may differ:
  // GL leaves them open), the column rule and point squares.
  bool matches_reference = false;
};

// `reference` is the reference's frame of lineProbe() (no channels), `driver` the driver's.
LineRuleResult analyseLines(const LineProbe& probe, const Frame& driver, const Frame& reference);

// ---- report.json ------------------------------------------------------------------------

nlohmann::json toJson(const SubpixelResult& r);
nlohmann::json toJson(const TieBreakResult& r);
nlohmann::json toJson(const DepthRoundingResult& r);
nlohmann::json toJson(const LineRuleResult& r);

// One line per variant for people, e.g. "subpixel: 8 bits (GL_SUBPIXEL_BITS 8, confirmed:
// ref:subpixel=8 reproduces the probe exactly)".
std::string describeSubpixel(const SubpixelResult& r);
std::string describeTieBreak(const TieBreakResult& r);
std::string describeDepthRounding(const DepthRoundingResult& r);
std::string describeLines(const LineRuleResult& r);

// The reference's frames of the subpixel probe `scene` at every candidate precision
// (kMinCandidateBits..kMaxCandidateBits), without uncertainty channels: what
// analyseSubpixel matches a driver's frame against.
std::map<int, Frame> subpixelReferences(const Scene& scene);

// What one GL backend's frames of the three probes say, report.json's "variants.SPEC"
// without "probe_seconds": "renderer", "stack" (from the subpixel frame's frame.json),
// "subpixel_bits" (GL_SUBPIXEL_BITS as the driver answers it), "band_subpixel_bits" (what
// its frames carry for the comparator's snap band), "subpixel", "tie_break",
// "depth_rounding" (toJson above) and "findings" (sentences: where the driver's answer and
// its rasterization disagree). Throws InputError for frames that do not fit the probes.
nlohmann::json backendVariants(const Frame& subpixel, const Frame& tie_break,
                               const Frame& depth_rounding, const std::map<int, Frame>& reference);

}  // namespace rc::variants
