// deqp-runner's files: see deqp_results.h.
#include "compare/deqp_results.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "compare/report.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;

namespace {

// Every status deqp-runner writes (0.1x: UnexpectedPass; 0.20: UnexpectedImprovement(X)).
constexpr std::array<const char*, 11> kStatuses = {
    "Pass", "Fail",         "Skip",    "Crash",          "Flake",  "KnownFlake",
    "Warn", "ExpectedFail", "Timeout", "UnexpectedPass", "Missing"};

bool knownStatus(const std::string& s) {
  if (std::find_if(kStatuses.begin(), kStatuses.end(), [&](const char* k) { return s == k; }) !=
      kStatuses.end())
    return true;
  const std::string prefix = "UnexpectedImprovement(";
  if (s.size() > prefix.size() + 1 && s.compare(0, prefix.size(), prefix) == 0 && s.back() == ')')
    return knownStatus(s.substr(prefix.size(), s.size() - prefix.size() - 1));
  return false;
}

// The lines of a text file with their 1-based numbers, '\r' dropped; InputError when it
// cannot be read.
std::vector<std::pair<int, std::string>> lines(const fs::path& file, const char* what) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot read the {} file", file.string(), what));
  std::vector<std::pair<int, std::string>> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.emplace_back(n, line);
  }
  return out;
}

double durationOf(const PairResult& r) { return r.render_seconds + r.seconds; }

struct Row {
  std::string name;
  std::string status;
  double seconds;
};

std::vector<Row> rows(const Report& report) {
  std::vector<Row> out;
  out.reserve(report.results.size() + report.skipped.size());
  for (const PairResult& r : report.results)
    out.push_back(
        {testName(r), r.runner_status.empty() ? runnerStatus(r) : r.runner_status, durationOf(r)});
  for (const std::string& name : report.skipped) out.push_back({name, "Skip", 0.0});
  // deqp-runner sorts by name (byte order).
  std::sort(out.begin(), out.end(), [](const Row& a, const Row& b) { return a.name < b.name; });
  return out;
}

}  // namespace

std::string testName(const PairResult& r) {
  std::string name = r.fixture + "@" + r.actual;
  if (r.expected != "ref") name += "@" + r.expected;
  // The files are comma-separated lines: a comma or line break in a fixture's name would
  // split its line.
  for (char& c : name)
    if (c == ',' || c == '\n' || c == '\r') c = '_';
  return name;
}

std::string runnerStatus(const PairResult& r) {
  switch (r.status) {
    case Status::Pass:
      return "Pass";
    case Status::Warn:
      return "Warn";
    case Status::Fail:
      return r.known.empty() ? "Fail" : "ExpectedFail";
    case Status::Error:
      // The watchdog's words (app/worker_pool.cpp): a render that never returned.
      return r.error.find("timed out") != std::string::npos ? "Timeout" : "Crash";
    case Status::NotSupported:
      return "Skip";
    case Status::Flake:
      return "Flake";
  }
  return "Fail";
}

bool runnerSuccess(const std::string& status) {
  return status == "Pass" || status == "Warn" || status == "Skip" || status == "Flake" ||
         status == "KnownFlake" || status == "ExpectedFail";
}

RunnerBaseline readRunnerBaseline(const fs::path& file) {
  RunnerBaseline out;
  for (const auto& [n, line] : lines(file, "baseline")) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t comma = line.find(',');
    const std::string at = fmt::format("{}:{}", file.string(), n);
    if (comma == 0 || comma == std::string::npos)
      throw InputError(fmt::format("{}: \"{}\": expected NAME,Status", at, line));
    const std::size_t end = line.find(',', comma + 1);
    const std::string name = line.substr(0, comma);
    const std::string status =
        line.substr(comma + 1, end == std::string::npos ? std::string::npos : end - comma - 1);
    if (!knownStatus(status))
      throw InputError(
          fmt::format("{}: unknown status \"{}\" (deqp-runner's: Pass, Fail, Skip, Crash, Flake, "
                      "KnownFlake, Warn, ExpectedFail, Timeout, Missing, UnexpectedPass, "
                      "UnexpectedImprovement(...))",
                      at, status));
    if (!out.expected.emplace(name, status).second)
      throw InputError(fmt::format("{}: {} is listed twice", at, name));
  }
  return out;
}

