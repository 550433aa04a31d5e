// `rastercheck compare EXPECTED_DIR ACTUAL_DIR --out DIR`: one pair of frame folders,
// one report (report.json, junit.xml, report.html) with the pair's images.
#include <filesystem>
#include <future>
#include <iostream>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/report_support.h"
#include "app/version.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/resource_estimate.h"

namespace rc {
namespace fs = std::filesystem;

int compareCommand(const CompareArgs& args) {
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  cli.extra.flip_mean_fail = args.flip_threshold;
  {
    Tolerances check;  // a bad threshold is refused before anything is read
    applyOverrides(check, cli);
  }
  // Loading the image module (OpenImageIO and its ~260 libraries) keeps one core busy for
  // a good part of the whole command; meanwhile the other allocates and touches the frames'
  // buffers (fresh pages are the largest cost of reading a 1080p pair: perf record,
  // docs/performance.md). A hint only: the reads below use them where the sizes match.
  auto reserve = [](const fs::path& dir) {
    return std::async(std::launch::async, [dir] { return reserveFrame(dir); });
  };
  std::future<Frame> expected_storage = reserve(args.expected);
  std::future<Frame> actual_storage = reserve(args.actual);
  std::future<Frame> third_storage;
  if (!args.uncertainty.empty()) third_storage = reserve(args.uncertainty);
  // The frames' memory within the limit before either is read (fixtures/resource_estimate.h).
  for (const fs::path& dir : {args.expected, args.actual}) {
    const auto [width, height] = readFrameSize(dir);
    checkComparison(dir.string(), width, height, ResourceLimits::current());
  }
  // The frames are independent files: read them concurrently (decompression dominates),
  // each with the check that its color.png can be reused (a digest of the whole frame).
  struct Read {
    Frame frame;
    fs::path picture;
    ClassMaps maps;  // reserved by the actual frame's reader (it usually finishes first)
  };
  auto read = [](const fs::path& dir, bool picture, std::future<Frame>& storage, bool maps) {
    return std::async(std::launch::async,
                      [dir, picture, maps, storage = std::move(storage)]() mutable {
                        Read r{readFrameDir(dir, storage.get()), {}};
                        if (picture) r.picture = readyPicture(dir, r.frame);
                        if (maps) reserveMaps(r.maps, r.frame.width, r.frame.height);
                        return r;
                      });
  };
  std::future<Read> expected_f = read(args.expected, true, expected_storage, false);
  std::future<Read> actual_f = read(args.actual, true, actual_storage, true);
  std::future<Read> third_f;
  if (!args.uncertainty.empty()) third_f = read(args.uncertainty, false, third_storage, false);
  const Read expected_read = expected_f.get();
  Read actual_read = actual_f.get();
  const Frame& expected = expected_read.frame;
  const Frame& actual = actual_read.frame;
  checkSameSize(expected, actual, args.expected, args.actual);
  Frame third;
  const Frame* uncertainty = &expected;
  if (third_f.valid()) {
    third = third_f.get().frame;
    checkSameSize(expected, third, args.expected, args.uncertainty);
    uncertainty = &third;
  } else if (!expected.hasUncertainty() && actual.hasUncertainty()) {
    uncertainty = &actual;  // comparing a driver against the reference the other way round
  }
  const Tolerances tolerances =
      pairTolerances(expected, actual, fixtureTolerance(expected, actual), cli);

  ReportFolder folder(args.out);
  Report report;
  report.tool_version = kVersion;
  report.command = "compare";
  const PairPictures pictures{expected_read.picture, actual_read.picture};
  report.results.push_back(comparePair(expected, actual, *uncertainty, tolerances, folder, pictures,
                                       args.diff_exr, args.flip, std::move(actual_read.maps)));
  folder.commit(report);
  printSummary(report, args.out, std::cout);
  return exitCodeFor(report);
}

}  // namespace rc
