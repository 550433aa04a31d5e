// Glue shared by `compare` and `run`: one pair compared with every tolerance source
// applied and its images written, and the closing summary a terminal user reads.
#pragma once

#include <filesystem>
#include <ostream>

#include "compare/compare.h"
#include "compare/report.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc {

// Tolerances: the formats' defaults, then the fixture's "tolerance" (loaded from
// expected.meta["fixture_file"] when that file still exists), then the command line.
// Writes the pair's images under out_dir and returns the result.
PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const ToleranceOverrides& cli, const std::filesystem::path& out_dir);

// A table of every non-passing pair, the counts, the report path and a closing
// PASS / WARNING / FAILURE line (idiff style).
void printSummary(const Report& report, const std::filesystem::path& out_dir, std::ostream& os);

}  // namespace rc
