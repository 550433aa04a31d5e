// Glue shared by `compare` and `run`: one pair compared with every tolerance source
// applied and its images written, the report folder written all-or-nothing, and the
// closing summary a terminal user reads.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>

#include "compare/compare.h"
#include "compare/pair_images.h"
#include "compare/report.h"
#include "compare/tolerances.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "reference/reference_renderer.h"

namespace rc {

// The fixture's own tolerance block for a pair: frame.json "tolerance" (recorded by
// `render`; the expected side's, else the actual side's), else the fixture file named by
// frame.json "fixture_file" when it still exists, else none. Throws InputError for a
// malformed block.
ToleranceOverrides fixtureTolerance(const Frame& expected, const Frame& actual);

// Tolerances of a pair: the formats' defaults, then `fixture`, then the command line.
Tolerances pairTolerances(const Frame& expected, const Frame& actual,
                          const ToleranceOverrides& fixture, const CommandLineTolerances& cli);

// Compares and writes the pair's images under out_dir (pairDirectory).
PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const Tolerances& tolerances, const std::filesystem::path& out_dir,
                       const PairPictures& pictures = {});

// A report row for a pair whose render failed with `message`: status not_supported when
// the message says the backend does not support the fixture, else error.
PairResult failedRenderResult(std::string fixture, std::string expected, std::string actual,
                              const std::string& message);

// A multisampled reference frame samples where the driver it is compared with does: when
// `gl`'s frame.json "multisample" positions differ from `ref`'s, `ref` is rendered again
// (with `options` and those positions) from the fixture file, keeping its frame.json keys.
// Nothing happens for single-sample frames or frames without positions.
void resampleReference(Frame& ref, const Frame& gl, const std::filesystem::path& scene_file,
                       ReferenceOptions options);

// A frame folder's color.png when it shows `frame` (frame.json's "color_digest", written
// by `render`, matches the frame that was read), else empty: then the comparator encodes
// the picture itself.
std::filesystem::path readyPicture(const std::filesystem::path& frame_dir, const Frame& frame);

// A report folder written all-or-nothing. Everything goes to a staging folder inside it;
// commit() writes the report there, then removes what an earlier run left (the files its
// report.json names, and the pairs/ and frames/ folders and report files this tool
// writes) and moves the new outputs in. Destroyed without commit(), it removes the
// staging folder (and `out` itself when it created it), leaving earlier outputs as they
// were.
class ReportFolder {
 public:
  // Throws InputError when `out` exists and is not a folder, or cannot be created.
  explicit ReportFolder(std::filesystem::path out);
  ReportFolder(const ReportFolder&) = delete;
  ReportFolder& operator=(const ReportFolder&) = delete;
  ~ReportFolder();

  const std::filesystem::path& path() const { return out_; }
  const std::filesystem::path& staging() const { return staging_; }
  void commit(const Report& report);

 private:
  std::filesystem::path out_;
  std::filesystem::path staging_;
  bool created_out_ = false;
  bool committed_ = false;
};

// Closing lines (idiff style): one line per non-passing pair, a fixture x backend table
// (only the fixtures with a non-passing pair when there are many), the counts, the
// report path and PASS / WARNING / FAILURE / ERROR.
void printSummary(const Report& report, const std::filesystem::path& out_dir, std::ostream& os);

// The table alone: one row per fixture, one column per actual backend; a cell is the
// status and the pair's key numbers (hard visibility px, depth max steps, shading max
// units). With more than `max_rows` fixtures, only those with a non-passing pair.
std::string summaryTable(const Report& report, std::size_t max_rows = 40);

}  // namespace rc
