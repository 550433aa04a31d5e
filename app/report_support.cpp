// See report_support.h.
#include "app/report_support.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "app/paths.h"
#include "compare/deqp_results.h"
#include "compare/pair_images.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/multisample.h"

namespace rc {

Expectations expectationsFromArgument(const std::string& arg) {
  if (arg == "none") return {};
  const std::filesystem::path file =
      arg.empty() ? defaultExpectationsFile() : std::filesystem::path(arg);
  if (!arg.empty() || std::filesystem::exists(file)) return readExpectations(file);
  return {};
}
namespace fs = std::filesystem;

fs::path readyPicture(const fs::path& frame_dir, const Frame& frame) {
  const auto it = frame.meta.find("color_digest");
  if (it == frame.meta.end() || !it->is_string() || it->get<std::string>() != colorDigest(frame))
    return {};
  fs::path png = frame_dir / "color.png";
  std::error_code ec;
  return fs::is_regular_file(png, ec) ? png : fs::path();
}

namespace {

// The frame.json keys that say which driver stack drew a GL frame (null for the
// reference, which has none of them).
nlohmann::json driverStack(const Frame& frame) {
  if (!frame.meta.contains("stack")) return nullptr;
  nlohmann::json out = nlohmann::json::object();
  for (const char* key :
       {"stack", "gl_renderer", "gl_version", "platform", "driver", "subpixel_bits",
        "gl_subpixel_bits", "subpixel_bits_source", "mesa", "vulkan"}) {
    if (frame.meta.contains(key)) out[key] = frame.meta[key];
  }
  return out;
}

}  // namespace

PairResult compareNamed(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                        const Tolerances& tolerances, ClassMaps* maps) {
  PairResult result = compareFrames(expected, actual, uncertainty, tolerances, maps);
  auto text = [](const Frame& f, const char* key, const char* fallback) {
    return f.meta.contains(key) && f.meta[key].is_string() ? f.meta[key].get<std::string>()
                                                           : std::string(fallback);
  };
  result.expected = text(expected, "backend", "expected");
  result.actual = text(actual, "backend", "actual");
  result.expected_stack = driverStack(expected);
  result.actual_stack = driverStack(actual);
  result.fixture = text(expected, "fixture", "");
  result.fixture_file = text(expected, "fixture_file", "");
  if (expected.meta.contains("tags") && expected.meta["tags"].is_array())
    for (const nlohmann::json& t : expected.meta["tags"])
      if (t.is_string()) result.tags.push_back(t.get<std::string>());
  setHeatScales(result);
  return result;
}

PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const Tolerances& tolerances, ReportFolder& folder,
                       const PairPictures& pictures, bool diff_exr_when_passing, bool flip,
                       ClassMaps&& maps) {
  maps.want_flip = flip;
  PairResult result = compareNamed(expected, actual, uncertainty, tolerances, &maps);
  writePairImages(expected, actual, maps, folder.pairDirectory(result), result, pictures,
                  diff_exr_when_passing || result.status != Status::Pass);
  return result;
}

// ---- ReportFolder ----

const std::vector<std::string>& ReportFolder::ownedNames() {
  static const std::vector<std::string> names = {"frames",      "pairs",       "variants",
                                                 "report.json", "junit.xml",   "report.html",
                                                 "results.csv", "failures.csv"};
  return names;
}

ReportFolder::ReportFolder(fs::path out) : folder_(std::move(out), ownedNames()) {}

void ReportFolder::commit(const Report& report) {
  writeReport(report, staging());
  folder_.commit();
}

PairResult failedRenderResult(std::string fixture, std::string expected, std::string actual,
                              const std::string& message) {
  if (const std::optional<std::string> reason = notSupportedReason(message))
    return notSupportedResult(std::move(fixture), std::move(expected), std::move(actual), *reason);
  return errorResult(std::move(fixture), std::move(expected), std::move(actual), message);
}

bool needsResample(const Frame& ref, const Frame& gl) {
  if (!ref.multisampled() || !gl.multisampled()) return false;
  const std::vector<glm::dvec2> want = samplePositionsFromMeta(gl.meta);
  return !want.empty() && want != samplePositionsFromMeta(ref.meta);
}

void resampleReference(Frame& ref, const Frame& gl, const fs::path& scene_file,
                       ReferenceOptions options) {
  if (!needsResample(ref, gl)) return;
  const std::vector<glm::dvec2> want = samplePositionsFromMeta(gl.meta);
  options.sample_positions = want;
  Frame again = renderReference(loadScene(scene_file), options);
  nlohmann::json meta = ref.meta;
  for (const char* key : {"multisample", "fragments", "triangles_rasterized", "timing_ms"})
    meta[key] = again.meta[key];
  meta["multisample"]["positions_from"] = gl.meta.value("backend", std::string("the driver"));
  again.meta = std::move(meta);
  ref = std::move(again);
}

// ---- Summary ----

