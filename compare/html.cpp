// report.html: one self-contained page (inline CSS and JS, no network; images are the
// relative files beside it), built to stay usable at tens of thousands of pairs: the
// summary, per-backend counts, a fixture x backend matrix (only fixtures with a
// non-passing pair when there are many), then the pairs table with failures first, grouped
// by signature (what failed, how), passing pairs collapsed into a count, filters by text,
// status, backend, class and tag; per pair the images side by side with legends and the
// numbers, images loaded only when the pair is opened. Small reports carry every pair's
// section in the page; large ones keep the sections as data and build one when opened.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "compare/pair_images.h"
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

std::string esc(std::string_view s) { return htmlEscape(s); }

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
.pass{background:#2e7d32}.warn{background:#e6a100}.fail{background:#c62828}.error{background:#6a1b9a}
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
.controls select{padding:3px}
tr.group-head th{background:#fff;text-align:left;cursor:pointer;font-weight:600;position:static}
tr.group-head .sig{font-family:ui-monospace,monospace;font-size:12px}
tr.group-head .by{color:#666;font-weight:normal;font-size:12px}
tbody.collapsed tr.pair-row,tbody.collapsed tr.detail-row{display:none}
tbody.collapsed .fold::before{content:"\25B8 "}tbody .fold::before{content:"\25BE "}
tr.detail-row > td{white-space:normal;background:#f6f6f6}
.hidden{display:none}
)CSS";

constexpr const char* kScript = R"JS(
(function () {
  var D = JSON.parse(document.getElementById('report-data').textContent);
  var P = D.pairs;  // per pair: fixture, expected, actual, status, column, classes, tags, group, numbers
  var table = document.getElementById('results');
  var filter = document.getElementById('filter');
  var statusF = document.getElementById('status-filter');
  var backendF = document.getElementById('backend-filter');
  var classF = document.getElementById('class-filter');
  var tagF = document.getElementById('tag-filter');
  var shown = document.getElementById('shown');
  var pending = 0, ready = false;

  function matches(k) {
    var p = P[k], text = filter.value.toLowerCase(), st = statusF.value;
    if (text && (p[0] + ' ' + p[1] + ' ' + p[2] + ' ' + p[3]).toLowerCase().indexOf(text) < 0) return false;
    if (st && p[3] !== st && !(st === 'not-pass' && p[3] !== 'pass')) return false;
    if (backendF.value !== '' && String(p[4]) !== backendF.value) return false;
    if (classF.value && p[5].indexOf(classF.value) < 0) return false;
    if (tagF.value !== '' && p[6].indexOf(+tagF.value) < 0) return false;
    return true;
  }

  // Marks for people (broken images get a red outline) and for automated checks.
  function report() {
    var ok = 0, bad = 0;
    for (var i = 0; i < document.images.length; i++) {
      var img = document.images[i];
      if (!img.getAttribute('src')) continue;
      if (img.complete && img.naturalWidth > 0) ok++; else bad++;
    }
    document.body.setAttribute('data-images-ok', ok);
    document.body.setAttribute('data-images-failed', bad);
    document.body.setAttribute('data-rows-rendered', document.querySelectorAll('tr.pair-row').length);
    document.body.setAttribute('data-pairs-rendered', document.querySelectorAll('details.pair').length);
    if (ready && pending === 0 && !document.body.hasAttribute('data-ready')) {
      document.body.setAttribute('data-ready', '1');
      document.body.setAttribute('data-ready-ms', Math.round(performance.now()));
    }
  }
  function settled(e) {
    if (e.type === 'error') e.target.classList.add('broken');
    pending--;
    report();
  }
  // Images load when their pair is opened, not with the page.
  function loadImages(root) {
    var imgs = root.querySelectorAll('img[data-src]');
    for (var i = 0; i < imgs.length; i++) {
      var img = imgs[i];
      pending++;
      img.addEventListener('load', settled);
      img.addEventListener('error', settled);
      img.src = img.getAttribute('data-src');
      img.removeAttribute('data-src');
    }
  }
  function watch(details) {
    if (details.open) loadImages(details);
    details.addEventListener('toggle', function () { if (details.open) loadImages(details); });
  }

  function cell(text, key, numeric) {
    var td = document.createElement('td');
    td.setAttribute('data-v', key);
    if (numeric) td.className = 'n';
    td.innerHTML = text;
    return td;
  }
  function fmt(v) {
    if (v === null) return '&mdash;';
    return Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toPrecision(4) : String(+v.toPrecision(4));
  }
  function esc(t) {
    return String(t).replace(/[&<>"']/g, function (c) {
      return {'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;'}[c];
    });
  }
  // A row of a pair the page carries as data only (passing pairs of large reports).
  function buildRow(k) {
    var p = P[k], tr = document.createElement('tr');
    tr.className = 'pair-row';
    tr.setAttribute('data-k', k);
    tr.appendChild(cell('<a href="#pair-' + k + '">' + esc(p[0]) + '</a>', p[0], false));
    tr.appendChild(cell(esc(p[1]), p[1], false));
    tr.appendChild(cell(esc(p[2]), p[2], false));
    tr.appendChild(cell('<span class="badge ' + p[3] + '">' + p[3] + '</span>', '0', true));
    for (var i = 0; i < 12; i++) {
      var v = p[8] ? p[8][i] : null;
      tr.appendChild(cell(fmt(v), v === null ? '-1' : String(v), true));
    }
    return tr;
  }
  function fillLazy(body) {
    if (!body.hasAttribute('data-lazy')) return;
    body.removeAttribute('data-lazy');
    var frag = document.createDocumentFragment();
    for (var k = 0; k < P.length; k++) if (P[k][7] === +body.getAttribute('data-group')) frag.appendChild(buildRow(k));
    body.appendChild(frag);
    apply();
  }
  function rowOf(k) { return table.querySelector('tr.pair-row[data-k="' + k + '"]'); }

  // Opens pair k: its section (small reports) or a detail row under its table row.
  function openPair(k) {
    var el = document.getElementById('pair-' + k);
    if (!el && D.big) {
      var row = rowOf(k);
      if (!row) {
        var body = table.querySelector('tbody[data-group="' + P[k][7] + '"]');
        if (body) { fillLazy(body); row = rowOf(k); }
      }
      if (!row) return null;
      row.parentNode.classList.remove('collapsed');
      var tr = document.createElement('tr'), td = document.createElement('td');
      tr.className = 'detail-row';
      tr.setAttribute('data-k', k);
      td.colSpan = 16;
      var p = P[k];
      td.innerHTML = D.details[k] || ('<details class="pair" id="pair-' + k + '"><summary><h3>' + esc(p[0]) +
          ' &mdash; ' + esc(p[1]) + ' vs ' + esc(p[2]) + ' <span class="badge ' + p[3] + '">' + p[3] +
          '</span></h3></summary><div class="describe">Every class passes; the numbers are in the row above ' +
          'and in report.json (run with --keep-frames for images of passing pairs).</div></details>');
      tr.appendChild(td);
      row.parentNode.insertBefore(tr, row.nextSibling);
      el = document.getElementById('pair-' + k);
      watch(el);
    }
    if (el && el.tagName === 'DETAILS') el.open = true;
    return el;
  }
  function openTarget() {
    var h = location.hash.slice(1);
    if (h === 'open-all') {
      for (var k = 0; k < P.length; k++) openPair(k);
      return;
    }
    var m = /^pair-(\d+)$/.exec(h);
    if (!m) return;
    var el = openPair(+m[1]);
    if (el) el.scrollIntoView();
  }

  function apply() {
    var visible = 0, per = {};
    for (var k = 0; k < P.length; k++) if (matches(k)) { visible++; per[P[k][7]] = (per[P[k][7]] || 0) + 1; }
    var rows = table.querySelectorAll('tr.pair-row, tr.detail-row');
    for (var i = 0; i < rows.length; i++) {
      var k2 = +rows[i].getAttribute('data-k'), ok = matches(k2);
      rows[i].classList.toggle('hidden', !ok);
      var sec = D.big ? null : document.getElementById('pair-' + k2);
      if (sec) sec.classList.toggle('hidden', !ok);
    }
    var groups = table.tBodies;
    for (var g = 0; g < groups.length; g++) {
      var n = per[groups[g].getAttribute('data-group')] || 0;
      groups[g].classList.toggle('hidden', n === 0);
      var c = groups[g].querySelector('.count');
      if (c) c.textContent = n;
    }
    shown.textContent = visible + ' of ' + P.length + ' pairs shown';
  }

  function sortBy(th) {
    var index = Array.prototype.indexOf.call(th.parentNode.children, th);
    var numeric = th.getAttribute('data-type') === 'num';
    var asc = !th.classList.contains('asc');
    var heads = th.parentNode.children;
    for (var k = 0; k < heads.length; k++) heads[k].classList.remove('asc', 'desc');
    th.classList.add(asc ? 'asc' : 'desc');
    for (var g = 0; g < table.tBodies.length; g++) {
      var body = table.tBodies[g];
      var rows = Array.prototype.slice.call(body.querySelectorAll('tr.pair-row'));
      rows.sort(function (a, b) {
        var x = a.cells[index].getAttribute('data-v'), y = b.cells[index].getAttribute('data-v');
        var c = numeric ? parseFloat(x) - parseFloat(y) : x.localeCompare(y);
        return asc ? c : -c;
      });
      rows.forEach(function (r) {
        var detail = body.querySelector('tr.detail-row[data-k="' + r.getAttribute('data-k') + '"]');
        body.appendChild(r);
        if (detail) body.appendChild(detail);
      });
    }
  }

  var ths = table.tHead.rows[0].cells;
  for (var i = 0; i < ths.length; i++)
    ths[i].addEventListener('click', function (e) { sortBy(e.currentTarget); });
  var heads = table.querySelectorAll('tr.group-head');
  for (var j = 0; j < heads.length; j++)
    heads[j].addEventListener('click', function (e) {
      var body = e.currentTarget.parentNode;
      fillLazy(body);
      body.classList.toggle('collapsed');
    });
  [filter, statusF, backendF, classF, tagF].forEach(function (el) {
    el.addEventListener(el.tagName === 'INPUT' ? 'input' : 'change', apply);
  });
  var sections = document.querySelectorAll('details.pair');
  for (var s = 0; s < sections.length; s++) watch(sections[s]);
  window.addEventListener('hashchange', openTarget);
  openTarget();
  apply();
  ready = true;
  report();
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
      "<figure><a href=\"{0}\"><img data-src=\"{0}\" alt=\"{1}\" width=\"{2}\" height=\"{3}\"></a>"
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
  if (r.status == Status::Error) return out + "</details>";

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
                 {"slope unknown", fmt::format("{}", d.slope_unknown)},
                 {"slope from plane fit", fmt::format("{}", d.slope_fitted)},
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

// Reports up to this many pairs carry every pair's row and section in the page; larger
// ones carry the passing rows and all sections as data (built when opened), so that the
// page stays quick to open (docs/performance.md: 10,000 pairs).
constexpr std::size_t kStaticPairs = 200;
// The matrix lists every fixture up to this many, else only those that did not pass.
constexpr std::size_t kMatrixRows = 40;

// The column a pair belongs to: its actual backend, labelled "actual vs expected" when the
// pairs do not all share one expected side (driver-vs-driver runs next to reference runs).
struct Columns {
  bool one_expected = true;
  std::vector<std::string> names;
  std::vector<std::size_t> of;  // per result
};

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
  std::vector<std::string> rows = fixtures;
  if (fixtures.size() > kMatrixRows)
    std::erase_if(rows, [&](const std::string& f) { return all_pass[f]; });
  std::string out = "<h2>Fixture &times; backend</h2>";
  if (columns.one_expected)
    out += fmt::format("<div class=\"meta\">every backend compared against {}</div>",
                       esc(report.results.front().expected));
  if (rows.size() < fixtures.size())
    out += fmt::format(
        "<div class=\"meta\">only the {} fixtures with a pair that did not pass; {} fixtures "
        "pass on every backend</div>",
        rows.size(), fixtures.size() - rows.size());
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
  std::vector<std::array<std::uint64_t, 4>> n(columns.names.size(), {0, 0, 0, 0});
  for (std::size_t k = 0; k < report.results.size(); ++k)
    ++n[columns.of[k]][static_cast<std::size_t>(report.results[k].status)];
  std::string out =
      "<h2>Backends</h2><table id=\"backends\"><tr><th>backend</th><th>pass</th><th>warn</th>"
      "<th>fail</th><th>error</th></tr>";
  for (std::size_t b = 0; b < columns.names.size(); ++b)
    out += fmt::format(
        "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>"
        "<td class=\"n\">{}</td></tr>",
        esc(columns.names[b]), n[b][0], n[b][1], n[b][2], n[b][3]);
  return out + "</table>";
}

// What a non-passing pair's failure looks like, for grouping alike failures: the classes
// at the pair's status (visibility with its largest kind of hard mismatch), or for an
// error row its message with the fixture name and every number taken out.
std::string signature(const PairResult& r) {
  if (r.status == Status::Error) {
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

// The table row of pair k.
std::string pairRow(const PairResult& r, std::size_t k) {
  std::string out = fmt::format("<tr class=\"pair-row\" data-k=\"{}\">", k);
  out += cell(fmt::format("<a href=\"#pair-{}\">{}</a>", k, esc(r.fixture)), r.fixture, false);
  out += cell(esc(r.expected), r.expected, false);
  out += cell(esc(r.actual), r.actual, false);
  out += cell(badge(r.status), fmt::format("{}", static_cast<int>(r.status)), true);
  if (r.status == Status::Error) {
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
  return out + "</tr>";
}

nlohmann::json finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

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
      "<th>GL_SUBPIXEL_BITS</th><th>subpixel precision</th><th>tie-break</th>"
      "<th>depth rounding</th></tr>";
  for (const auto& [spec, v] : report.variants.items()) {
    out += fmt::format("<tr><td>{}</td>", esc(spec));
    if (v.contains("error")) {
      out += fmt::format("<td colspan=\"5\">{} {}</td></tr>", badge(Status::Error),
                         esc(text(v, "error")));
      continue;
    }
    out += fmt::format("<td>{}</td><td class=\"n\">{}</td>", esc(text(v, "renderer")),
                       esc(text(v, "subpixel_bits")));
    out += fmt::format("<td>{} {}</td>",
                       mark(v, "subpixel", "confirmed", "confirmed", "not confirmed"),
                       esc(text(v, "subpixel")));
    out += fmt::format("<td>{} {}</td>",
                       mark(v, "tie_break", "matches_reference", "as ref", "differs"),
                       esc(text(v, "tie_break")));
    out += fmt::format("<td>{} {}</td></tr>",
                       mark(v, "depth_rounding", "matches_reference", "as ref", "differs"),
                       esc(text(v, "depth_rounding")));
  }
  return out + "</table>";
}

}  // namespace

std::string reportHtml(const Report& report, const fs::path& report_dir) {
  const ReportSummary sum = report.summary();
  const bool big = report.results.size() > kStaticPairs;
  std::string gradient;
  for (const Rgb8& c : heatColorStops(9)) {
    if (!gradient.empty()) gradient += ',';
    gradient += hex(c);
  }
  const Columns columns = columnsOf(report);

  // Groups: one per (status, signature) of the pairs that did not pass, worst status
  // first, then the largest; then one for every passing pair.
  struct Group {
    Status status;
    std::string signature;
    std::vector<std::size_t> pairs;
  };
  std::vector<Group> groups;
  std::map<std::pair<int, std::string>, std::size_t> group_of_key;
  std::vector<std::size_t> group_of(report.results.size());
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
  std::vector<std::size_t> order(groups.size());
  for (std::size_t g = 0; g < order.size(); ++g) order[g] = g;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (groups[a].status != groups[b].status)
      return static_cast<int>(groups[a].status) > static_cast<int>(groups[b].status);
    if (groups[a].pairs.size() != groups[b].pairs.size())
      return groups[a].pairs.size() > groups[b].pairs.size();
    return groups[a].signature < groups[b].signature;
  });
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (std::size_t k : groups[g].pairs) group_of[k] = g;
  std::vector<std::string> tags;
  for (const PairResult& r : report.results)
    for (const std::string& t : r.tags)
      if (std::find(tags.begin(), tags.end(), t) == tags.end()) tags.push_back(t);
  std::sort(tags.begin(), tags.end());

  std::string out = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">";
  out += fmt::format("<title>{} report</title><style>{}</style></head><body>",
                     esc(report.tool_name), kStyle);
  out += fmt::format("<h1>{} report</h1><div class=\"meta\">{} {}{}</div>", esc(report.tool_name),
                     esc(report.tool_name), esc(report.tool_version),
                     report.command.empty() ? "" : " &middot; " + esc(report.command));
  out += fmt::format(
      "<div class=\"summary\" id=\"summary\"><div>pairs<b>{}</b></div><div>pass<b>{}</b></div>"
      "<div>warn<b>{}</b></div><div>fail<b>{}</b></div><div>error<b>{}</b></div>"
      "<div>exit code<b>{}</b></div></div>",
      sum.total(), sum.pass, sum.warn, sum.fail, sum.error, exitCodeFor(report));
  out += backendCounts(report, columns);
  out += matrix(report, columns);
  out += variantsTable(report);

  out +=
      "<h2>Pairs</h2><div class=\"controls\"><input id=\"filter\" type=\"search\" "
      "placeholder=\"filter: fixture, backend, status...\"><select id=\"status-filter\">"
      "<option value=\"\">all statuses</option><option value=\"not-pass\">not pass</option>"
      "<option value=\"pass\">pass</option><option value=\"warn\">warn</option>"
      "<option value=\"fail\">fail</option><option value=\"error\">error</option></select>"
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
  for (const std::size_t g : order) {
    const Group& group = groups[g];
    const bool pass = group.status == Status::Pass;
    const bool lazy = pass && big;  // passing rows of large reports: built when opened
    std::map<std::size_t, std::size_t> per_column;
    for (std::size_t k : group.pairs) ++per_column[columns.of[k]];
    std::string by;
    for (const auto& [b, n] : per_column)
      by += fmt::format("{}{} {}", by.empty() ? "" : ", ", columns.names[b], n);
    out += fmt::format(
        "<tbody data-group=\"{}\"{}{}><tr class=\"group-head\"><th colspan=\"16\"><span "
        "class=\"fold\"></span>{} <span class=\"sig\">{}</span> &mdash; <span "
        "class=\"count\">{}</span> pairs <span class=\"by\">({})</span></th></tr>",
        g, lazy ? " class=\"collapsed\"" : "", lazy ? " data-lazy=\"1\"" : "", badge(group.status),
        esc(pass ? std::string("every class passes") : group.signature), group.pairs.size(),
        esc(by));
    if (!lazy)
      for (std::size_t k : group.pairs) out += pairRow(report.results[k], k);
    out += "</tbody>";
  }
  out += "</table>";

  // Every pair as data: what the filters, counts and built rows need.
  nlohmann::json pairs = nlohmann::json::array();
  nlohmann::json details = nlohmann::json::array();
  for (std::size_t k = 0; k < report.results.size(); ++k) {
    const PairResult& r = report.results[k];
    nlohmann::json classes = nlohmann::json::array();
    if (r.status != Status::Error) {
      if (r.visibility.status != Status::Pass) classes.push_back("visibility");
      if (r.depth.status != Status::Pass) classes.push_back("depth");
      if (r.shading.status != Status::Pass) classes.push_back("shading");
    }
    nlohmann::json tag_ids = nlohmann::json::array();
    for (const std::string& t : r.tags)
      tag_ids.push_back(std::find(tags.begin(), tags.end(), t) - tags.begin());
    nlohmann::json numbers;
    if (r.status != Status::Error)
      numbers = {
          r.visibility.hard,          r.visibility.ambiguous,       r.visibility.missing,
          r.visibility.extra,         r.visibility.wrong_primitive, finite(r.depth.max_steps),
          finite(r.depth.p99_steps),  r.depth.over_tolerance,       finite(r.shading.max_abs),
          finite(r.shading.mean_abs), finite(r.shading.psnr_db),    r.shading.over_tolerance};
    pairs.push_back({r.fixture, r.expected, r.actual, toString(r.status), columns.of[k], classes,
                     tag_ids, group_of[k], numbers});
    if (big)
      details.push_back(r.status == Status::Pass && r.images.empty()
                            ? nlohmann::json()
                            : nlohmann::json(pairSection(r, k, report_dir, gradient)));
  }
  if (!big) {
    out += "<h2>Details</h2>";
    for (std::size_t k = 0; k < report.results.size(); ++k)
      out += pairSection(report.results[k], k, report_dir, gradient);
  }
  nlohmann::json data = {{"big", big}, {"pairs", pairs}};
  if (big) data["details"] = details;
  // Inside <script>, "</script>" or "<!--" in a name would end or confuse the element:
  // JSON may spell every '<' as \u003c (it can only occur inside strings).
  std::string text = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string safe;
  safe.reserve(text.size());
  for (const char ch : text) {
    if (ch == '<')
      safe += "\\u003c";
    else
      safe += ch;
  }
  out += fmt::format("<script type=\"application/json\" id=\"report-data\">{}</script>", safe);
  out += fmt::format("<script>{}</script></body></html>\n", kScript);
  return out;
}

}  // namespace rc
