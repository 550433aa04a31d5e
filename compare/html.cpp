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

std::string hex(const Rgb8& c) { return fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]); }

std::string badge(Status s) {
  return fmt::format("<span class=\"badge {0}\">{0}</span>", toString(s));
}

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
.controls select{padding:3px}
tr.group-head th{background:#fff;text-align:left;cursor:pointer;font-weight:600;position:static}
tr.group-head .sig{font-family:ui-monospace,monospace;font-size:12px}
tr.group-head .by{color:#666;font-weight:normal;font-size:12px}
tbody.collapsed tr.pair-row,tbody.collapsed tr.detail-row{display:none}
tbody.collapsed .fold::before{content:"\25B8 "}tbody .fold::before{content:"\25BE "}
tr.detail-row > td{white-space:normal;background:#f6f6f6}
tr.group-head:hover th{background:#f4f4f4}
.hidden{display:none}
)CSS";
constexpr const char* kScript = R"JS(
(function () {
  var D = JSON.parse(document.getElementById('report-data').textContent);
  // Per pair: fixture, expected, actual, status, column, classes not passing, tag ids,
  // group, the row's 12 numbers (null for error rows).
  var P = D.pairs;
  var X = D.details;  // per pair: what its section shows (null: a passing pair without images)
  var table = document.getElementById('results');
  var filter = document.getElementById('filter');
  var statusF = document.getElementById('status-filter');
  var backendF = document.getElementById('backend-filter');
  var classF = document.getElementById('class-filter');
  var tagF = document.getElementById('tag-filter');
  var shown = document.getElementById('shown');
  var pending = 0, ready = false;

  function esc(t) {
    return String(t).replace(/[&<>"']/g, function (c) {
      return {'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;'}[c];
    });
  }
  // Numbers as the C++ side prints them (4 significant digits); strings are non-finite.
  function num(v) {
    if (v === null || v === undefined) return '&mdash;';
    if (typeof v === 'string') return v;
    return String(+v.toPrecision(4));
  }
  function badge(s) { return '<span class="badge ' + s + '">' + s + '</span>'; }
  function at(x, y, h) { return x < 0 ? '(none)' : '(' + x + ',' + y + ') window (' + x + ',' + (h - 1 - y) + ')'; }

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
    var b = document.body;
    b.setAttribute('data-images-ok', ok);
    b.setAttribute('data-images-failed', bad);
    b.setAttribute('data-rows-rendered', table.querySelectorAll('tr.pair-row').length);
    b.setAttribute('data-pairs-rendered', document.querySelectorAll('details.pair').length);
    if (ready && pending === 0 && !b.hasAttribute('data-ready')) {
      b.setAttribute('data-ready', '1');
      b.setAttribute('data-ready-ms', Math.round(performance.now()));
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

  // ---- one pair's section: images with legends, then the numbers ----
  function figure(x, kind, caption, legend) {
    if (!x.f || !x.f[kind]) return '';
    var url = x.img + x.f[kind];
    var h = x.wh[0] > 0 ? Math.floor(240 * x.wh[1] / x.wh[0]) : 240;
    return '<figure><a href="' + url + '"><img data-src="' + url + '" alt="' + esc(caption) +
        '" width="240" height="' + h + '"></a><figcaption>' + esc(caption) + '</figcaption>' +
        (legend || '') + '</figure>';
  }
  function sw(cls, label) { return '<span><i class="sw ' + cls + '"></i>' + label + '</span>'; }
  function heatLegend(scale, unit) {
    return '<div class="ramp"></div><div class="ramp-labels"><span>0</span><span>log scale</span><span>' +
        num(scale) + ' ' + unit + '</span></div><div class="legend">' + sw('nc', 'not compared') +
        sw('nf', 'NaN/Inf') + '</div>';
  }
  function table2(title, status, rows) {
    var out = '<table><tr><th colspan="2">' + title + ' ' + badge(status) + '</th></tr>';
    for (var i = 0; i < rows.length; i++)
      out += '<tr><td>' + esc(rows[i][0]) + '</td><td class="n">' + esc(rows[i][1]) + '</td></tr>';
    return out + '</table>';
  }
  function section(k) {
    var p = P[k], x = X[k] || {}, open = p[3] !== 'pass';
    var out = '<details class="pair" id="pair-' + k + '"' + (open ? ' open' : '') + '><summary><h3>' +
        esc(p[0]) + ' &mdash; ' + esc(p[1]) + ' vs ' + esc(p[2]) + ' ' + badge(p[3]) + '</h3></summary>';
    out += '<div class="describe">' + esc(x.d || ('PASS ' + p[0] + ' ' + p[1] + ' vs ' + p[2])) + '</div>';
    if (p[3] === 'error' || p[3] === 'not_supported') return out + '</details>';
    var v = x.v;
    var vis = v ? '<div class="legend">' + sw('c1', 'match') + sw('c3', 'missing ' + v[4]) +
        sw('c2', 'missing (ambiguous) ' + (v[3] - v[4])) + sw('c5', 'extra ' + v[6]) +
        sw('c4', 'extra (ambiguous) ' + (v[5] - v[6])) + sw('c7', 'wrong_primitive ' + v[8]) +
        sw('c6', 'wrong_primitive (ambiguous) ' + (v[7] - v[8])) + sw('c0', 'background') + '</div>' : '';
    var hs = x.hs || [1, 1];
    out += '<div class="images">' + figure(x, 'expected', 'expected: ' + p[1]) +
        figure(x, 'actual', 'actual: ' + p[2]) + figure(x, 'visibility', 'visibility classes', vis) +
        figure(x, 'depth_heat', 'depth |dZ| (steps)', heatLegend(hs[0], 'steps')) +
        figure(x, 'shading_heat', 'shading max |dC| (8-bit units)', heatLegend(hs[1], 'units')) +
        figure(x, 'flip_heat', 'LDR-FLIP error (0 to 1, magma)', x.fl ? '<div class="ramp-labels">' +
            '<span>0</span><span>mean ' + num(x.fl[0]) + '</span><span>1</span></div>' : '') + '</div>';
    if (x.f && x.f.diff_exr)
      out += '<div class="meta">float channels: <a href="' + x.img + x.f.diff_exr + '">' +
          esc(x.f.diff_exr) + '</a></div>';
    if (!v) {
      // A passing pair of a large report: the row's numbers.
      var n = p[8];
      return out + '<div class="numbers">' + table2('key numbers', p[3], [
        ['hard px', num(n[0])], ['ambiguous px', num(n[1])], ['depth max (steps)', num(n[5])],
        ['depth p99', num(n[6])], ['shading max (8-bit)', num(n[8])], ['PSNR (dB)', num(n[10])]]) +
        '</div><div class="meta">every number of this pair is in report.json</div></details>';
    }
    var z = x.z, s = x.s, t = x.t, h = x.wh[1], cs = x.cs;
    out += '<div class="numbers">';
    out += table2('visibility', cs[0], [
      ['mismatched', v[0]], ['ambiguous', v[1]], ['hard', v[2]],
      ['missing (hard)', v[3] + ' (' + v[4] + ')'], ['extra (hard)', v[5] + ' (' + v[6] + ')'],
      ['wrong_primitive (hard)', v[7] + ' (' + v[8] + ')'], ['excused by depth_gap', v[9]],
      ['band (px)', num(v[10])], ['uncertainty channels', v[11] ? 'yes' : 'no'],
      ['thresholds warn / fail', t[0] + ' / ' + t[1]], ['worst', at(v[12], v[13], h)]]);
    out += table2('depth', cs[1], [
      ['compared', z[0]], ['max (steps)', num(z[1])], ['mean', num(z[2])], ['p99', num(z[3])],
      ['over tolerance', z[4]], ['over fail', z[5]], ['non-finite', z[6]], ['blended, uncertain', z[7]],
      ['slope band (px)', num(z[8])], ['format', x.fmt[0]],
      ['thresholds warn / fail', t[2] + ' / ' + t[3] + ' + ' + t[4] + ' x slope x band'],
      ['worst', at(z[9], z[10], h)], ['worst steps / allowance', num(z[11]) + ' / ' + num(z[12])]]);
    out += table2('shading', cs[2], [
      ['compared', s[0]], ['max abs (8-bit)', num(s[1])], ['mean abs', num(s[2])], ['rmse', num(s[3])],
      ['psnr (dB)', num(s[4]) + (s[3] > 0 ? '' : ' (identical)')], ['p99', num(s[5])],
      ['over warn', s[6]], ['over fail', s[7]], ['texel choice excused', s[17]],
      ['blended, uncertain', s[18]], ['non-finite', s[8]],
      ['max R G B A', num(s[9]) + ' ' + num(s[10]) + ' ' + num(s[11]) + ' ' + num(s[12])],
      ['format', x.fmt[1]], ['thresholds warn / fail', num(t[5]) + ' / ' + num(t[6]) + ' + allowance'],
      ['allowance', x.a], ['worst', at(s[13], s[14], h)],
      ['worst error / allowance', num(s[15]) + ' / ' + num(s[16])]]);
    // The additive blocks: perceptual error (flip, ciede2000) and, against ref:abuffer,
    // exact transparency (oit).
    if (x.de)
      out += table2('CIEDE2000 (per pixel, 8-bit sRGB)', 'pass', [
        ['mean', num(x.de[0])], ['weighted median', num(x.de[1])],
        ['weighted quartiles', num(x.de[2]) + ' / ' + num(x.de[3])], ['max', num(x.de[4])],
        ['pixels that differ', x.de[5]], ['worst', at(x.de[6], x.de[7], h)]]);
    if (x.fl)
      out += table2('flip (LDR-FLIP)', x.fl[6], [
        ['mean', num(x.fl[0])], ['weighted median', num(x.fl[1])],
        ['weighted quartiles', num(x.fl[2]) + ' / ' + num(x.fl[3])], ['max', num(x.fl[4])],
        ['pixels per degree', num(x.fl[5])], ['fail above (mean)', x.fl[7] === null ? 'none' : num(x.fl[7])]]);
    if (x.oi)
      out += table2('transparency vs exact (A-buffer)', 'pass', [
        ['blended pixels', x.oi[0]], ['draw order not depth order', x.oi[1]],
        ['pixels over shading warn', x.oi[2]], ['max abs (8-bit)', num(x.oi[3])],
        ['mean abs (blended)', num(x.oi[4])], ['out-of-order pairs (far over near)', x.oi[5] || 'none']]);
    if (x.nf) {
      var names = ['R', 'G', 'B', 'A', 'Z'], rows = [];
      for (var c = 0; c < 5; c++)
        rows.push([names[c], x.nf[0][c] + '/' + x.nf[1][c] + ' | ' + x.nf[2][c] + '/' + x.nf[3][c]]);
      out += table2('NaN/Inf: expected | actual', 'fail', rows);
    }
    return out + '</div></details>';
  }

  // ---- the pairs table ----
  function cell(html, key, numeric) {
    var td = document.createElement('td');
    td.setAttribute('data-v', key);
    if (numeric) td.className = 'n';
    td.innerHTML = html;
    return td;
  }
  var ORDER = {pass: 0, warn: 1, fail: 2, error: 3, not_supported: 4};
  function buildRow(k) {
    var p = P[k], tr = document.createElement('tr');
    tr.className = 'pair-row';
    tr.setAttribute('data-k', k);
    tr.appendChild(cell('<a href="#pair-' + k + '">' + esc(p[0]) + '</a>', p[0], false));
    tr.appendChild(cell(esc(p[1]), p[1], false));
    tr.appendChild(cell(esc(p[2]), p[2], false));
    tr.appendChild(cell(badge(p[3]), String(ORDER[p[3]]), true));
    for (var i = 0; i < 12; i++) {
      var v = p[8] ? p[8][i] : null;
      tr.appendChild(cell(num(v), v === null ? '-1' : (typeof v === 'string' ? '1e308' : String(v)), true));
    }
    return tr;
  }
  // A group's rows are built the first time it is opened.
  function fill(body) {
    if (!body.hasAttribute('data-lazy')) return;
    body.removeAttribute('data-lazy');
    var g = +body.getAttribute('data-group'), frag = document.createDocumentFragment();
    for (var k = 0; k < P.length; k++) if (P[k][7] === g) frag.appendChild(buildRow(k));
    body.appendChild(frag);
    apply();
  }
  function rowOf(k) { return table.querySelector('tr.pair-row[data-k="' + k + '"]'); }

  // Opens pair k: its section below the table (small reports) or a row under its table row.
  function openPair(k) {
    if (!(k >= 0 && k < P.length)) return null;
    var el = document.getElementById('pair-' + k);
    if (!el && D.big) {
      var body = table.querySelector('tbody[data-group="' + P[k][7] + '"]');
      fill(body);
      body.classList.remove('collapsed');
      var row = rowOf(k), tr = document.createElement('tr'), td = document.createElement('td');
      tr.className = 'detail-row';
      tr.setAttribute('data-k', k);
      td.colSpan = 16;
      td.innerHTML = section(k);
      tr.appendChild(td);
      row.parentNode.insertBefore(tr, row.nextSibling);
      el = document.getElementById('pair-' + k);
      watch(el);
    }
    if (el) el.open = true;
    return el;
  }
  function openTarget() {
    var h = location.hash.slice(1);
    if (h === 'open-all') {
      for (var k = 0; k < P.length; k++) openPair(k);
      return;
    }
    var m = /^pair-(\d+)$/.exec(h);
    var el = m ? openPair(+m[1]) : null;
    // Large reports: the pair's row, with its section under it, below the sticky header.
    var row = el && D.big ? rowOf(+m[1]) : null;
    if (row) window.scrollTo(0, row.getBoundingClientRect().top + window.scrollY - 40);
    else if (el) el.scrollIntoView();
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
      groups[g].querySelector('.count').textContent = n;
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

  // Small reports: every row and every section now; large ones: on demand.
  var bodies = table.tBodies;
  for (var b = 0; b < bodies.length; b++) if (!D.big) fill(bodies[b]);
  if (!D.big) {
    var html = '';
    for (var k = 0; k < P.length; k++) html += section(k);
    document.getElementById('details').innerHTML = html;
  }
  var ths = table.tHead.rows[0].cells;
  for (var i = 0; i < ths.length; i++)
    ths[i].addEventListener('click', function (e) { sortBy(e.currentTarget); });
  var gheads = table.querySelectorAll('tr.group-head');
  for (var j = 0; j < gheads.length; j++)
    gheads[j].addEventListener('click', function (e) {
      var body = e.currentTarget.parentNode;
      fill(body);
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

// Colours of the legends, from the same tables the images use.
std::string legendStyle() {
  std::string gradient;
  for (const Rgb8& c : heatColorStops(9)) {
    if (!gradient.empty()) gradient += ',';
    gradient += hex(c);
  }
  std::string out = fmt::format(".ramp{{background:linear-gradient(to right,{})}}", gradient);
  for (int c = 0; c < kPixelClassCount; ++c)
    out += fmt::format(".sw.c{}{{background:{}}}", c, hex(classColor(static_cast<PixelClass>(c))));
  out += fmt::format(".sw.nc{{background:{}}}.sw.nf{{background:{}}}", hex(kNotComparedColor),
                     hex(kNonFiniteColor));
  return out;
}

// JSON has no NaN or Inf: those are the strings the page prints for them. Six
// significant digits are more than the page shows (four) and keep the data small.
nlohmann::json jnum(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return std::stod(fmt::format("{:.6g}", v));
}

// What pair k's section shows. `full`: every number (pairs that did not pass, and every
// pair of a small report); else only the images and their scales (null without images),
// the section then shows the row's numbers.
nlohmann::json sectionData(const PairResult& r, const fs::path& report_dir, bool full) {
  using nlohmann::json;
  json x = json::object();
  if (!r.images.empty()) {
    // One folder per pair: its URL once, the file names per kind.
    std::string dir;
    bool one_dir = true;
    for (const auto& [kind, file] : r.images) {
      const std::string d = relativeUrl(file.parent_path(), report_dir) + "/";
      if (dir.empty()) dir = d;
      one_dir = one_dir && d == dir;
    }
    json files = json::object();
    for (const auto& [kind, file] : r.images)
      files[kind] = one_dir ? urlPath(file.filename().string()) : relativeUrl(file, report_dir);
    x["img"] = one_dir ? dir : "";
    x["f"] = files;
  }
  if (r.status == Status::Error || r.status == Status::NotSupported) {
    x["d"] = describe(r);
    return x;
  }
  x["wh"] = {r.width, r.height};
  x["hs"] = {jnum(r.depth_heat_scale), jnum(r.shading_heat_scale)};
  if (!full) return r.images.empty() ? json() : x;
  const VisibilityStats& v = r.visibility;
  const DepthStats& d = r.depth;
  const ShadingStats& s = r.shading;
  const Tolerances& t = r.tolerances;
  if (r.status != Status::Pass) x["d"] = describe(r);
  x["cs"] = {toString(v.status), toString(d.status), toString(s.status)};
  x["v"] = {v.mismatched,
            v.ambiguous,
            v.hard,
            v.missing,
            v.missing_hard,
            v.extra,
            v.extra_hard,
            v.wrong_primitive,
            v.wrong_primitive_hard,
            v.ambiguous_by_depth_gap,
            jnum(v.band_px),
            v.uncertainty_available ? 1 : 0,
            v.worst.x,
            v.worst.y};
  x["z"] = {
      d.compared,  jnum(d.max_steps),   jnum(d.mean_steps),     jnum(d.p99_steps), d.over_tolerance,
      d.over_fail, d.nonfinite,         d.blend_uncertain,      jnum(d.band_px),   d.worst.x,
      d.worst.y,   jnum(d.worst_steps), jnum(d.worst_allowance)};
  x["s"] = {s.compared,
            jnum(s.max_abs),
            jnum(s.mean_abs),
            jnum(s.rmse),
            jnum(s.psnr_db),
            jnum(s.p99_abs),
            s.over_tolerance,
            s.over_fail,
            s.nonfinite,
            jnum(s.max_abs_rgba[0]),
            jnum(s.max_abs_rgba[1]),
            jnum(s.max_abs_rgba[2]),
            jnum(s.max_abs_rgba[3]),
            s.worst.x,
            s.worst.y,
            jnum(s.worst_abs),
            jnum(s.worst_allowance),
            s.texel_choice,
            s.blend_uncertain};
  x["t"] = {jnum(t.visibility.warn), jnum(t.visibility.fail),    jnum(t.depth.warn),
            jnum(t.depth.fail),      jnum(t.depth_slope_factor), jnum(t.shading.warn),
            jnum(t.shading.fail)};
  x["fmt"] = {toString(t.depth_format), toString(t.color_format)};
  x["a"] = shadingAllowanceText(t, d.band_px);
  if (r.flip) {
    const FlipStats& f = *r.flip;
    x["fl"] = {jnum(f.mean),        jnum(f.weighted_median),
               jnum(f.weighted_q1), jnum(f.weighted_q3),
               jnum(f.max),         jnum(f.ppd),
               toString(f.status),  f.threshold ? jnum(*f.threshold) : json(nullptr)};
  }
  if (r.ciede2000) {
    const DeltaE2000Stats& e = *r.ciede2000;
    x["de"] = {jnum(e.mean),        jnum(e.weighted_median),
               jnum(e.weighted_q1), jnum(e.weighted_q3),
               jnum(e.max),         e.differing,
               e.worst_x,           e.worst_y};
  }
  if (r.oit) {
    const OitStats& o = *r.oit;
    std::string pairs;
    for (std::size_t k = 0; k < o.out_of_order.size() && k < 8; ++k)
      pairs += fmt::format("{}{} over {} ({} px)", k ? ", " : "", o.out_of_order[k].far_id,
                           o.out_of_order[k].near_id, o.out_of_order[k].pixels);
    x["oi"] = {o.blended_pixels, o.unsorted_pixels, o.pixels,
               jnum(o.max_abs),  jnum(o.mean_abs),  pairs};
  }
  if (r.nonfinite_expected.total() + r.nonfinite_actual.total() > 0)
    x["nf"] = {r.nonfinite_expected.nan, r.nonfinite_expected.inf, r.nonfinite_actual.nan,
               r.nonfinite_actual.inf};
  return x;
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
      "<th>fail</th><th>error</th><th>not supported</th></tr>";
  for (std::size_t b = 0; b < columns.names.size(); ++b)
    out += fmt::format(
        "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>"
        "<td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
        esc(columns.names[b]), n[b][0], n[b][1], n[b][2], n[b][3], n[b][4]);
  return out + "</table>";
}

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
  const bool big = report.results.size() > kStaticPairs;
  const Columns columns = columnsOf(report);

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
                     esc(report.tool_name), kStyle, legendStyle());
  out += fmt::format("<h1>{} report</h1><div class=\"meta\">{} {}{}</div>", esc(report.tool_name),
                     esc(report.tool_name), esc(report.tool_version),
                     report.command.empty() ? "" : " &middot; " + esc(report.command));
  out += fmt::format(
      "<div class=\"summary\" id=\"summary\"><div>pairs<b>{}</b></div><div>pass<b>{}</b></div>"
      "<div>warn<b>{}</b></div><div>fail<b>{}</b></div><div>error<b>{}</b></div>"
      "<div>not supported<b>{}</b></div><div>exit code<b>{}</b></div></div>",
      sum.total(), sum.pass, sum.warn, sum.fail, sum.error, sum.not_supported, exitCodeFor(report));
  out += backendCounts(report, columns);
  // Large reports: the groups of failures come before the (shortened) matrix.
  if (!big) out += matrix(report, columns) + variantsTable(report);

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
  if (big) out += matrix(report, columns) + variantsTable(report);

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
    sections.push_back(sectionData(r, report_dir, !big || r.status != Status::Pass));
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
  out += fmt::format("<script>{}</script></body></html>\n", kScript);
  return out;
}

}  // namespace rc