namespace {

std::string cellText(const PairResult& r) {
  if (r.status == Status::Error) return "ERROR";
  if (r.status == Status::NotSupported) return "not supported";
  if (r.status == Status::Flake) return "FLAKE";
  std::string status = toString(r.status);
  if (r.status != Status::Pass)
    std::transform(status.begin(), status.end(), status.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (!r.known.empty()) status = "known";  // a failure an expectation covers
  return fmt::format("{:<4} v{} d{:g} s{:.3g}", status, r.visibility.hard, r.depth.max_steps,
                     r.shading.max_abs);
}

}  // namespace

std::string summaryTable(const Report& report, std::size_t max_rows) {
  std::vector<std::string> fixtures;
  std::vector<std::string> backends;
  std::map<std::pair<std::string, std::string>, const PairResult*> cells;
  for (const PairResult& r : report.results) {
    if (std::find(fixtures.begin(), fixtures.end(), r.fixture) == fixtures.end())
      fixtures.push_back(r.fixture);
    if (std::find(backends.begin(), backends.end(), r.actual) == backends.end())
      backends.push_back(r.actual);
    const PairResult*& cell = cells[{r.fixture, r.actual}];
    if (!cell || static_cast<int>(r.status) > static_cast<int>(cell->status)) cell = &r;
  }
  auto allPass = [&](const std::string& f) {
    for (const std::string& b : backends) {
      const auto it = cells.find({f, b});
      if (it != cells.end() && it->second->status != Status::Pass) return false;
    }
    return true;
  };
  std::vector<std::string> rows = fixtures;
  const bool compact = fixtures.size() > max_rows;
  if (compact) std::erase_if(rows, allPass);

  std::size_t first = std::max<std::size_t>(std::string("fixture").size(),
                                            fmt::format("(all {})", fixtures.size()).size());
  for (const std::string& f : rows) first = std::max(first, f.size());
  std::vector<std::size_t> widths;
  for (const std::string& b : backends) {
    std::size_t w = std::max<std::size_t>(b.size(), compact ? 30 : 0);
    for (const std::string& f : rows) {
      const auto it = cells.find({f, b});
      if (it != cells.end()) w = std::max(w, cellText(*it->second).size());
    }
    widths.push_back(w);
  }
  std::string out = fmt::format("{:<{}}", "fixture", first);
  for (std::size_t k = 0; k < backends.size(); ++k)
    out += fmt::format("  {:<{}}", backends[k], widths[k]);
  out += '\n';
  for (const std::string& f : rows) {
    std::string line = fmt::format("{:<{}}", f, first);
    for (std::size_t k = 0; k < backends.size(); ++k) {
      const auto it = cells.find({f, backends[k]});
      line += fmt::format("  {:<{}}", it == cells.end() ? "-" : cellText(*it->second), widths[k]);
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + '\n';
  }
  if (compact) {
    // One more row: every fixture's verdicts per backend.
    std::string line = fmt::format("{:<{}}", fmt::format("(all {})", fixtures.size()), first);
    for (std::size_t k = 0; k < backends.size(); ++k) {
      std::map<Status, int> n;
      for (const std::string& f : fixtures)
        if (const auto it = cells.find({f, backends[k]}); it != cells.end())
          ++n[it->second->status];
      std::string text;
      for (const Status st : {Status::Pass, Status::Warn, Status::Fail, Status::Error,
                              Status::NotSupported, Status::Flake})
        if (n[st] > 0)
          text += fmt::format("{}{} {}", text.empty() ? "" : ", ", n[st], toString(st));
      line += fmt::format("  {:<{}}", text, widths[k]);
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + '\n';
    out += fmt::format("({} fixtures that pass on every backend not listed)\n",
                       fixtures.size() - rows.size());
  }
  out += "v: hard visibility px, d: depth max (steps), s: shading max (8-bit units)\n";
  return out;
}

void printSummary(const Report& report, const fs::path& out_dir, std::ostream& os) {
  for (const PairResult& r : report.results) {
    if (r.status != Status::Pass) os << describe(r) << '\n';
  }
  if (!report.results.empty()) os << '\n' << summaryTable(report) << '\n';
  // What the variant probes found a driver saying about itself that is not so (not a
  // failure: the comparisons used what the driver really does).
  for (const auto& [spec, v] : report.variants.items()) {
    if (!v.is_object() || !v.contains("findings") || !v["findings"].is_array()) continue;
    for (const nlohmann::json& f : v["findings"])
      if (f.is_string()) os << "finding: " << spec << ": " << f.get<std::string>() << '\n';
  }
  const ReportSummary s = report.summary();
  os << fmt::format(
      "{} pairs: {} pass, {} warn, {} fail{}, {} error{}{}\n", s.total(), s.pass, s.warn, s.fail,
      s.known_fail ? fmt::format(" ({} known)", s.known_fail) : std::string(), s.error,
      s.not_supported ? fmt::format(", {} not supported", s.not_supported) : std::string(),
      s.flake ? fmt::format(", {} flake", s.flake) : std::string());
  if (!report.runner.empty()) {
    // deqp-runner's verdict (compare/deqp_results.h): what the exit code follows.
    const std::uint64_t unexpected = report.runner.value("unexpected", std::uint64_t{0});
    os << (unexpected == 0
               ? std::string("deqp-runner: matches baseline")
               : fmt::format("deqp-runner: does not match baseline: {} unexpected", unexpected));
    if (!report.skipped.empty()) os << fmt::format(" ({} skipped)", report.skipped.size());
    os << '\n';
    for (const PairResult& r : report.results)
      if (!r.runner_status.empty() && !runnerSuccess(r.runner_status))
        os << "  " << testName(r) << ',' << r.runner_status << '\n';
  }
  os << "report: " << (fs::absolute(out_dir) / "report.html").lexically_normal().string() << '\n';
  const int code = exitCodeFor(report);
  os << (code == kExitBackend    ? "ERROR"
         : code == kExitFail     ? "FAILURE"
         : s.fail > s.known_fail ? "PASS (as the baseline expects)"
         : s.fail || s.warn      ? "WARNING"
         : s.flake               ? "PASS (with flakes)"
                                 : "PASS")
     << '\n';
}

}  // namespace rc
