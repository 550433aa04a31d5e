// report.html: one self-contained page (inline CSS and JS, no network; images are the
// relative files beside it), built to stay usable at tens of thousands of pairs: the
// summary, per-backend counts, a fixture x backend matrix (only fixtures with a
// non-passing pair when there are many), then the pairs table with failures first, grouped
// by signature (what failed, how), passing pairs one group with a count per backend,
// filters by text, status, backend, class and tag; per pair the images side by side with
// legends and the numbers, images loaded only when the pair is opened. The page carries
// the pairs as data and its script builds rows and sections from them: every one at once
// for small reports, a group's rows when it is opened and a pair's section when that is
// opened for large ones (docs/reports.md, docs/scaling.md).
#include <algorithm>
#include <cctype>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "compare/html_internal.h"
#include "compare/report.h"
#include "compare/report_text.h"

namespace rc {
namespace fs = std::filesystem;

std::string htmlEscape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

namespace {

// Reports up to this many pairs carry every pair's row and section in the page; larger
// ones carry the passing rows and all sections as data (built when opened), so that the
// page stays quick to open (docs/performance.md: 10,000 pairs).
constexpr std::size_t kStaticPairs = 200;

// What a non-passing pair's failure looks like, for grouping alike failures: the classes
// at the pair's status (visibility with its largest kind of hard mismatch), or for an
// error row its message with the fixture name and every number taken out.
std::string signature(const PairResult& r) {
  if (r.status == Status::Error || r.status == Status::NotSupported) {
    std::string m = r.error;
    for (std::size_t at = 0;
         !r.fixture.empty() && (at = m.find(r.fixture, at)) != std::string::npos;)
      m.replace(at, r.fixture.size(), "<fixture>");
    std::string out;
    for (std::size_t i = 0; i < m.size(); ++i) {
      if (std::isdigit(static_cast<unsigned char>(m[i]))) {
        out += 'N';
        while (i + 1 < m.size() &&
               (std::isdigit(static_cast<unsigned char>(m[i + 1])) || m[i + 1] == '.'))
          ++i;
      } else {
        out += m[i];
      }
    }
    if (out.size() > 120) out = out.substr(0, 117) + "...";
    return out;
  }
  std::vector<std::string> parts;
  if (r.visibility.status == r.status) {
    const VisibilityStats& v = r.visibility;
    const char* kind = v.missing_hard >= v.extra_hard && v.missing_hard >= v.wrong_primitive_hard
                           ? "missing"
                           : (v.extra_hard >= v.wrong_primitive_hard ? "extra" : "wrong_primitive");
    parts.push_back(fmt::format("visibility ({})", v.hard > 0 ? kind : "ambiguous"));
  }
  if (r.depth.status == r.status) parts.emplace_back("depth");
  if (r.shading.status == r.status) parts.emplace_back("shading");
  return fmt::format("{}", fmt::join(parts, " + "));
}

}  // namespace

std::string reportHtml(const Report& report, const fs::path& report_dir) {
  using detail::badge;
  using detail::esc;
  using detail::jnum;
  const ReportSummary sum = report.summary();
  const bool big = report.results.size() > kStaticPairs;
  const detail::Columns columns = detail::columnsOf(report);

  // Groups: one per (status, signature); the worst status first, then the largest.
  struct Group {
    Status status;
    std::string signature;
    std::vector<std::size_t> pairs;
  };
  std::vector<Group> groups;
  std::map<std::pair<int, std::string>, std::size_t> group_of_key;
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    const auto key = std::make_pair(static_cast<int>(r.status), signature(r));
    auto it = group_of_key.find(key);
    if (it == group_of_key.end()) {
      it = group_of_key.emplace(key, groups.size()).first;
      groups.push_back({r.status, key.second, {}});
    }
    groups[it->second].pairs.push_back(k);
  }
  std::stable_sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) {
    if (a.status != b.status) return static_cast<int>(a.status) > static_cast<int>(b.status);
    if (a.pairs.size() != b.pairs.size()) return a.pairs.size() > b.pairs.size();
    return a.signature < b.signature;
  });
  std::vector<std::size_t> group_of(report.results.size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (std::size_t k : groups[g].pairs) group_of[k] = g;
  std::vector<std::string> tags;
  for (const PairResult& r : report.results)
    for (const std::string& t : r.tags)
      if (std::find(tags.begin(), tags.end(), t) == tags.end()) tags.push_back(t);
  std::sort(tags.begin(), tags.end());

  std::string out = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">";
  out += fmt::format("<title>{} report</title><style>{}{}</style></head><body>",
                     esc(report.tool_name), detail::kStyle, detail::legendStyle());
  out += fmt::format("<h1>{} report</h1><div class=\"meta\">{} {}{}</div>", esc(report.tool_name),
                     esc(report.tool_name), esc(report.tool_version),
                     report.command.empty() ? "" : " &middot; " + esc(report.command));
  out += fmt::format(
      "<div class=\"summary\" id=\"summary\"><div>pairs<b>{}</b></div><div>pass<b>{}</b></div>"
      "<div>warn<b>{}</b></div><div>fail<b>{}</b></div><div>error<b>{}</b></div>"
      "<div>not supported<b>{}</b></div><div>exit code<b>{}</b></div></div>",
      sum.total(), sum.pass, sum.warn, sum.fail, sum.error, sum.not_supported, exitCodeFor(report));
  out += detail::backendCounts(report, columns);
  // Large reports: the groups of failures come before the (shortened) matrix.
  if (!big) out += detail::matrix(report, columns) + detail::variantsTable(report);

  out +=
      "<h2>Pairs</h2><div class=\"controls\"><input id=\"filter\" type=\"search\" "
      "placeholder=\"filter: fixture, backend, status...\"><select id=\"status-filter\">"
      "<option value=\"\">all statuses</option><option value=\"not-pass\">not pass</option>"
      "<option value=\"pass\">pass</option><option value=\"warn\">warn</option>"
      "<option value=\"fail\">fail</option><option value=\"error\">error</option>"
      "<option value=\"not_supported\">not supported</option></select>"
      "<select id=\"backend-filter\"><option value=\"\">all backends</option>";
  for (std::size_t b = 0; b < columns.names.size(); ++b)
    out += fmt::format("<option value=\"{}\">{}</option>", b, esc(columns.names[b]));
  out +=
      "</select><select id=\"class-filter\"><option value=\"\">any class</option>"
      "<option value=\"visibility\">visibility not pass</option><option value=\"depth\">depth "
      "not pass</option><option value=\"shading\">shading not pass</option></select>"
      "<select id=\"tag-filter\"><option value=\"\">all tags</option>";
  for (std::size_t t = 0; t < tags.size(); ++t)
    out += fmt::format("<option value=\"{}\">{}</option>", t, esc(tags[t]));
  out += "</select><span id=\"shown\"></span></div>";
  out += "<table id=\"results\"><thead><tr>";
  const std::pair<const char*, bool> heads[] = {
      {"fixture", false},    {"expected", false},    {"actual", false},   {"status", true},
      {"hard px", true},     {"ambiguous px", true}, {"missing", true},   {"extra", true},
      {"wrong prim.", true}, {"depth max", true},    {"depth p99", true}, {"depth over", true},
      {"shading max", true}, {"shading mean", true}, {"PSNR dB", true},   {"shading over", true}};
  for (const auto& [name, numeric] : heads)
    out += fmt::format("<th data-type=\"{}\">{}</th>", numeric ? "num" : "text", name);
  out += "</tr></thead>";
  // Group heads only: the script builds the rows (all of them at once for small reports).
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const Group& group = groups[g];
    std::map<std::size_t, std::size_t> per_column;
    for (std::size_t k : group.pairs) ++per_column[columns.of[k]];
    std::string by;
    for (const auto& [b, n] : per_column)
      by += fmt::format("{}{} {}", by.empty() ? "" : ", ", columns.names[b], n);
    out += fmt::format(
        "<tbody data-group=\"{}\" data-lazy=\"1\"{}><tr class=\"group-head\"><th colspan=\"16\">"
        "<span class=\"fold\"></span>{} <span class=\"sig\">{}</span> &mdash; <span "
        "class=\"count\">{}</span> pairs <span class=\"by\">({})</span></th></tr></tbody>",
        g, big ? " class=\"collapsed\"" : "", badge(group.status),
        esc(group.status == Status::Pass ? std::string("every class passes") : group.signature),
        group.pairs.size(), esc(by));
  }
  out += "</table>";
  if (!big) out += "<h2>Details</h2><div id=\"details\"></div>";
  if (big) out += detail::matrix(report, columns) + detail::variantsTable(report);

  // Every pair as data: the rows, the filters, and what each section shows.
  nlohmann::json pairs = nlohmann::json::array();
  nlohmann::json sections = nlohmann::json::array();
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    nlohmann::json classes = nlohmann::json::array();
    if (r.status != Status::Error && r.status != Status::NotSupported) {
      if (r.visibility.status != Status::Pass) classes.push_back("visibility");
      if (r.depth.status != Status::Pass) classes.push_back("depth");
      if (r.shading.status != Status::Pass) classes.push_back("shading");
    }
    nlohmann::json tag_ids = nlohmann::json::array();
    for (const std::string& t : r.tags)
      tag_ids.push_back(std::find(tags.begin(), tags.end(), t) - tags.begin());
    nlohmann::json numbers;
    if (r.status != Status::Error && r.status != Status::NotSupported)
      numbers = {r.visibility.hard,        r.visibility.ambiguous,       r.visibility.missing,
                 r.visibility.extra,       r.visibility.wrong_primitive, jnum(r.depth.max_steps),
                 jnum(r.depth.p99_steps),  r.depth.over_tolerance,       jnum(r.shading.max_abs),
                 jnum(r.shading.mean_abs), jnum(r.shading.psnr_db),      r.shading.over_tolerance};
    pairs.push_back({r.fixture, r.expected, r.actual, toString(r.status), columns.of[k], classes,
                     tag_ids, group_of[k], numbers});
    sections.push_back(detail::sectionData(r, report_dir, !big || r.status != Status::Pass));
  }
  const nlohmann::json data = {{"big", big}, {"pairs", pairs}, {"details", sections}};
  // Inside <script>, "</script>" or "<!--" in a name would end or confuse the element:
  // JSON may spell every '<' as \u003c (it can only occur inside strings).
  const std::string text = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string safe;
  safe.reserve(text.size() + text.size() / 64);
  for (const char ch : text) {
    if (ch == '<')
      safe += "\\u003c";
    else
      safe += ch;
  }
  out += fmt::format("<script type=\"application/json\" id=\"report-data\">{}</script>", safe);
  out += fmt::format("<script>{}</script></body></html>\n", detail::kScript);
  return out;
}

}  // namespace rc
