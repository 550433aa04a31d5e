// Known, understood driver differences (fixtures/expectations.json): which failures a run,
// the conformance suite, the accuracy report and campaigns expect, each scoped so that a
// known difference does not hide others: to fixtures (a name or a glob), backends (a '*'
// part matches one ':'-separated part), the driver version the actual side reported, and
// the fixture's render state (e.g. softpipe with d16) and tags. One parser and one matcher for
// every user of the file.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/report.h"

namespace rc {

struct Expectation {
  std::string id;              // short name reports show ("softpipe-z16-depth-step")
  std::string fixture = "*";   // fixture name or glob (* and ?)
  std::string backend;         // backend SPEC pattern: "gl:*:softpipe"
  std::string driver_version;  // glob over the actual side's GL version string; "" = any
  std::map<std::string, std::string> state;  // render state key -> value (as in the fixture)
  // Tags the fixture must all carry (e.g. the random generator's "clear:wide-color"): for a
  // difference that needs a scene property no render state key names.
  std::vector<std::string> tags;
  std::string cls;  // visibility | depth | shading
  std::string reason;
  // The conformance suite also fails when the listed class passes (an expected failure
  // that went away). Default: true for an entry naming one fixture exactly, false for a
  // pattern (a difference that shows only where the scene provokes it).
  bool strict = true;
};

struct Expectations {
  std::vector<Expectation> entries;
};

// Parses and validates an expectations document. Throws InputError naming `source`, the
// JSON path and the problem (unknown key, wrong type, unknown class or state key, empty
// reason, a repeated id).
Expectations parseExpectations(const nlohmann::json& doc, const std::string& source);
// Reads `file` (InputError when it cannot be read or parsed).
Expectations readExpectations(const std::filesystem::path& file);

// '*' matches any run of characters, '?' one.
bool globMatches(const std::string& pattern, const std::string& text);
// A backend pattern: '*' as a whole ':'-separated part matches that part.
bool backendMatches(const std::string& pattern, const std::string& backend);

// What an entry is matched against: one compared pair.
struct PairContext {
  std::string fixture;
  std::string backend;         // the actual side's SPEC
  std::string driver_version;  // the actual side's GL version string ("" for the reference)
  nlohmann::json state = nlohmann::json::object();  // the fixture's render state
  std::vector<std::string> tags;                    // the fixture's tags
};
PairContext contextOf(const PairResult& result);

// Whether the entry covers the pair (its class is not looked at).
bool covers(const Expectation& e, const PairContext& pair);

// The entries that cover the pair and name `cls`.
std::vector<const Expectation*> expectationsFor(const Expectations& x, const PairContext& pair,
                                                const std::string& cls);

// The known failures of one pair: for each failing class the entries that cover it, or
// none at all unless every failing class is covered (a pair is known as a whole).
std::vector<KnownFailure> knownFailuresOf(const Expectations& x, const PairResult& r);

// Marks every failed pair whose failing classes are all covered as known (PairResult::known:
// the ids and reasons), so reports can tell expected failures from new ones.
void applyExpectations(const Expectations& x, Report& report);

}  // namespace rc
