// The tables of report.html above the pairs: verdict counts per backend, the fixture x
// backend matrix and the legal variants each GL backend follows.
#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "compare/html_internal.h"

namespace rc::detail {
namespace {

// The matrix lists every fixture up to this many, else only those that did not pass.
constexpr std::size_t kMatrixRows = 40;

}  // namespace

Columns columnsOf(const Report& report) {
  Columns c;
  for (const PairResult& r : report.results)
    c.one_expected = c.one_expected && r.expected == report.results.front().expected;
  for (const PairResult& r : report.results) {
    const std::string name = c.one_expected ? r.actual : r.actual + " vs " + r.expected;
    auto it = std::find(c.names.begin(), c.names.end(), name);
    if (it == c.names.end()) it = c.names.insert(c.names.end(), name);
    c.of.push_back(static_cast<std::size_t>(it - c.names.begin()));
  }
  return c;
}

std::string matrix(const Report& report, const Columns& columns) {
  std::vector<std::string> fixtures;
  std::map<std::string, bool> all_pass;
  std::map<std::pair<std::string, std::size_t>, std::pair<Status, std::size_t>> cells;
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    if (!all_pass.count(r.fixture)) fixtures.push_back(r.fixture);
    all_pass[r.fixture] =
        all_pass.emplace(r.fixture, true).first->second && r.status == Status::Pass;
    auto key = std::make_pair(r.fixture, columns.of[k]);
    auto it = cells.find(key);
    if (it == cells.end() || static_cast<int>(r.status) > static_cast<int>(it->second.first))
      cells[key] = {r.status, k};
  }
  // A run renders at least two backends (the compared one and --against), so it always
  // gets the matrix; a single `compare` does not.
  if (columns.names.empty() || (columns.names.size() < 2 && report.command != "run")) return "";
  // Many fixtures: only those with a pair that did not pass, the worst first, at most
  // kMatrixRows of them (the pairs table lists them all).
  std::vector<std::string> rows = fixtures;
  std::size_t not_passing = fixtures.size();
  if (fixtures.size() > kMatrixRows) {
    std::erase_if(rows, [&](const std::string& f) { return all_pass[f]; });
    not_passing = rows.size();
    std::map<std::string, int> worst;
    for (const auto& [key, cell] : cells)
      worst[key.first] = std::max(worst[key.first], static_cast<int>(cell.first));
    std::stable_sort(rows.begin(), rows.end(), [&](const std::string& a, const std::string& b) {
      return worst[a] > worst[b];
    });
    if (rows.size() > kMatrixRows) rows.resize(kMatrixRows);
  }
  std::string out = "<h2>Fixture &times; backend</h2>";
  if (columns.one_expected)
    out += fmt::format("<div class=\"meta\">every backend compared against {}</div>",
                       esc(report.results.front().expected));
  if (rows.size() < fixtures.size())
    out += fmt::format(
        "<div class=\"meta\">{} of the {} fixtures with a pair that did not pass, the worst "
        "first ({} fixtures pass on every backend; the pairs table below lists every pair)</div>",
        rows.size(), not_passing, fixtures.size() - not_passing);
  out += "<table id=\"matrix\"><tr><th>fixture</th>";
  for (const std::string& b : columns.names) out += fmt::format("<th>{}</th>", esc(b));
  out += "</tr>";
  for (const std::string& f : rows) {
    out += fmt::format("<tr><td>{}</td>", esc(f));
    for (std::size_t b = 0; b < columns.names.size(); ++b) {
      const auto it = cells.find({f, b});
      if (it == cells.end()) {
        out += "<td class=\"cellstatus\">&mdash;</td>";
        continue;
      }
      out += fmt::format("<td class=\"cellstatus\"><a href=\"#pair-{}\">{}</a></td>",
                         it->second.second, badge(it->second.first));
    }
    out += "</tr>";
  }
  return out + "</table>";
}