RunnerPatterns readRunnerPatterns(const fs::path& file) {
  RunnerPatterns out;
  for (const auto& [n, line] : lines(file, "pattern")) {
    if (line.empty() || line[0] == '#') continue;
    try {
      out.compiled.emplace_back(line, std::regex::ECMAScript | std::regex::optimize);
    } catch (const std::regex_error& e) {
      throw InputError(fmt::format("{}:{}: \"{}\" is not a regular expression: {}", file.string(),
                                   n, line, e.what()));
    }
    out.patterns.push_back(line);
  }
  return out;
}

bool RunnerPatterns::matches(const std::string& name) const {
  return std::any_of(compiled.begin(), compiled.end(),
                     [&](const std::regex& re) { return std::regex_search(name, re); });
}

std::string withBaseline(const std::string& now, const std::string& baseline) {
  const auto listed = [&](std::initializer_list<const char*> any) {
    return std::any_of(any.begin(), any.end(), [&](const char* s) { return baseline == s; });
  };
  if (now == "Fail") {
    if (listed({"Fail", "ExpectedFail"})) return "ExpectedFail";
    if (listed({"Crash", "Timeout"})) return "UnexpectedImprovement(Fail)";
    return now;
  }
  if (now == "Pass" || now == "Skip") {
    // deqp-runner 0.1x called the first UnexpectedPass, as docs/ci.md and this harness do.
    if (listed({"Fail", "Crash", "Missing", "Timeout"}))
      return now == "Pass" ? "UnexpectedPass" : "UnexpectedImprovement(Skip)";
    return now;
  }
  if (now == "Crash") return listed({"Crash", "ExpectedFail"}) ? "ExpectedFail" : now;
  if (now == "Warn") {
    if (listed({"Warn"})) return "ExpectedFail";
    if (listed({"Fail", "Crash"})) return "UnexpectedImprovement(Warn)";
    return now;
  }
  if (now == "Timeout") return listed({"Timeout"}) ? "ExpectedFail" : now;
  return now;  // ExpectedFail (an expectation of our own), Flake
}

RunnerFiles readRunnerFiles(const fs::path& baseline, const fs::path& flakes,
                            const fs::path& skips) {
  RunnerFiles f;
  f.baseline_file = baseline;
  f.flakes_file = flakes;
  f.skips_file = skips;
  if (!baseline.empty()) f.baseline = readRunnerBaseline(baseline);
  if (!flakes.empty()) f.flakes = readRunnerPatterns(flakes);
  if (!skips.empty()) f.skips = readRunnerPatterns(skips);
  return f;
}

void applyRunnerFiles(const RunnerFiles& files, Report& report) {
  if (!files.any()) return;
  std::uint64_t unexpected = 0;
  nlohmann::json listed = nlohmann::json::array();
  for (PairResult& r : report.results) {
    const std::string name = testName(r);
    const auto it = files.baseline.expected.find(name);
    std::string status = withBaseline(
        runnerStatus(r), it == files.baseline.expected.end() ? std::string() : it->second);
    if (!runnerSuccess(status) && files.flakes.matches(name)) status = "KnownFlake";
    r.runner_status = status;
    if (!runnerSuccess(status)) {
      ++unexpected;
      if (listed.size() < 50) listed.push_back(fmt::format("{},{}", name, status));
    }
  }
  nlohmann::json j = {{"matches_baseline", unexpected == 0}, {"unexpected", unexpected}};
  if (!listed.empty()) j["unexpected_results"] = listed;
  if (!files.baseline_file.empty()) j["baseline"] = files.baseline_file.string();
  if (!files.flakes_file.empty()) j["flakes"] = files.flakes_file.string();
  if (!files.skips_file.empty()) j["skips"] = files.skips_file.string();
  j["skipped"] = report.skipped.size();
  report.runner = j;
}

std::string resultsCsv(const Report& report) {
  std::string out;
  for (const Row& r : rows(report))
    out += fmt::format("{},{},{}\n", r.name, r.status, static_cast<float>(r.seconds));
  return out;
}

std::string failuresCsv(const Report& report) {
  std::string out;
  for (const Row& r : rows(report))
    if (!runnerSuccess(r.status)) out += fmt::format("{},{}\n", r.name, r.status);
  return out;
}

}  // namespace rc
