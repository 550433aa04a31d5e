// `rastercheck compare EXPECTED_DIR ACTUAL_DIR --out DIR`: one pair of frame folders,
// one report (report.json, junit.xml, report.html) with the pair's images.
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/report_support.h"
#include "app/version.h"
#include "compare/compare.h"
#include "compare/pair_images.h"
#include "compare/report.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"

namespace rc {
namespace fs = std::filesystem;

int compareCommand(const CompareArgs& args) {
  ToleranceOverrides cli;
  parseToleranceArgs(args.tolerance, cli);
  const Frame expected = readFrameDir(args.expected);
  const Frame actual = readFrameDir(args.actual);
  checkSameSize(expected, actual, args.expected, args.actual);
  Frame third;
  const Frame* uncertainty = &expected;
  if (!args.uncertainty.empty()) {
    third = readFrameDir(args.uncertainty);
    checkSameSize(expected, third, args.expected, args.uncertainty);
    uncertainty = &third;
  } else if (!expected.hasUncertainty() && actual.hasUncertainty()) {
    uncertainty = &actual;  // comparing a driver against the reference the other way round
  }

  PairResult result = comparePair(expected, actual, *uncertainty, cli, args.out);
  Report report;
  report.tool_version = kVersion;
  report.command = "compare";
  report.results.push_back(std::move(result));
  writeReport(report, args.out);
  printSummary(report, args.out, std::cout);
  return exitCodeFor(report);
}

}  // namespace rc
