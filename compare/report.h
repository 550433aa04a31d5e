// Reports of a set of comparisons: report.json (the contract in ../shared/DESIGN.md plus
// the fields docs/report-schema.json lists), junit.xml for CI, and report.html for people.
// docs/reports.md says what each file holds.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"

namespace rc {

inline constexpr const char* kReportFormat = "rastercheck-report/1";

struct ReportSummary {
  std::uint64_t pass = 0;
  std::uint64_t warn = 0;
  std::uint64_t fail = 0;
  std::uint64_t error = 0;
  std::uint64_t known_fail = 0;     // of `fail`, those an expectation covers
  std::uint64_t not_supported = 0;  // the backend cannot render the fixture: no verdict
  std::uint64_t flake = 0;          // renders that disagreed when retried: no verdict
  std::uint64_t total() const { return pass + warn + fail + error + not_supported + flake; }
};

struct Report {
  std::string tool_name = "rastercheck";
  std::string tool_version;
  std::string command;  // the command line that produced it, when known
  std::vector<PairResult> results;
  // Per GL backend, the legal variants it follows (app/variants.h; empty: not probed).
  nlohmann::json variants = nlohmann::json::object();
  // A part of a sharded run (`run --shard K/N`): which part, and where its rows go in the
  // whole run, for `merge` (compare/merge.h). Empty for a whole run.
  nlohmann::json shard = nlohmann::json::object();
  // deqp-runner's view (compare/deqp_results.h): the tests `--skips` left out (written to
  // results.csv as Skip), and, when a baseline, flakes or skips file was applied, what was
  // applied and whether the run matches it (report.json "runner"); empty otherwise.
  std::vector<std::string> skipped;
  nlohmann::json runner = nlohmann::json::object();

  ReportSummary summary() const;
};

// Exit status of a command that produced this report. With deqp-runner files applied
// (report.runner): 0 when every row's runner_status is a success (the run matches its
// baseline), 3 when a row is an unexpected Crash or Timeout, else 1. Without: 3 when any
// row is an error (a backend could not run), else 1 when any comparison failed that no
// expectation covers, else 0 (warnings, known failures and flakes pass).
int exitCodeFor(const Report& report);

// report.json content. Image paths are written relative to report_dir (the folder the
// report goes to), with '/' separators. Non-finite numbers become null.
nlohmann::json toJson(const PairResult& result, const std::filesystem::path& report_dir);
nlohmann::json toJson(const Report& report, const std::filesystem::path& report_dir);

// One line on a pair, e.g. "FAIL shading/sphere ref vs gl:egl:llvmpipe: depth: 12 px over
// tolerance, max 40 steps, worst (3,4) window (3,251)". Failing (else warning) classes
// only; just "PASS <fixture> <expected> vs <actual>" when all pass.
std::string describe(const PairResult& result);

// The junit.xml and report.html texts (report_dir as for toJson).
std::string junitXml(const Report& report);
std::string reportHtml(const Report& report, const std::filesystem::path& report_dir);

// Writes report.json, junit.xml and report.html into out_dir (created if needed), all or
// none. Throws InputError when they cannot be written.
void writeReport(const Report& report, const std::filesystem::path& out_dir);

}  // namespace rc
