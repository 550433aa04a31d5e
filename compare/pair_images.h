// The per-pair error images people look at (and the float diff.exr tools read): written
// from the frames and the ClassMaps of one comparison, all-or-nothing.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "compare/compare.h"

namespace rc {

// The colour map of both heat maps (an OpenImageIO ImageBufAlgo::color_map name).
inline constexpr const char* kHeatColorMap = "inferno";

using Rgb8 = std::array<std::uint8_t, 3>;

// visibility.png's colour for each class (match pixels are a dim grey of the expected
// image's luminance; this is the colour shown in the legend for them).
Rgb8 classColor(PixelClass c);
// Heat-map pixels that were not compared (background or a visibility mismatch), and
// compared pixels whose value is NaN or Inf.
inline constexpr Rgb8 kNotComparedColor = {40, 44, 52};
inline constexpr Rgb8 kNonFiniteColor = {0, 255, 255};

// `count` evenly spaced colours of OpenImageIO's colour map `map` from 0 to 1 (entry i is
// the map at i / (count - 1), each channel rounded to 8 bits).
std::vector<Rgb8> colorStops(int count, const char* map);

// The same for the heat colour map, for legends.
std::vector<Rgb8> heatColorStops(int count);

// Where a heat map value v lands on the colour map: log2(1 + v) / log2(1 + scale), in
// [0, 1]. Log-scaled so that one-step errors stay visible next to large ones.
float heatPosition(float value, double scale);

// A digest of a frame's size and colour buffer (16 hex digits). `render` records it in
// frame.json ("color_digest"), so that a reader can tell whether the folder's color.png
// still shows the colour in frame.exr.
std::string colorDigest(const Frame& frame);
// The same over everything a driver rendered: size, samples, colour, depth, ids, stencil
// and the per-sample planes (not the reference's uncertainty channels). Two renders with
// the same digest gave the same bits (`run --retries` tells a flake by it).
std::string frameDigest(const Frame& frame);
// Pixels where two frames of one size differ in any bit of colour, depth, id or stencil
// (multisampled: of a sample's id or depth too), and the first of them in row order.
std::uint64_t differingPixels(const Frame& a, const Frame& b, int* first_x, int* first_y);

// Ready-made 8-bit pictures of the two frames (the frame folders' color.png, which
// `render` writes from the same frame with the same conversion). When given, they are
// linked (or copied) as expected.png/actual.png instead of encoding the frames again.
struct PairPictures {
  std::filesystem::path expected;
  std::filesystem::path actual;
};

// Writes into `dir` (created if needed), all files concurrently: expected.png, actual.png,
// visibility.png, depth_heat.png, shading_heat.png and, with_diff_exr, diff.exr (float
// channels id_class, depth_steps, depth_tolerance, shading_abs, shading_tolerance, dR, dG,
// dB, dA; see docs/reports.md), and records them in result.images and the heat scales in
// result. Throws InputError when a file cannot be written; then none of them is left behind.
void writePairImages(const Frame& expected, const Frame& actual, const ClassMaps& maps,
                     const std::filesystem::path& dir, PairResult& result,
                     const PairPictures& pictures = {}, bool with_diff_exr = true);

// The files writePairImages writes into `dir` for these maps, by role (PairResult::images).
std::map<std::string, std::filesystem::path> pairImageNames(const std::filesystem::path& dir,
                                                            bool with_diff_exr,
                                                            const ClassMaps& maps);

// The values at the top of the two heat maps' colour scales (what writePairImages sets):
// max(largest error, fail threshold, 1) for depth steps and shading units.
void setHeatScales(PairResult& result);

// A folder for one pair's images under a report folder: <out>/pairs/<fixture>/<expected>
// _vs_<actual>, every name reduced to [A-Za-z0-9._-] (fixture "a/b" becomes "a_b") and
// to at most 100 characters.
std::filesystem::path pairDirectory(const std::filesystem::path& out_dir, const PairResult& result);

// The pair folders of one report, unique whatever the names: pairDirectory's choice, with
// "~2", "~3"... added to the fixture folder when another fixture's name reduces to the
// same one ("dup/a b" and "dup/a_b"), and to the pair folder when a fixture name has the
// same pair twice (two fixture files with one name). Deterministic in call order.
class PairFolders {
 public:
  std::filesystem::path take(const std::filesystem::path& out_dir, const PairResult& result);

 private:
  std::map<std::string, std::string> fixture_folder_;  // fixture name -> its folder
  std::set<std::string> fixture_folders_taken_;
  std::set<std::string> pair_folders_taken_;  // "<fixture folder>/<pair folder>"
};

}  // namespace rc
