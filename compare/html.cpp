// report.html: one self-contained page (inline CSS and JS, no network; images are the
// relative files beside it). Summary first, then a fixture x backend matrix when there are
// several backends, a sortable and filterable table of every pair, and per pair the
// images side by side with legends and the numbers.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "compare/pair_images.h"
#include "compare/report.h"
#include "compare/report_text.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

std::string esc(std::string_view s) {
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

// Percent-encodes a relative path for src/href, keeping '/'.
std::string urlPath(const std::string& path) {
  std::string out;
  for (char ch : path) {
    const auto u = static_cast<unsigned char>(ch);
    const bool keep =
        std::isalnum(u) || ch == '/' || ch == '.' || ch == '_' || ch == '-' || ch == '~';
    out += keep ? std::string(1, ch) : fmt::format("%{:02X}", u);
  }
  return out;
}

std::string relativeUrl(const fs::path& file, const fs::path& base) {
  std::error_code ec;
  fs::path rel = fs::proximate(file, base.empty() ? fs::path(".") : base, ec);
  if (ec) rel = file;
  return urlPath(rel.generic_string());
}

std::string number(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.4g}", v);
}

std::string hex(const Rgb8& c) { return fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]); }

std::string badge(Status s) {
  return fmt::format("<span class=\"badge {0}\">{0}</span>", toString(s));
}

// One table cell with a sort key: numbers sort numerically, text alphabetically.
std::string cell(const std::string& text, const std::string& key, bool numeric) {
  return fmt::format("<td data-v=\"{}\"{}>{}</td>", esc(key), numeric ? " class=\"n\"" : "", text);
}
std::string numCell(double v) {
  return cell(esc(number(v)), std::isfinite(v) ? fmt::format("{}", v) : "1e308", true);
}
std::string countCell(std::uint64_t v) {
  return cell(fmt::format("{}", v), fmt::format("{}", v), true);
}
std::string emptyCell() { return cell("&mdash;", "-1", true); }

