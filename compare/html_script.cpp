// report.html's script: builds the pairs table's rows and each pair's section from the
// data the page carries, filters and sorts them, and loads a pair's images when it opens.
#include "compare/html_internal.h"

namespace rc::detail {

const char* const kScript = R"JS(
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

}  // namespace rc::detail
