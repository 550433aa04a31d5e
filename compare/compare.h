// The comparator: for two frames of one fixture, says pixel by pixel what differs and
// why (visibility, depth, shading), separates legal differences from errors using the
// reference's uncertainty channels, and gives each class and the pair a verdict.
// It does not read or write files (see frame_io.h, pair_images.h, report.h) and does not
// render; the classes and numbers are those of ../shared/DESIGN.md "The comparison".
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "compare/ciede2000.h"
#include "compare/flip.h"
#include "compare/histogram.h"
#include "compare/oit.h"
#include "compare/pixel_class.h"
#include "compare/tolerances.h"
#include "fixtures/frame.h"

namespace rc {

// A pixel in image coordinates (origin top-left, y down); x = -1 when there is none.
// Reports add the GL window coordinate [x, height - 1 - y].
struct PixelRef {
  int x = -1;
  int y = -1;
  bool valid() const { return x >= 0; }
};

struct VisibilityStats {
  Status status = Status::Pass;
  std::uint64_t mismatched = 0;  // = missing + extra + wrong_primitive = ambiguous + hard
  std::uint64_t ambiguous = 0;
  std::uint64_t hard = 0;
  std::uint64_t missing = 0;
  std::uint64_t extra = 0;
  std::uint64_t wrong_primitive = 0;
  std::uint64_t missing_hard = 0;
  std::uint64_t extra_hard = 0;
  std::uint64_t wrong_primitive_hard = 0;
  std::uint64_t ambiguous_by_depth_gap = 0;  // mismatches excused only by depth_gap
  double band_px = 0.0;                      // edge_dist at or below this is ambiguous
  bool uncertainty_available = false;        // false: no edge_dist/depth_gap, all are hard
  int samples = 1;                           // samples per pixel compared (multisampled frames)
  std::uint64_t mismatched_samples = 0;      // samples whose ids differ (multisampled frames)
  PixelRef worst;                // the hard mismatch farthest from any edge (first on ties)
  double worst_edge_dist = 0.0;  // its edge_dist (1 = capped; +inf without uncertainty)
};

// The stencil buffers, compared exactly where both frames have one (state.stencil_format):
// a differing pixel is ambiguous where the reference says a fragment there may legally
// go either way (edge_dist within the band, or a depth test within its tolerance: the
// stencil op can follow the depth test), else hard. Hard ones count in the depth class's
// over_tolerance and over_fail (the stencil is part of the depth-stencil buffer).
// The spread of r assumed when a frame does not give its r: r from 1 to 4 times the
// minimum (llvmpipe and softpipe measure 2 for d16/d24, zink 4).
inline constexpr double kUnknownOffsetSpread = 3.0;

struct StencilStats {
  bool compared = false;
  std::uint64_t pixels = 0;
  std::uint64_t mismatched = 0;
  std::uint64_t ambiguous = 0;
  std::uint64_t hard = 0;
  PixelRef worst;  // the first hard mismatch in row order (none: no hard mismatch)
  int worst_expected = 0;
  int worst_actual = 0;
};

struct DepthStats {
  Status status = Status::Pass;
  std::uint64_t compared = 0;  // pixels with a = b != 0 (including non-finite ones)
  double max_steps = 0.0;      // over finite pixels
  double mean_steps = 0.0;
  double p99_steps = 0.0;
  std::uint64_t over_tolerance = 0;  // |dZ| > warn + allowance (non-finite pixels count)
  std::uint64_t over_fail = 0;       // |dZ| > fail + allowance (non-finite pixels count)
  std::uint64_t nonfinite = 0;       // Z NaN or Inf on either side
  // Pixels over their tolerance that were not counted because the fragments blended under
  // the top one may legally differ there (near an edge, or a depth tie; the reference's
  // blend_count, edge_dist, blend_gap).
  std::uint64_t blend_uncertain = 0;
  double band_px = 0.0;  // the slope band: allowance = factor * depth_slope * band
  // The pixel furthest over its tolerance when any is over, else the largest error (first
  // in row order on ties); none when every compared depth is equal.
  PixelRef worst;
  double worst_steps = 0.0;
  double worst_allowance = 0.0;  // the slope allowance there (steps)
  double max_slope = 0.0;        // largest slope met while checking pixels (steps/px)
  ErrorHistogram histogram{1.0, true};
  // Pixels where neither side drew anything (background on both): their depth must be the
  // clear depth on both sides, to format rounding (a step for d16 and d24, exact for d32f);
  // each that is not counts in over_tolerance and over_fail (docs/tolerances.md "Cleared
  // buffers").
  std::uint64_t cleared_checked = 0;
  std::uint64_t cleared_mismatched = 0;
  StencilStats stencil;
  // Polygon offset's r of each side (frame.json "polygon_offset_r", in units of the
  // format's minimum resolvable difference; NaN: the frame does not say) and the spread
  // the depth allowance takes: |r_expected - r_actual| x the pixel's offset_steps, or
  // kUnknownOffsetSpread when a side does not say (docs/tolerances.md "Polygon offset").
  double offset_r_expected = std::numeric_limits<double>::quiet_NaN();
  double offset_r_actual = std::numeric_limits<double>::quiet_NaN();
  double offset_r_spread = 0.0;
};

// PSNR of identical images (rmse 0) and the cap of every PSNR: 20 log10(255 / rmse) for
// rmse = 255e-10 units, far below any float32 difference a driver produces in practice.
inline constexpr double kPsnrCapDb = 200.0;

struct ShadingStats {
  Status status = Status::Pass;
  std::uint64_t compared = 0;  // pixels with a = b != 0 (including non-finite ones)
  double max_abs = 0.0;        // 8-bit units, over finite pixels and the four channels
  double mean_abs = 0.0;       // over finite pixels and the four channels
  double rmse = 0.0;
  double psnr_db = kPsnrCapDb;       // min(kPsnrCapDb, 20 log10(255 / rmse))
  double p99_abs = 0.0;              // of the per-pixel error (largest channel)
  std::uint64_t over_tolerance = 0;  // a channel's error > warn + its allowance (non-finite count)
  std::uint64_t over_fail = 0;       // a channel's error > fail + its allowance (non-finite count)
  std::uint64_t nonfinite = 0;       // a colour channel NaN or Inf on either side
  // Pixels over warn plus the rest of their allowance that the texel choice allowance (a
  // nearest-filtered sample within the band of a texel boundary) brought within it.
  std::uint64_t texel_choice = 0;
  // Pixels over their tolerance not counted because the fragments blended under the top
  // one may legally differ (see DepthStats::blend_uncertain).
  std::uint64_t blend_uncertain = 0;
  // Multisampled pairs: pixels not compared because a sample there may legally show
  // another primitive by a depth tie (docs/tolerances.md "5. Multisampling").
  std::uint64_t depth_tied = 0;
  // Pixels where neither side drew anything: the clear colour on both sides, to format
  // rounding (a unit for rgba8, exact for rgba32f); each that is not counts in
  // over_tolerance and over_fail.
  std::uint64_t cleared_checked = 0;
  std::uint64_t cleared_mismatched = 0;
  std::array<double, 4> max_abs_rgba{};
  // The pixel furthest over its tolerance when any is over (a non-finite one first), else
  // the largest per-pixel error (first in row order on ties); none when all are equal.
  PixelRef worst;
  double worst_abs = 0.0;        // the error of the deciding channel there (units)
  double worst_allowance = 0.0;  // that channel's allowance (units)
  ErrorHistogram histogram{1.0 / 4096.0, false};
};

// NaN and Inf counts of one frame, per channel R G B A Z, over every pixel.
struct NonFiniteCounts {
  std::array<std::uint64_t, 5> nan{};
  std::array<std::uint64_t, 5> inf{};
  std::uint64_t total() const;
};
inline constexpr std::array<const char*, 5> kFrameChannels = {"R", "G", "B", "A", "Z"};

// An expected failure a pair's failing class is covered by (compare/expectations.h).
struct KnownFailure {
  std::string id;
  std::string cls;
  std::string reason;
};

struct PairResult {
  std::string fixture;
  std::string fixture_file;       // the fixture file, when the frames name it (frame.json)
  std::vector<std::string> tags;  // the fixture's tags, when the frames name them
  std::string expected;           // backend specs, e.g. "ref", "gl:egl:llvmpipe"
  std::string actual;
  // The fixture's render state (frame.json "state": the fixture's state block with every
  // default filled in) and the actual side's GL version string ("" for the reference):
  // what expected failures are scoped by.
  nlohmann::json state = nlohmann::json::object();
  std::string actual_driver;
  // Non-empty when the pair failed only in classes known to fail (applyExpectations()).
  std::vector<KnownFailure> known;
  Status status = Status::Pass;
  std::string error;  // status Error: why the pair could not be compared
  int width = 0;
  int height = 0;
  std::uint64_t pixels = 0;
  int expected_subpixel_bits = 8;
  int actual_subpixel_bits = 8;
  // The driver stack each side ran on (frame.json "stack", "mesa", "vulkan", ...); null
  // for the reference or frames that do not say. report.json "stacks".
  nlohmann::json expected_stack;
  nlohmann::json actual_stack;
  Tolerances tolerances;  // the ones in effect
  VisibilityStats visibility;
  DepthStats depth;
  ShadingStats shading;
  NonFiniteCounts nonfinite_expected;
  NonFiniteCounts nonfinite_actual;
  // Against an A-buffer frame (ref:abuffer): the distance from exact transparency.
  std::optional<OitStats> oit;
  // The perceptual error (LDR-FLIP): computed only when asked for (ClassMaps::want_flip,
  // `--flip`) or when a FLIP threshold is set; its verdict joins the pair's status.
  std::optional<FlipStats> flip;
  // CIEDE2000 per pixel, pooled: every compared pair (a measurement, no verdict).
  std::optional<DeltaE2000Stats> ciede2000;
  // Files written by writePairImages, by kind: expected, actual, visibility, depth_heat,
  // shading_heat, diff_exr. Reports print them relative to the report folder.
  std::map<std::string, std::filesystem::path> images;
  double depth_heat_scale = 0.0;    // steps that map to the top of depth_heat's colour map
  double shading_heat_scale = 0.0;  // 8-bit units that map to the top of shading_heat's
  double seconds = 0.0;             // time the comparison took
  double render_seconds = 0.0;      // the actual side's render (frame.json time_ms), if known
  // `run --retries`: every render of the actual side (empty: rendered once). Status Flake
  // when they disagree; the classes above are then the comparison of the first attempt
  // that rendered, and flake_pixels and flake_first locate where the first two frames that
  // differ differ (0 and none when the disagreement is one render failing).
  struct Attempt {
    std::string digest;  // frameDigest() of what it rendered; empty when it did not render
    std::string error;   // why it did not render
    std::string frame;   // where its frame was kept, relative to the report folder
  };
  std::vector<Attempt> attempts;
  std::uint64_t flake_pixels = 0;
  PixelRef flake_first;
  // The deqp-runner status of the row (compare/deqp_results.h) once a baseline, flakes or
  // skips list has been applied; empty otherwise.
  std::string runner_status;
};

// A report row for a pair that could not be compared (e.g. the backend did not start).
PairResult errorResult(std::string fixture, std::string expected, std::string actual,
                       std::string message);
// A report row for a pair whose backend cannot render the fixture (status NotSupported;
// `reason` in PairResult::error, without the "not supported: " prefix).
PairResult notSupportedResult(std::string fixture, std::string expected, std::string actual,
                              std::string reason);
// When `message` (a render's last line of output, or an exception text) says the backend
// does not support the fixture ("not supported: ..." anywhere), the reason after it.
std::optional<std::string> notSupportedReason(const std::string& message);

// Per-pixel results, for images and diff.exr. Index y * width + x (image coordinates).
// (The colour deltas diff.exr also holds come straight from the frames.)
struct ClassMaps {
  int width = 0;
  int height = 0;
  std::vector<PixelClass> pixel_class;
  std::vector<float> depth_steps;      // |dZ| in steps where compared (NaN: non-finite), else 0
  std::vector<float> depth_tolerance;  // warn + slope allowance where compared, else 0
  std::vector<float> shading_abs;      // largest channel error where compared (NaN: non-finite)
  // Where shading_abs exceeds warn: the threshold it is held to (warn + its largest
  // channel error - that pixel's largest channel excess over its allowance), else 0.
  std::vector<float> shading_tolerance;
  std::vector<float> flip;  // LDR-FLIP per pixel (every pixel), empty when not computed
  // Compute LDR-FLIP (`--flip`): it costs ~2000 instructions a pixel near differences,
  // more than the rest of the comparison, so it is opt-in (a threshold also asks for it).
  bool want_flip = false;
  // One pixel (index) whose per-channel shading allowances a tool wants to show (`explain`):
  // recorded where that pixel's largest channel error is over warn, the only place the
  // comparison computes them; NaN otherwise.
  static constexpr double kNoAllowance = std::numeric_limits<double>::quiet_NaN();
  std::size_t describe_pixel = static_cast<std::size_t>(-1);
  std::array<double, 4> describe_allowances{kNoAllowance, kNoAllowance, kNoAllowance, kNoAllowance};
};

// Sizes the maps for a width x height comparison: allocates and touches the five per-pixel
// maps with the values the comparison starts from. A caller can so pay for the fresh
// memory while it waits for something else: the comparison reuses buffers that have the
// size it needs (docs/performance.md, `compare` on a 1080p pair).
void reserveMaps(ClassMaps& maps, int width, int height);

// The thresholds compared pixel i (class Match) was held to by the comparison that filled
// `maps` with `tolerances`: the class's warn and fail raised by the pixel's allowance
// (Thresholds::raisedBy). verdict() of them on maps.depth_steps[i] / shading_abs[i] is the
// pixel's verdict.
Thresholds depthThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances);
Thresholds shadingThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances);