constexpr const char* kStyle = R"CSS(
body{font:14px/1.4 system-ui,sans-serif;margin:0 24px 48px;color:#222;background:#fafafa}
h1{font-size:22px;margin:18px 0 4px}h2{font-size:18px;margin:28px 0 8px}
h3{font-size:15px;margin:0 0 6px}
.meta{color:#666;font-size:12px}
.summary{display:flex;gap:12px;margin:12px 0}
.summary div{padding:8px 14px;border-radius:6px;background:#fff;border:1px solid #ddd;min-width:70px}
.summary b{display:block;font-size:20px}
.badge{display:inline-block;padding:0 6px;border-radius:4px;font-size:12px;font-weight:600;
  text-transform:uppercase;color:#fff}
.pass{background:#2e7d32}.warn{background:#e6a100}.fail{background:#c62828}.error{background:#6a1b9a}.not_supported{background:#607d8b}
table{border-collapse:collapse;background:#fff}
th,td{border:1px solid #ddd;padding:3px 7px;text-align:left;white-space:nowrap}
td.n{text-align:right;font-variant-numeric:tabular-nums}
#results th{cursor:pointer;user-select:none;background:#f0f0f0;position:sticky;top:0}
#results th.asc::after{content:" \25B2"}#results th.desc::after{content:" \25BC"}
.controls{margin:8px 0;display:flex;gap:8px;align-items:center}
.controls input{width:320px;padding:4px}
.pair{background:#fff;border:1px solid #ddd;border-radius:6px;padding:8px 12px;margin:10px 0}
.pair summary{cursor:pointer}.pair summary h3{display:inline}
.pair .describe{font-family:ui-monospace,monospace;font-size:12px;white-space:pre-wrap;color:#444}
.images{display:flex;flex-wrap:wrap;gap:10px;margin:8px 0}
figure{margin:0}figcaption{font-size:12px;color:#555;max-width:242px}
figure img{display:block;width:240px;height:auto;image-rendering:pixelated;
  border:1px solid #ccc;background:#eee}
img.broken{outline:3px solid #c62828}
.legend{display:flex;flex-wrap:wrap;gap:2px 10px;font-size:11px;max-width:242px;margin-top:3px}
.sw{display:inline-block;width:11px;height:11px;border:1px solid #888;vertical-align:middle;
  margin-right:3px}
.ramp{height:10px;width:240px;border:1px solid #888}
.ramp-labels{display:flex;justify-content:space-between;width:242px;font-size:11px}
.numbers{display:flex;flex-wrap:wrap;gap:12px}
.numbers table td:first-child{color:#555}
#matrix td a{color:inherit;text-decoration:none}
#matrix td.cellstatus{text-align:center}
#variants td{white-space:normal;max-width:420px;vertical-align:top}
.hidden{display:none}
)CSS";

constexpr const char* kScript = R"JS(
(function () {
  var table = document.getElementById('results');
  var body = table ? table.tBodies[0] : null;
  var filter = document.getElementById('filter');
  var statusFilter = document.getElementById('status-filter');
  var shown = document.getElementById('shown');
  function apply() {
    var text = filter.value.toLowerCase();
    var st = statusFilter.value;
    var visible = 0;
    var rows = body ? body.rows : [];
    for (var i = 0; i < rows.length; i++) {
      var row = rows[i];
      var s = row.getAttribute('data-status');
      var ok = (!text || row.getAttribute('data-text').indexOf(text) >= 0) &&
               (!st || s === st || (st === 'not-pass' && s !== 'pass'));
      row.classList.toggle('hidden', !ok);
      var pair = document.getElementById(row.getAttribute('data-pair'));
      if (pair) pair.classList.toggle('hidden', !ok);
      if (ok) visible++;
    }
    shown.textContent = visible + ' of ' + rows.length + ' pairs shown';
  }
  function sortBy(th) {
    var index = Array.prototype.indexOf.call(th.parentNode.children, th);
    var numeric = th.getAttribute('data-type') === 'num';
    var asc = !th.classList.contains('asc');
    var heads = th.parentNode.children;
    for (var k = 0; k < heads.length; k++) heads[k].classList.remove('asc', 'desc');
    th.classList.add(asc ? 'asc' : 'desc');
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = a.cells[index].getAttribute('data-v'), y = b.cells[index].getAttribute('data-v');
      var c = numeric ? parseFloat(x) - parseFloat(y) : x.localeCompare(y);
      return asc ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  if (table) {
    var ths = table.tHead.rows[0].cells;
    for (var i = 0; i < ths.length; i++)
      ths[i].addEventListener('click', function (e) { sortBy(e.currentTarget); });
  }
  // Links to a folded pair unfold it.
  function openTarget() {
    var el = location.hash ? document.getElementById(location.hash.slice(1)) : null;
    if (el && el.tagName === 'DETAILS') el.open = true;
  }
  window.addEventListener('hashchange', openTarget);
  openTarget();
  filter.addEventListener('input', apply);
  statusFilter.addEventListener('change', apply);
  apply();
  // Marks for people (broken images get a red outline) and for automated checks.
  function imagesDone() {
    var ok = 0, bad = 0;
    for (var i = 0; i < document.images.length; i++) {
      var img = document.images[i];
      if (img.complete && img.naturalWidth > 0) ok++;
      else { bad++; img.classList.add('broken'); }
    }
    document.body.setAttribute('data-images-ok', ok);
    document.body.setAttribute('data-images-failed', bad);
    document.body.setAttribute('data-ready', '1');
  }
  document.body.setAttribute('data-rows-rendered', body ? body.rows.length : 0);
  document.body.setAttribute('data-pairs-rendered', document.querySelectorAll('details.pair').length);
  if (document.readyState === 'complete') imagesDone();
  else window.addEventListener('load', imagesDone);
})();
)JS";

std::string visibilityLegend(const PairResult& r) {
  const VisibilityStats& v = r.visibility;
  struct Entry {
    PixelClass cls;
    std::uint64_t count;
  };
  const std::uint64_t missing_amb = v.missing - v.missing_hard;
  const std::uint64_t extra_amb = v.extra - v.extra_hard;
  const std::uint64_t wrong_amb = v.wrong_primitive - v.wrong_primitive_hard;
  const Entry entries[] = {{PixelClass::Match, 0},
                           {PixelClass::MissingHard, v.missing_hard},
                           {PixelClass::MissingAmbiguous, missing_amb},
                           {PixelClass::ExtraHard, v.extra_hard},
                           {PixelClass::ExtraAmbiguous, extra_amb},
                           {PixelClass::WrongHard, v.wrong_primitive_hard},
                           {PixelClass::WrongAmbiguous, wrong_amb},
                           {PixelClass::Background, 0}};
  std::string out = "<div class=\"legend\">";
  for (const Entry& e : entries) {
    const bool counted = e.cls != PixelClass::Match && e.cls != PixelClass::Background;
    out += fmt::format("<span><i class=\"sw\" style=\"background:{}\"></i>{}{}</span>",
                       hex(classColor(e.cls)), esc(toString(e.cls)),
                       counted ? fmt::format(" {}", e.count) : std::string());
  }
  return out + "</div>";
}

std::string heatLegend(double scale, const char* unit, const std::string& gradient) {
  return fmt::format(
      "<div class=\"ramp\" style=\"background:linear-gradient(to right,{})\"></div>"
      "<div class=\"ramp-labels\"><span>0</span><span>log scale</span><span>{} {}</span></div>"
      "<div class=\"legend\"><span><i class=\"sw\" style=\"background:{}\"></i>not compared</span>"
      "<span><i class=\"sw\" style=\"background:{}\"></i>NaN/Inf</span></div>",
      gradient, esc(number(scale)), unit, hex(kNotComparedColor), hex(kNonFiniteColor));
}

std::string figure(const PairResult& r, const char* kind, const char* caption,
                   const fs::path& report_dir, const std::string& legend) {
  const auto it = r.images.find(kind);
  if (it == r.images.end()) return "";
  const std::string url = relativeUrl(it->second, report_dir);
  return fmt::format(
      "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\" width=\"{2}\" height=\"{3}\"></a>"
      "<figcaption>{1}</figcaption>{4}</figure>",
      url, esc(caption), 240, r.width > 0 ? 240 * r.height / r.width : 240, legend);
}

std::string rowsTable(const char* title, Status status,
                      const std::vector<std::pair<std::string, std::string>>& rows) {
  std::string out =
      fmt::format("<table><tr><th colspan=\"2\">{} {}</th></tr>", title, badge(status));
  for (const auto& [k, v] : rows)
    out += fmt::format("<tr><td>{}</td><td class=\"n\">{}</td></tr>", esc(k), esc(v));
  return out + "</table>";
}

std::string at(const PixelRef& p, int height) { return where(p, height); }

std::string pairSection(const PairResult& r, std::size_t k, const fs::path& report_dir,
                        const std::string& gradient) {
  // Passing pairs start folded so that a large run shows what needs attention.
  std::string out = fmt::format(
      "<details class=\"pair\" id=\"pair-{}\" data-status=\"{}\"{}><summary><h3>{} &mdash; {} "
      "vs {} {}</h3></summary>",
      k, toString(r.status), r.status == Status::Pass ? "" : " open", esc(r.fixture),
      esc(r.expected), esc(r.actual), badge(r.status));
  out += fmt::format("<div class=\"describe\">{}</div>", esc(describe(r)));
  if (r.status == Status::Error || r.status == Status::NotSupported) return out + "</details>";

  out += "<div class=\"images\">";
  out += figure(r, "expected", ("expected: " + r.expected).c_str(), report_dir, "");
  out += figure(r, "actual", ("actual: " + r.actual).c_str(), report_dir, "");
  out += figure(r, "visibility", "visibility classes", report_dir, visibilityLegend(r));
  out += figure(r, "depth_heat", "depth |dZ| (steps)", report_dir,
                heatLegend(r.depth_heat_scale, "steps", gradient));
  out += figure(r, "shading_heat", "shading max |dC| (8-bit units)", report_dir,
                heatLegend(r.shading_heat_scale, "units", gradient));
  out += "</div>";
  if (const auto it = r.images.find("diff_exr"); it != r.images.end())
    out += fmt::format("<div class=\"meta\">float channels: <a href=\"{0}\">{1}</a></div>",
                       relativeUrl(it->second, report_dir), esc(it->second.filename().string()));

  const VisibilityStats& v = r.visibility;
  const DepthStats& d = r.depth;
  const ShadingStats& s = r.shading;
  const Tolerances& t = r.tolerances;
  out += "<div class=\"numbers\">";
  out += rowsTable(
      "visibility", v.status,
      {{"mismatched", fmt::format("{}", v.mismatched)},
       {"ambiguous", fmt::format("{}", v.ambiguous)},
       {"hard", fmt::format("{}", v.hard)},
       {"missing (hard)", fmt::format("{} ({})", v.missing, v.missing_hard)},
       {"extra (hard)", fmt::format("{} ({})", v.extra, v.extra_hard)},
       {"wrong_primitive (hard)",
        fmt::format("{} ({})", v.wrong_primitive, v.wrong_primitive_hard)},
       {"excused by depth_gap", fmt::format("{}", v.ambiguous_by_depth_gap)},
       {"band (px)", number(v.band_px)},
       {"uncertainty channels", v.uncertainty_available ? "yes" : "no"},
       {"thresholds warn / fail", fmt::format("{} / {}", t.visibility.warn, t.visibility.fail)},
       {"worst", at(v.worst, r.height)}});
  out +=
      rowsTable("depth", d.status,
                {{"compared", fmt::format("{}", d.compared)},
                 {"max (steps)", number(d.max_steps)},
                 {"mean", number(d.mean_steps)},
                 {"p99", number(d.p99_steps)},
                 {"over tolerance", fmt::format("{}", d.over_tolerance)},
                 {"over fail", fmt::format("{}", d.over_fail)},
                 {"non-finite", fmt::format("{}", d.nonfinite)},
                 {"blended, uncertain", fmt::format("{}", d.blend_uncertain)},
                 {"slope band (px)", number(d.band_px)},
                 {"format", toString(t.depth_format)},
                 {"thresholds warn / fail", fmt::format("{} / {} + {} x slope x band", t.depth.warn,
                                                        t.depth.fail, t.depth_slope_factor)},
                 {"worst", at(d.worst, r.height)},
                 {"worst steps / allowance",
                  fmt::format("{} / {}", number(d.worst_steps), number(d.worst_allowance))}});
  out += rowsTable(
      "shading", s.status,
      {{"compared", fmt::format("{}", s.compared)},
       {"max abs (8-bit)", number(s.max_abs)},
       {"mean abs", number(s.mean_abs)},
       {"rmse", number(s.rmse)},
       {"psnr (dB)", s.rmse > 0.0 ? number(s.psnr_db) : number(s.psnr_db) + " (identical)"},
       {"p99", number(s.p99_abs)},
       {"over warn", fmt::format("{}", s.over_tolerance)},
       {"over fail", fmt::format("{}", s.over_fail)},
       {"texel choice excused", fmt::format("{}", s.texel_choice)},
       {"blended, uncertain", fmt::format("{}", s.blend_uncertain)},
       {"non-finite", fmt::format("{}", s.nonfinite)},
       {"max R G B A",
        fmt::format("{} {} {} {}", number(s.max_abs_rgba[0]), number(s.max_abs_rgba[1]),
                    number(s.max_abs_rgba[2]), number(s.max_abs_rgba[3]))},
       {"format", toString(t.color_format)},
       {"thresholds warn / fail",
        fmt::format("{:.4g} / {:.4g} + allowance", t.shading.warn, t.shading.fail)},
       {"allowance", shadingAllowanceText(t, r.depth.band_px)},
       {"worst", at(s.worst, r.height)},
       {"worst error / allowance",
        fmt::format("{} / {}", number(s.worst_abs), number(s.worst_allowance))}});
  const std::uint64_t nf_e = r.nonfinite_expected.total();
  const std::uint64_t nf_a = r.nonfinite_actual.total();
  if (nf_e || nf_a) {
    std::vector<std::pair<std::string, std::string>> rows;
    for (std::size_t c = 0; c < kFrameChannels.size(); ++c)
      rows.emplace_back(
          kFrameChannels[c],
          fmt::format("{}/{} | {}/{}", r.nonfinite_expected.nan[c], r.nonfinite_expected.inf[c],
                      r.nonfinite_actual.nan[c], r.nonfinite_actual.inf[c]));
    out += rowsTable("NaN/Inf: expected | actual", Status::Fail, rows);
  }
  out += "</div></details>";
  return out;
}

std::string matrix(const Report& report) {
  // One column per backend compared; labelled "actual vs expected" when the pairs do not
  // all share one expected side (driver-vs-driver runs next to reference runs).
  bool one_expected = true;
  for (const PairResult& r : report.results)
    one_expected = one_expected && r.expected == report.results.front().expected;
  auto column = [&](const PairResult& r) {
    return one_expected ? r.actual : r.actual + " vs " + r.expected;
  };
  std::vector<std::string> backends;
  std::vector<std::string> fixtures;
  std::map<std::pair<std::string, std::string>, std::pair<Status, std::size_t>> cells;
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    if (std::find(backends.begin(), backends.end(), column(r)) == backends.end())
      backends.push_back(column(r));
    if (std::find(fixtures.begin(), fixtures.end(), r.fixture) == fixtures.end())
      fixtures.push_back(r.fixture);
    auto key = std::make_pair(r.fixture, column(r));
    auto it = cells.find(key);
    if (it == cells.end() || static_cast<int>(r.status) > static_cast<int>(it->second.first))
      cells[key] = {r.status, k};
  }
  // A run renders at least two backends (the compared one and --against), so it always
  // gets the matrix; a single `compare` does not.
  if (backends.empty() || (backends.size() < 2 && report.command != "run")) return "";
  std::string out = "<h2>Fixture &times; backend</h2>";
  if (one_expected)
    out += fmt::format("<div class=\"meta\">every backend compared against {}</div>",
                       esc(report.results.front().expected));
  out += "<table id=\"matrix\"><tr><th>fixture</th>";
  for (const std::string& b : backends) out += fmt::format("<th>{}</th>", esc(b));
  out += "</tr>";
  for (const std::string& f : fixtures) {
    out += fmt::format("<tr><td>{}</td>", esc(f));
    for (const std::string& b : backends) {
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
      "<th>tie-break</th><th>depth rounding</th><th>findings</th></tr>";
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
    std::string findings;
    if (v.contains("findings") && v["findings"].is_array()) {
      for (const nlohmann::json& f : v["findings"])
        if (f.is_string()) findings += (findings.empty() ? "" : "<br>") + esc(f.get<std::string>());
    }
    out += fmt::format("<td>{}</td></tr>", findings);
  }
  return out + "</table>";
}

}  // namespace

std::string reportHtml(const Report& report, const fs::path& report_dir) {
  const ReportSummary sum = report.summary();
  std::string gradient;
  for (const Rgb8& c : heatColorStops(9)) {
    if (!gradient.empty()) gradient += ',';
    gradient += hex(c);
  }

  std::string out = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">";
  out += fmt::format("<title>{} report</title><style>{}</style></head><body>",
                     esc(report.tool_name), kStyle);
  out += fmt::format("<h1>{} report</h1><div class=\"meta\">{} {}{}</div>", esc(report.tool_name),
                     esc(report.tool_name), esc(report.tool_version),
                     report.command.empty() ? "" : " &middot; " + esc(report.command));
  out += fmt::format(
      "<div class=\"summary\" id=\"summary\"><div>pairs<b>{}</b></div><div>pass<b>{}</b></div>"
      "<div>warn<b>{}</b></div><div>fail<b>{}</b></div><div>error<b>{}</b></div>"
      "<div>not supported<b>{}</b></div><div>exit code<b>{}</b></div></div>",
      sum.total(), sum.pass, sum.warn, sum.fail, sum.error, sum.not_supported, exitCodeFor(report));
  out += matrix(report);
  out += variantsTable(report);

  out +=
      "<h2>Pairs</h2><div class=\"controls\"><input id=\"filter\" type=\"search\" "
      "placeholder=\"filter: fixture, backend, status...\"><select id=\"status-filter\">"
      "<option value=\"\">all statuses</option><option value=\"not-pass\">not pass</option>"
      "<option value=\"pass\">pass</option><option value=\"warn\">warn</option>"
      "<option value=\"fail\">fail</option><option value=\"error\">error</option>"
      "<option value=\"not_supported\">not supported</option></select>"
      "<span id=\"shown\"></span></div>";
  out += "<table id=\"results\"><thead><tr>";
  const std::pair<const char*, bool> heads[] = {
      {"fixture", false},    {"expected", false},    {"actual", false},   {"status", true},
      {"hard px", true},     {"ambiguous px", true}, {"missing", true},   {"extra", true},
      {"wrong prim.", true}, {"depth max", true},    {"depth p99", true}, {"depth over", true},
      {"shading max", true}, {"shading mean", true}, {"PSNR dB", true},   {"shading over", true}};
  for (const auto& [name, numeric] : heads)
    out += fmt::format("<th data-type=\"{}\">{}</th>", numeric ? "num" : "text", name);
  out += "</tr></thead><tbody>";
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    std::string text = r.fixture + " " + r.expected + " " + r.actual + " " + toString(r.status);
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    out += fmt::format("<tr data-status=\"{}\" data-pair=\"pair-{}\" data-text=\"{}\">",
                       toString(r.status), k, esc(text));
    out += cell(fmt::format("<a href=\"#pair-{}\">{}</a>", k, esc(r.fixture)), r.fixture, false);
    out += cell(esc(r.expected), r.expected, false);
    out += cell(esc(r.actual), r.actual, false);
    out += cell(badge(r.status), fmt::format("{}", static_cast<int>(r.status)), true);
    if (r.status == Status::Error || r.status == Status::NotSupported) {
      for (int c = 0; c < 12; ++c) out += emptyCell();
    } else {
      out += countCell(r.visibility.hard);
      out += countCell(r.visibility.ambiguous);
      out += countCell(r.visibility.missing);
      out += countCell(r.visibility.extra);
      out += countCell(r.visibility.wrong_primitive);
      out += numCell(r.depth.max_steps);
      out += numCell(r.depth.p99_steps);
      out += countCell(r.depth.over_tolerance);
      out += numCell(r.shading.max_abs);
      out += numCell(r.shading.mean_abs);
      out += numCell(r.shading.psnr_db);
      out += countCell(r.shading.over_tolerance);
    }
    out += "</tr>";
  }
  out += "</tbody></table>";

  out += "<h2>Details</h2>";
  for (std::size_t k = 0; k < report.results.size(); ++k)
    out += pairSection(report.results[k], k, report_dir, gradient);
  out += fmt::format("<script>{}</script></body></html>\n", kScript);
  return out;
}

}  // namespace rc
