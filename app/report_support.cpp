// See report_support.h.
#include "app/report_support.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "compare/pair_images.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"

namespace rc {
namespace fs = std::filesystem;

ToleranceOverrides fixtureTolerance(const Frame& expected, const Frame& actual) {
  for (const Frame* f : {&expected, &actual}) {
    const auto it = f->meta.find("tolerance");
    if (it == f->meta.end()) continue;
    const std::string backend = f->meta.contains("backend") && f->meta["backend"].is_string()
                                    ? f->meta["backend"].get<std::string>()
                                    : std::string(f == &expected ? "expected" : "actual");
    return toleranceFromJson(*it, fmt::format("frame.json of {}", backend));
  }
  // Frames written before frame.json recorded the block: read the fixture itself.
  if (expected.meta.contains("fixture_file") && expected.meta["fixture_file"].is_string()) {
    const fs::path fixture = expected.meta["fixture_file"].get<std::string>();
    if (fs::exists(fixture)) return loadScene(fixture).tolerance;
  }
  return {};
}

Tolerances pairTolerances(const Frame& expected, const Frame& actual,
                          const ToleranceOverrides& fixture, const CommandLineTolerances& cli) {
  Tolerances tol = tolerancesForFrames(expected, actual);
  applyOverrides(tol, fixture);
  applyOverrides(tol, cli);
  return tol;
}

fs::path readyPicture(const fs::path& frame_dir, const Frame& frame) {
  const auto it = frame.meta.find("color_digest");
  if (it == frame.meta.end() || !it->is_string() || it->get<std::string>() != colorDigest(frame))
    return {};
  fs::path png = frame_dir / "color.png";
  std::error_code ec;
  return fs::is_regular_file(png, ec) ? png : fs::path();
}

PairResult compareNamed(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                        const Tolerances& tolerances, ClassMaps* maps) {
  PairResult result = compareFrames(expected, actual, uncertainty, tolerances, maps);
  auto text = [](const Frame& f, const char* key, const char* fallback) {
    return f.meta.contains(key) && f.meta[key].is_string() ? f.meta[key].get<std::string>()
                                                           : std::string(fallback);
  };
  result.expected = text(expected, "backend", "expected");
  result.actual = text(actual, "backend", "actual");
  result.fixture = text(expected, "fixture", "");
  result.fixture_file = text(expected, "fixture_file", "");
  if (expected.meta.contains("tags") && expected.meta["tags"].is_array())
    for (const nlohmann::json& t : expected.meta["tags"])
      if (t.is_string()) result.tags.push_back(t.get<std::string>());
  setHeatScales(result);
  return result;
}

PairResult comparePair(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                       const Tolerances& tolerances, const fs::path& out_dir,
                       const PairPictures& pictures, bool diff_exr_when_passing) {
  ClassMaps maps;
  PairResult result = compareNamed(expected, actual, uncertainty, tolerances, &maps);
  writePairImages(expected, actual, maps, pairDirectory(out_dir, result), result, pictures,
                  diff_exr_when_passing || result.status != Status::Pass);
  return result;
}

// ---- ReportFolder ----

namespace {

constexpr const char* kOwnedEntries[] = {"frames", "pairs", "report.json", "junit.xml",
                                         "report.html"};

// Removes the image files an earlier report.json names (relative paths inside `out`
// only) and the folders they leave empty.
void removeReportedFiles(const fs::path& out) {
  std::ifstream in(out / "report.json");
  if (!in) return;
  const nlohmann::json old = nlohmann::json::parse(in, nullptr, false);
  if (old.is_discarded() || !old.contains("results") || !old["results"].is_array()) return;
  std::error_code ec;
  for (const nlohmann::json& row : old["results"]) {
    if (!row.is_object() || !row.contains("images") || !row["images"].is_object()) continue;
    for (const auto& [kind, value] : row["images"].items()) {
      if (!value.is_string()) continue;
      const fs::path rel = fs::path(value.get<std::string>()).lexically_normal();
      if (rel.empty() || rel.is_absolute() || *rel.begin() == "..") continue;
      fs::path file = out / rel;
      fs::remove(file, ec);
      for (fs::path dir = file.parent_path();
           dir != out && dir.string().size() > out.string().size(); dir = dir.parent_path()) {
        if (!fs::is_empty(dir, ec) || ec) break;
        fs::remove(dir, ec);
      }
    }
  }
}

}  // namespace

ReportFolder::ReportFolder(fs::path out) : out_(std::move(out)) {
  std::error_code ec;
  if (out_.empty()) throw InputError("--out: needs a folder");
  if (fs::exists(out_, ec) && !fs::is_directory(out_, ec))
    throw InputError(fmt::format("{}: --out names a file; it must be a folder", out_.string()));
  if (!fs::exists(out_, ec)) {
    fs::create_directories(out_, ec);
    if (ec)
      throw InputError(
          fmt::format("{}: cannot create the report folder: {}", out_.string(), ec.message()));
    created_out_ = true;
  }
  staging_ = out_ / fmt::format(".rastercheck-staging-{}", ::getpid());
  fs::remove_all(staging_, ec);
  fs::create_directory(staging_, ec);
  if (ec) {
    if (created_out_) fs::remove(out_, ec);
    throw InputError(
        fmt::format("{}: cannot write into the report folder: {}", out_.string(), ec.message()));
  }
}

ReportFolder::~ReportFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (created_out_) fs::remove(out_, ec);  // only when still empty
}

void ReportFolder::commit(const Report& report) {
  writeReport(report, staging_);
  std::error_code ec;
  removeReportedFiles(out_);
  for (const char* name : kOwnedEntries) fs::remove_all(out_ / name, ec);
  for (const char* name : kOwnedEntries) {
    if (!fs::exists(staging_ / name, ec)) continue;
    fs::rename(staging_ / name, out_ / name, ec);
    if (ec)
      throw InputError(
          fmt::format("{}: cannot move into place: {}", (out_ / name).string(), ec.message()));
  }
  fs::remove_all(staging_, ec);
  committed_ = true;
}

// ---- Summary ----

namespace {

std::string cellText(const PairResult& r) {
  if (r.status == Status::Error) return "ERROR";
  std::string status = toString(r.status);
  if (r.status != Status::Pass)
    std::transform(status.begin(), status.end(), status.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
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
      for (const Status st : {Status::Pass, Status::Warn, Status::Fail, Status::Error})
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
  const ReportSummary s = report.summary();
  os << fmt::format("{} pairs: {} pass, {} warn, {} fail, {} error\n", s.total(), s.pass, s.warn,
                    s.fail, s.error);
  os << "report: " << (fs::absolute(out_dir) / "report.html").lexically_normal().string() << '\n';
  os << (s.error ? "ERROR" : s.fail ? "FAILURE" : s.warn ? "WARNING" : "PASS") << '\n';
}

}  // namespace rc