// Verdict counts per backend column.
std::string backendCounts(const Report& report, const Columns& columns) {
  if (columns.names.size() < 2 && report.results.size() < 2) return "";
  // One count per Status (kStatusCount): a not_supported row (MSAA) indexed past a table
  // of four overflowed it (heap-buffer-overflow found by the asan-ubsan build).
  std::vector<std::array<std::uint64_t, kStatusCount>> n(columns.names.size(),
                                                         std::array<std::uint64_t, kStatusCount>{});
  for (std::size_t k = 0; k < report.results.size(); ++k)
    ++n[columns.of[k]][static_cast<std::size_t>(report.results[k].status)];
  std::string out =
      "<h2>Backends</h2><table id=\"backends\"><tr><th>backend</th><th>pass</th><th>warn</th>"
      "<th>fail</th><th>error</th><th>not supported</th><th>flake</th></tr>";
  for (std::size_t b = 0; b < columns.names.size(); ++b)
    out += fmt::format(
        "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>"
        "<td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
        esc(columns.names[b]), n[b][0], n[b][1], n[b][2], n[b][3], n[b][4], n[b][5]);
  return out + "</table>";
}

// The legal variants each GL backend follows (report.variants, see docs/debugging.md).
std::string variantsTable(const Report& report) {
  if (!report.variants.is_object() || report.variants.empty()) return "";
  auto text = [](const nlohmann::json& v, const char* key) -> std::string {
    if (!v.contains(key)) return "";
    const nlohmann::json& x = v[key];
    if (x.is_object() && x.contains("summary") && x["summary"].is_string())
      return x["summary"].get<std::string>();
    return x.is_string() ? x.get<std::string>() : x.dump();
  };
  // A legal variant is not a failure: the marks say "same as the reference" or not.
  auto mark = [](const nlohmann::json& v, const char* key, const char* flag, const char* yes,
                 const char* no) {
    const bool ok = v.contains(key) && v[key].is_object() && v[key].value(flag, false);
    return fmt::format("<span class=\"badge {}\">{}</span>", ok ? "pass" : "warn", ok ? yes : no);
  };
  std::string out =
      "<h2>Backend variants</h2><table id=\"variants\"><tr><th>backend</th><th>renderer</th>"
      "<th>GL_SUBPIXEL_BITS</th><th>snap band bits</th><th>subpixel precision</th>"
      "<th>tie-break</th><th>depth rounding</th><th>lines and points</th><th>findings</th></tr>";
  for (const auto& [spec, v] : report.variants.items()) {
    out += fmt::format("<tr><td>{}</td>", esc(spec));
    if (v.contains("error")) {
      out += fmt::format("<td colspan=\"7\">{} {}</td></tr>", badge(Status::Error),
                         esc(text(v, "error")));
      continue;
    }
    const std::string band = text(v, "band_subpixel_bits");
    out +=
        fmt::format("<td title=\"{}\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>",
                    esc(text(v, "stack")), esc(text(v, "renderer")), esc(text(v, "subpixel_bits")),
                    esc(band.empty() ? text(v, "subpixel_bits") : band));
    out += fmt::format("<td>{} {}</td>",
                       mark(v, "subpixel", "confirmed", "confirmed", "not confirmed"),
                       esc(text(v, "subpixel")));
    out += fmt::format("<td>{} {}</td>",
                       mark(v, "tie_break", "matches_reference", "as ref", "differs"),
                       esc(text(v, "tie_break")));
    out += fmt::format("<td>{} {}</td>",
                       mark(v, "depth_rounding", "matches_reference", "as ref", "differs"),
                       esc(text(v, "depth_rounding")));
    out +=
        fmt::format("<td>{} {}</td>",
                    v.contains("lines") ? mark(v, "lines", "matches_reference", "as ref", "differs")
                                        : std::string(),
                    esc(text(v, "lines")));
    std::string findings;
    if (v.contains("findings") && v["findings"].is_array()) {
      for (const nlohmann::json& f : v["findings"])
        if (f.is_string()) findings += (findings.empty() ? "" : "<br>") + esc(f.get<std::string>());
    }
    out += fmt::format("<td>{}</td></tr>", findings);
  }
  return out + "</table>";
}

}  // namespace rc::detail
