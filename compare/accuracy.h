// The accuracy report (docs/accuracy.md): reads the report.json of one or more
// `rastercheck run` folders, finds each fixture's tags, and tabulates verdicts and error
// statistics per driver, per topic (tag) and per fixture, plus the differences between
// two drivers compared with each other, with the pixels to look at. It does not render
// or compare; `rastercheck accuracy` is its command.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/expectations.h"
#include "compare/tolerances.h"

namespace rc {

// One row of a report.json, reduced to what the tables show.
struct AccuracyPair {
  std::string fixture;
  std::string expected;  // backend specs
  std::string actual;
  std::vector<std::string> tags;  // empty when the fixture file could not be found
  Status status = Status::Pass;
  std::string error;
  Status visibility_status = Status::Pass;
  Status depth_status = Status::Pass;
  Status shading_status = Status::Pass;
  int height = 0;
  std::uint64_t pixels = 0;
  int expected_subpixel_bits = 0;  // 0: not in the report
  int actual_subpixel_bits = 0;
  // visibility
  std::uint64_t mismatched = 0;
  std::uint64_t ambiguous = 0;
  std::uint64_t hard = 0;
  std::uint64_t ambiguous_by_depth_gap = 0;
  std::optional<PixelRef> visibility_worst;
  // depth (steps of the fixture's depth format)
  std::uint64_t depth_compared = 0;
  double depth_max = 0.0;
  double depth_mean = 0.0;
  double depth_p99 = 0.0;
  std::uint64_t depth_over = 0;
  std::optional<PixelRef> depth_worst;
  // shading (8-bit units, largest channel)
  std::uint64_t shading_compared = 0;
  double shading_max = 0.0;
  double shading_mean = 0.0;
  double shading_rmse = 0.0;
  std::optional<double> psnr_db;
  std::uint64_t shading_over = 0;
  std::optional<PixelRef> shading_worst;
  // perceptual error (report.json "flip"), when the report has it
  std::optional<double> flip_mean;
  double flip_max = 0.0;
  // CIEDE2000 (report.json "ciede2000"), when the report has it
  std::optional<double> ciede2000_mean;
  double ciede2000_max = 0.0;
  // against ref:abuffer (report.json "oit"), when the report has it
  bool oit = false;
  std::uint64_t oit_blended = 0;
  std::uint64_t oit_unsorted = 0;
  std::uint64_t oit_pixels = 0;  // over the shading warn threshold
  double oit_max_abs = 0.0;
  double oit_mean_abs = 0.0;
  std::uint64_t oit_pairs = 0;  // triangle pairs blended out of depth order
};

struct AccuracyData {
  std::vector<std::string> sources;  // the run folders, as given
  std::vector<AccuracyPair> pairs;   // sorted by expected, actual, fixture
  Expectations known;                // fixtures/expectations.json, listed in the document
  // report.json "variants" of every run, by backend SPEC (the last run read wins): the
  // driver stack, the probed legal variants and the findings (app/variants.h).
  std::map<std::string, nlohmann::json> variants;
};

// Reads report.json from each run folder. A fixture's tags come from the fixture file
// its frames name (frames/*/*/frame.json "fixture_file"), else from a fixture of that
// name under `catalogs`. A pair that appears in several runs keeps the last one read.
// Throws InputError naming the file and JSON path on a missing or malformed report.
AccuracyData readAccuracyRuns(const std::vector<std::filesystem::path>& runs,
                              const std::vector<std::filesystem::path>& catalogs);

// The Markdown document. `command` (Markdown) is printed as the way to regenerate it.
std::string accuracyMarkdown(const AccuracyData& data, const std::string& command);

}  // namespace rc
