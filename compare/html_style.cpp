// report.html's style sheet, and the colours of its legends taken from the tables the pair
// images use (pair_images.h).
#include <string>

#include <fmt/format.h>

#include "compare/html_internal.h"
#include "compare/pair_images.h"
#include "compare/pixel_class.h"

namespace rc::detail {
namespace {

std::string hex(const Rgb8& c) { return fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]); }

}  // namespace

const char* const kStyle = R"CSS(
body{font:14px/1.4 system-ui,sans-serif;margin:0 24px 48px;color:#222;background:#fafafa}
h1{font-size:22px;margin:18px 0 4px}h2{font-size:18px;margin:28px 0 8px}
h3{font-size:15px;margin:0 0 6px}
.meta{color:#666;font-size:12px}
.summary{display:flex;gap:12px;margin:12px 0}
.summary div{padding:8px 14px;border-radius:6px;background:#fff;border:1px solid #ddd;min-width:70px}
.summary b{display:block;font-size:20px}
.badge{display:inline-block;padding:0 6px;border-radius:4px;font-size:12px;font-weight:600;
  text-transform:uppercase;color:#fff}
.pass{background:#2e7d32}.warn{background:#e6a100}.fail{background:#c62828}.error{background:#6a1b9a}.not_supported{background:#607d8b}.flake{background:#ad1457}
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

}  // namespace rc::detail
