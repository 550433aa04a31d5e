// Glue shared by `compare` and `run`: one pair compared with every tolerance source
// applied and its images written, the report folder written all-or-nothing, and the
// closing summary a terminal user reads.
#pragma once

#include <filesystem>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "compare/compare.h"
#include "compare/expectations.h"
#include "compare/pair_images.h"
#include "compare/pair_tolerances.h"
#include "compare/report.h"
#include "compare/tolerances.h"
#include "fixtures/frame.h"
#include "fixtures/output_folder.h"
#include "fixtures/scene.h"
#include "reference/reference_renderer.h"

namespace rc {

// The known differences `run --expectations ARG` applies: ARG a file, "none" (no entries),
// or empty for defaultExpectationsFile() when it exists. `campaign` re-applies the same
// file to its runs' reports. Throws InputError for a file that cannot be read or is invalid.
Expectations expectationsFromArgument(const std::string& arg);

class ReportFolder;

// Compares without writing anything: the result named from the frames' frame.json
// (fixture, backends, fixture file, tags, driver stacks), with its heat scales; `maps` as
// compareFrames.
PairResult compareNamed(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                        const Tolerances& tolerances, ClassMaps* maps);

// Compares and writes the pair's images into the report folder (a folder of its own for
// every pair: ReportFolder::pairDirectory); diff.exr only when the pair does not pass,
// unless diff_exr_when_passing; LDR-FLIP and flip_heat.png when flip (or a FLIP threshold).
// `maps`: buffers for the comparison's maps (reserveMaps()), or none.
PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const Tolerances& tolerances, ReportFolder& folder,
                       const PairPictures& pictures = {}, bool diff_exr_when_passing = true,
                       bool flip = false, ClassMaps&& maps = ClassMaps{});

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
// Whether resampleReference(ref, gl, ...) would render again (cheap: frame.json only).
bool needsResample(const Frame& ref, const Frame& gl);

// A frame folder's color.png when it shows `frame` (frame.json's "color_digest", written
// by `render`, matches the frame that was read), else empty: then the comparator encodes
// the picture itself.
std::filesystem::path readyPicture(const std::filesystem::path& frame_dir, const Frame& frame);

// A report folder replaced whole (fixtures/output_folder.h): everything is written under
// staging(); commit() writes the report files there and puts the folder in place in one
// step. Files of the user's in an earlier report folder are kept; what an earlier run
// wrote (frames/, pairs/, variants/, the report files) goes. Destroyed without commit(),
// nothing of it remains and the earlier outputs are as they were.
class ReportFolder {
 public:
  // The top-level names a report folder's writers use.
  static const std::vector<std::string>& ownedNames();

  // Throws InputError when `out` exists and is not a folder, or cannot be staged.
  explicit ReportFolder(std::filesystem::path out);

  const std::filesystem::path& path() const { return folder_.target(); }
  const std::filesystem::path& staging() const { return folder_.staging(); }
  // A fresh folder under staging() for one pair's images, unique whatever the names.
  // Thread-safe: `run` compares fixtures on several threads.
  std::filesystem::path pairDirectory(const PairResult& result) {
    const std::lock_guard lock(pairs_mutex_);
    return pairs_.take(staging(), result);
  }
  void commit(const Report& report);

 private:
  OutputFolder folder_;
  std::mutex pairs_mutex_;
  PairFolders pairs_;
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
