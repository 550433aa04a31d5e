// See report_support.h.
#include "app/report_support.h"

#include <fmt/format.h>

#include "compare/pair_images.h"
#include "fixtures/loader.h"

namespace rc {
namespace fs = std::filesystem;

PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const ToleranceOverrides& cli, const fs::path& out_dir) {
  Tolerances tol = tolerancesForFrames(expected, actual);
  if (expected.meta.contains("fixture_file") && expected.meta["fixture_file"].is_string()) {
    const fs::path fixture = expected.meta["fixture_file"].get<std::string>();
    if (fs::exists(fixture)) applyOverrides(tol, loadScene(fixture).tolerance);
  }
  applyOverrides(tol, cli);
  ClassMaps maps;
  PairResult result = compareFrames(expected, actual, uncertainty, tol, &maps);
  auto name = [](const Frame& f, const char* fallback) {
    return f.meta.contains("backend") && f.meta["backend"].is_string()
               ? f.meta["backend"].get<std::string>()
               : std::string(fallback);
  };
  result.expected = name(expected, "expected");
  result.actual = name(actual, "actual");
  if (expected.meta.contains("fixture") && expected.meta["fixture"].is_string())
    result.fixture = expected.meta["fixture"].get<std::string>();
  writePairImages(expected, actual, maps, pairDirectory(out_dir, result), result);
  return result;
}

void printSummary(const Report& report, const fs::path& out_dir, std::ostream& os) {
  for (const PairResult& r : report.results) {
    if (r.status != Status::Pass) os << describe(r) << '\n';
  }
  const ReportSummary s = report.summary();
  os << fmt::format("{} pairs: {} pass, {} warn, {} fail, {} error\n", s.total(), s.pass, s.warn,
                    s.fail, s.error);
  os << "report: " << (fs::absolute(out_dir) / "report.html").string() << '\n';
  os << (s.error ? "ERROR" : s.fail ? "FAILURE" : s.warn ? "WARNING" : "PASS") << '\n';
}

}  // namespace rc
