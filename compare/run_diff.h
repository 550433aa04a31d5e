// Runs against runs (`rastercheck diff-runs OLD NEW`, like piglit's summary): two run
// reports matched pair by pair (fixture, expected, actual) and sorted into regressions
// (the verdict got worse), fixes (better), changes (same verdict, a class's verdict or
// pixel count moved), new and vanished pairs, with per class the verdict transitions and
// the pixels that moved. Text for terminals, JSON for tools, one HTML page for people.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/report.h"

namespace rc {

// One class of one pair in one run: its verdict and the pixels behind it (visibility:
// hard mismatches; depth and shading: pixels over tolerance).
struct ClassState {
  Status status = Status::Pass;
  std::uint64_t pixels = 0;
};
inline constexpr std::array<const char*, 3> kDiffClasses = {"visibility", "depth", "shading"};

struct PairState {
  Status status = Status::Pass;
  std::array<ClassState, 3> classes{};
  std::string error;  // error rows: why
};

struct PairDiff {
  enum class Kind { Regression, Fix, Changed, Unchanged, New, Vanished };
  Kind kind = Kind::Unchanged;
  std::string fixture;
  std::string expected;
  std::string actual;
  std::optional<PairState> before;  // absent: new
  std::optional<PairState> after;   // absent: vanished
};
const char* toString(PairDiff::Kind kind);

struct RunDiff {
  std::string old_name;  // as given, for the headings
  std::string new_name;
  std::vector<PairDiff> pairs;  // every pair of either run: the old run's order, then new ones
  std::size_t count(PairDiff::Kind kind) const;
  // Pairs in both runs whose class c went from status a to status b: transitions[c][a][b].
  std::array<std::array<std::array<std::uint64_t, kStatusCount>, kStatusCount>, 3> transitions{};
  // Pixels of class c summed over the pairs in both runs, before and after.
  std::array<std::array<std::uint64_t, 2>, 3> pixels{};
};

RunDiff diffRuns(const Report& before, const Report& after, std::string old_name,
                 std::string new_name);

// Exit code: 1 when anything regressed, else 0.
int exitCodeFor(const RunDiff& diff);

std::string runDiffText(const RunDiff& diff);
nlohmann::json runDiffJson(const RunDiff& diff);
std::string runDiffHtml(const RunDiff& diff);

}  // namespace rc