// Compares `actual` with `expected`. `uncertainty` is the reference frame whose
// edge_dist/depth_gap and Z classify the pair: usually `expected` itself (pass the same
// object), or the reference render of the same fixture when both sides are GL drivers.
// Without uncertainty channels every mismatch is hard. FLIP (result.flip) is computed when
// maps->want_flip or tolerances.flip_mean_fail is set; CIEDE2000 (result.ciede2000) always.
// Subpixel bits come from each frame's meta["subpixel_bits"] (8 when absent). Throws InputError
// when sizes differ or a frame's buffers do not match its size.
PairResult compareFrames(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                         const Tolerances& tolerances, ClassMaps* maps = nullptr);

// The defaults for a pair, from the frames' typed facts (Frame::drawn): depth and colour
// format (d24 and rgba32f when neither frame says) and whether a textured material is
// filtered linearly (the linear filtering allowance). Throws InputError when the two frames
// name different formats.
Tolerances tolerancesForFrames(const Frame& expected, const Frame& actual);

// What `rastercheck compare` gives for two frames, e.g. compareFrames(renderReference(s),
// renderGl(s, spec)): `expected` classifies; the tolerances are the formats' defaults and
// then the fixture's "tolerance" block the frames carry (compare/pair_tolerances.h).
// Command-line thresholds are the one layer left to the caller (the other overload).
PairResult compareFrames(const Frame& expected, const Frame& actual);

// Throws InputError naming both directories when the frames differ in size.
void checkSameSize(const Frame& expected, const Frame& actual,
                   const std::filesystem::path& expected_dir,
                   const std::filesystem::path& actual_dir);

}  // namespace rc
