// Shared by the conformance, catalog and mutation suites: rendering a fixture in a child
// process (`rastercheck render`, one driver per process) into a scratch folder that is
// removed when the test process exits, the skip-or-fail rule when no GL driver can start,
// and the expectations file of known differences (loaded and validated).
#pragma once

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/expectations.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc::conformance {

// The backends every fixture is checked against (osmesa only where it was built).
std::vector<std::string> backends();
// Every backend the suite knows, built or not: what expectations may name.
std::vector<std::string> knownBackends();

// This process's scratch folder (created on first use, removed at exit).
std::filesystem::path scratchRoot();

// Renders `fixture` with `spec` in a `rastercheck worker` process (the path `run` takes;
// the frame comes back through a pipe) and returns the frame. `fault` (e.g. "shift_x=0.5",
// a RASTERCHECK_GL_FAULT setting) applies to this render only; every render of a backend
// in this process reuses its worker. On failure returns nullopt and sets
// `error` to the one-line reason and `exit_code` to what `rastercheck render` exits with
// (2 bad fixture, 3 the backend could not render).
std::optional<Frame> renderInChild(const std::filesystem::path& fixture, const std::string& spec,
                                   std::string& error, int& exit_code,
                                   const std::string& fault = "");

// The reference render of a fixture, in this process (the same code path as
// `rastercheck render --backend ref`, without a child process: the reference is plain
// deterministic CPU code). Throws InputError on a bad fixture.
Frame renderReference(const std::filesystem::path& fixture);

// True when `spec` can render at all on this machine (a one-triangle scene), cached per
// process. When it cannot, GL tests skip, or fail under RASTERCHECK_REQUIRE_GL=1.
bool backendStarts(const std::string& spec, std::string& why);
bool glRequired();

// renderInChild for a GL backend. Only when the render fails with 3 is the probe scene tried
// (one process fewer per test on the usual path): if the backend cannot render even that,
// `unavailable` is set and the caller skips; a failure on this fixture alone is an error.
struct BackendRender {
  std::optional<Frame> frame;
  bool unavailable = false;
  std::string error;
  int exit_code = 0;
};
BackendRender renderWithBackend(const std::filesystem::path& fixture, const std::string& spec,
                                const std::string& fault = "");

// The classes ("visibility", "depth", "shading") whose status is fail in `result`.
std::set<std::string> failingClasses(const PairResult& result);

// The catalog folder and its fixtures' names (as written in each file's "name").
std::filesystem::path catalogDir();
std::vector<std::string> catalogNames();

// fixtures/expectations.json (compare/expectations.h), checked against the suite: an
// entry naming one fixture exactly must name a catalog fixture, and every backend pattern
// must match one of the suite's backends. `errors`: one line per problem (a parse error is
// one line too); never throws.
struct SuiteExpectations {
  Expectations parsed;
  std::vector<std::string> errors;
};
SuiteExpectations checkExpectations(const Expectations& parsed,
                                    const std::set<std::string>& fixtures,
                                    const std::vector<std::string>& backends);
// The file in the source tree, parsed and checked against the catalog (cached).
const SuiteExpectations& expectations();
std::filesystem::path expectationsFile();

// Writes the pair's images and a one-pair report under the build tree for a person to
// open after a failure; returns the report folder.
std::filesystem::path writeArtifacts(const std::string& test_name, const Frame& expected,
                                     const Frame& actual, const Frame& uncertainty,
                                     PairResult& result);

// Tolerances for the pair: compare/pair_tolerances.h pairTolerances (format defaults, then
// the fixture's overrides; the suite has no command line).
Tolerances tolerancesFor(const Scene& scene, const Frame& expected, const Frame& actual);

}  // namespace rc::conformance
