// The tolerances a pair is judged by, in their three layers: the defaults of the pair's
// formats (tolerancesForFrames), then the fixture's own "tolerance" block, then the
// command line (`--tolerance CLASS.KEY=VALUE`). `compare`, `run`, `explain`, `reduce`, the
// mutation study and the conformance suite all take them from here.
#pragma once

#include <string>
#include <vector>

#include "compare/tolerances.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc {

// The fixture's own tolerance block for a pair: frame.json "tolerance" (recorded by
// `render`; the expected side's, else the actual side's), else the fixture file named by
// frame.json "fixture_file" when it still exists, else none. Throws InputError for a
// malformed block.
ToleranceOverrides fixtureTolerance(const Frame& expected, const Frame& actual);

// Tolerances of a pair: the formats' defaults, then `fixture`, then the command line.
Tolerances pairTolerances(const Frame& expected, const Frame& actual,
                          const ToleranceOverrides& fixture, const CommandLineTolerances& cli = {});

// Adds `--tolerance CLASS.KEY=VALUE` arguments (keys: visibility|depth|shading .warn|fail,
// depth.slope_factor, shading.relative, shading.slope_factor, visibility.band) to `out`.
// Throws InputError (one line naming the argument) for a malformed one, and for a warn
// above its fail, before anything is rendered or read.
void parseToleranceArgs(const std::vector<std::string>& args, CommandLineTolerances& out);

}  // namespace rc
