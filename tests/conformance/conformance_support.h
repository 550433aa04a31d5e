// Shared by the conformance and mutation suites: rendering a fixture with a GL backend in
// a child process (`rastercheck render`, one driver per process), the skip-or-fail rule
// when no GL driver can start, and the expectations file of known differences.
#pragma once

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "compare/compare.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"

namespace rc::conformance {

// The backends every fixture is checked against (osmesa only where it was built).
std::vector<std::string> backends();

// Renders `fixture` with `spec` through the rastercheck binary into a scratch folder and
// reads the frame back. On failure returns nullopt and sets `error` to the child's last
// line and `exit_code` to its exit code.
std::optional<Frame> renderInChild(const std::filesystem::path& fixture, const std::string& spec,
                                   std::string& error, int& exit_code);

// True when `spec` can render at all on this machine (a one-triangle scene), cached per
// process. When it cannot, conformance tests skip, or fail under RASTERCHECK_REQUIRE_GL=1.
bool backendStarts(const std::string& spec, std::string& why);
bool glRequired();

// The classes ("visibility", "depth", "shading") whose status is fail in `result`.
std::set<std::string> failingClasses(const PairResult& result);

// tests/conformance/expectations.json: known, understood differences. Each entry names a
// fixture, a backend (exact, or with '*' as a wildcard for one ':'-separated part), a
// class that is expected to fail, and the reason.
struct Expectation {
  std::string fixture;
  std::string backend;
  std::string cls;
  std::string reason;
};
const std::vector<Expectation>& expectations();
bool backendMatches(const std::string& pattern, const std::string& backend);
std::vector<Expectation> expectationsFor(const std::string& fixture, const std::string& backend);

// Writes the pair's images and a one-pair report under the build tree for a person to
// open after a failure; returns the report folder.
std::filesystem::path writeArtifacts(const std::string& test_name, const Frame& expected,
                                     const Frame& actual, const Frame& uncertainty,
                                     PairResult& result);

// Tolerances for the pair: format defaults plus the fixture's overrides.
Tolerances tolerancesFor(const Scene& scene, const Frame& expected, const Frame& actual);

}  // namespace rc::conformance
