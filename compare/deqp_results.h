// deqp-runner's files, so that a driver team's CI adopts a run without glue (docs/ci.md):
// a stable test name per pair, its status in deqp-runner's vocabulary, results.csv and
// failures.csv as deqp-runner writes them, and its baseline (`name,Status` lines), flakes
// and skips (one regular expression per line) applied the way deqp-runner applies them.
//
// Facts taken from deqp-runner (runner_results.rs, lib.rs; 0.1x to 0.20): results.csv is
// `name,Status,duration` (seconds, shortest float form), no header, sorted by name;
// failures.csv is `name,Status` of the rows that are not a success; a baseline skips
// blank lines and lines starting with '#', reads the first two comma-separated fields, and
// refuses unknown statuses and duplicate names; flakes and skips lines are regular
// expressions found anywhere in the name (not anchored), blank and '#' lines skipped.
#pragma once

#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "compare/compare.h"

namespace rc {

struct Report;

// "<fixture>@<actual>", and "@<expected>" after it when the pair is not compared with the
// reference: e.g. "shading/blinn_phong_sphere@gl:egl:llvmpipe". Commas and line breaks
// (in a fixture's name) become '_'.
std::string testName(const PairResult& r);

// What the row is in deqp-runner's words before any baseline: Pass (pass), Warn (warn),
// Fail (fail), ExpectedFail (a fail fixtures/expectations.json covers), Crash (error),
// Timeout (an error from the --timeout watchdog), Skip (not_supported), Flake (flake).
std::string runnerStatus(const PairResult& r);

// Whether deqp-runner counts the status as a success: Pass, Warn, Skip, Flake, KnownFlake,
// ExpectedFail. (Fail, Crash, Missing, Timeout, UnexpectedPass and UnexpectedImprovement(...)
// are not.)
bool runnerSuccess(const std::string& status);

// A baseline file: test name -> expected status. Throws InputError naming file:line for
// a line that is not `name,Status`, an unknown status or a name listed twice.
struct RunnerBaseline {
  std::map<std::string, std::string> expected;
};
RunnerBaseline readRunnerBaseline(const std::filesystem::path& file);

// One regular expression per line (ECMAScript syntax, matched anywhere in the name).
// Throws InputError naming file:line for a pattern that does not compile.
struct RunnerPatterns {
  std::vector<std::string> patterns;
  std::vector<std::regex> compiled;
  bool matches(const std::string& name) const;
};
RunnerPatterns readRunnerPatterns(const std::filesystem::path& file);

// deqp-runner's baseline rule for one test: `now` as runnerStatus() gives it, `baseline`
// the file's status ("" when the test is not listed). E.g. Fail listed Fail: ExpectedFail;
// Pass listed Fail, Crash, Missing or Timeout: UnexpectedPass; Crash listed Crash or
// ExpectedFail: ExpectedFail; Fail listed Crash or Timeout: UnexpectedImprovement(Fail).
std::string withBaseline(const std::string& now, const std::string& baseline);

// The run's deqp-runner files and verdict: given any of the three files, every row gets its
// runner_status (baseline, then flakes: a row still failing that a flakes pattern matches
// is KnownFlake), and the report's exit code follows them (exitCodeFor).
struct RunnerFiles {
  std::filesystem::path baseline_file, flakes_file, skips_file;
  RunnerBaseline baseline;
  RunnerPatterns flakes, skips;
  bool any() const { return !baseline_file.empty() || !flakes_file.empty() || !skips_file.empty(); }
};
RunnerFiles readRunnerFiles(const std::filesystem::path& baseline,
                            const std::filesystem::path& flakes,
                            const std::filesystem::path& skips);
void applyRunnerFiles(const RunnerFiles& files, Report& report);

// results.csv and failures.csv of a report (rows with their runner_status when set, else
// runnerStatus(); the report's skipped tests as Skip with duration 0).
std::string resultsCsv(const Report& report);
std::string failuresCsv(const Report& report);

}  // namespace rc
