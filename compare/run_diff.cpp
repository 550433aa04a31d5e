// See run_diff.h.
#include "compare/run_diff.h"

#include <algorithm>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "compare/report_text.h"

namespace rc {
namespace {

using Key = std::tuple<std::string, std::string, std::string>;

PairState stateOf(const PairResult& r) {
  PairState s;
  s.status = r.status;
  s.error = r.error;
  s.classes[0] = {r.visibility.status, r.visibility.hard};
  s.classes[1] = {r.depth.status, r.depth.over_tolerance};
  s.classes[2] = {r.shading.status, r.shading.over_tolerance};
  return s;
}

PairDiff::Kind kindOf(const PairState& a, const PairState& b) {
  if (static_cast<int>(b.status) > static_cast<int>(a.status)) return PairDiff::Kind::Regression;
  if (static_cast<int>(b.status) < static_cast<int>(a.status)) return PairDiff::Kind::Fix;
  for (std::size_t c = 0; c < a.classes.size(); ++c)
    if (a.classes[c].status != b.classes[c].status || a.classes[c].pixels != b.classes[c].pixels)
      return PairDiff::Kind::Changed;
  if (a.error != b.error) return PairDiff::Kind::Changed;
  return PairDiff::Kind::Unchanged;
}

std::string upper(Status s) {
  std::string t = toString(s);
  for (char& c : t) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return t;
}

// "visibility pass -> fail (hard px 0 -> 412)" for each class that moved.
std::string classChanges(const PairDiff& d, bool html) {
  std::vector<std::string> parts;
  if (!d.before || !d.after) return "";
  for (std::size_t c = 0; c < kDiffClasses.size(); ++c) {
    const ClassState& a = d.before->classes[c];
    const ClassState& b = d.after->classes[c];
    if (a.status == b.status && a.pixels == b.pixels) continue;
    const char* unit = c == 0 ? "hard px" : "px over";
    parts.push_back(a.status == b.status ? fmt::format("{} {} ({} {} -> {})", kDiffClasses[c],
                                                       toString(a.status), unit, a.pixels, b.pixels)
                                         : fmt::format("{} {} -> {} ({} {} -> {})", kDiffClasses[c],
                                                       toString(a.status), toString(b.status), unit,
                                                       a.pixels, b.pixels));
  }
  if (d.before->error != d.after->error && !d.after->error.empty())
    parts.push_back("error: " + d.after->error);
  std::string out = fmt::format("{}", fmt::join(parts, "; "));
  return html ? htmlEscape(out) : out;
}

std::string pairName(const PairDiff& d) {
  return fmt::format("{} {} vs {}", d.fixture, d.expected, d.actual);
}

std::string statusChange(const PairDiff& d) {
  if (!d.before) return fmt::format("(new) {}", upper(d.after->status));
  if (!d.after) return fmt::format("{} (vanished)", upper(d.before->status));
  return fmt::format("{} -> {}", upper(d.before->status), upper(d.after->status));
}

nlohmann::json stateJson(const std::optional<PairState>& s) {
  if (!s) return nullptr;
  nlohmann::json j = {{"status", toString(s->status)}};
  for (std::size_t c = 0; c < kDiffClasses.size(); ++c)
    j[kDiffClasses[c]] = {{"status", toString(s->classes[c].status)},
                          {"pixels", s->classes[c].pixels}};
  if (!s->error.empty()) j["error"] = s->error;
  return j;
}

constexpr PairDiff::Kind kListed[] = {PairDiff::Kind::Regression, PairDiff::Kind::Fix,
                                      PairDiff::Kind::New, PairDiff::Kind::Vanished,
                                      PairDiff::Kind::Changed};

const char* heading(PairDiff::Kind k) {
  switch (k) {
    case PairDiff::Kind::Regression:
      return "Regressions";
    case PairDiff::Kind::Fix:
      return "Fixes";
    case PairDiff::Kind::New:
      return "New pairs";
    case PairDiff::Kind::Vanished:
      return "Vanished pairs";
    case PairDiff::Kind::Changed:
      return "Changed (same verdict, pixels moved)";
    case PairDiff::Kind::Unchanged:
      return "Unchanged";
  }
  return "";
}

}  // namespace

const char* toString(PairDiff::Kind kind) {
  switch (kind) {
    case PairDiff::Kind::Regression:
      return "regression";
    case PairDiff::Kind::Fix:
      return "fix";
    case PairDiff::Kind::Changed:
      return "changed";
    case PairDiff::Kind::Unchanged:
      return "unchanged";
    case PairDiff::Kind::New:
      return "new";
    case PairDiff::Kind::Vanished:
      return "vanished";
  }
  return "";
}

std::size_t RunDiff::count(PairDiff::Kind kind) const {
  return static_cast<std::size_t>(
      std::count_if(pairs.begin(), pairs.end(), [&](const PairDiff& d) { return d.kind == kind; }));
}

RunDiff diffRuns(const Report& before, const Report& after, std::string old_name,
                 std::string new_name) {
  RunDiff out;
  out.old_name = std::move(old_name);
  out.new_name = std::move(new_name);
  std::map<Key, const PairResult*> later;
  for (const PairResult& r : after.results) later.emplace(Key{r.fixture, r.expected, r.actual}, &r);
  std::map<Key, bool> seen;
  for (const PairResult& r : before.results) {
    const Key key{r.fixture, r.expected, r.actual};
    if (!seen.emplace(key, true).second) continue;  // a repeated row counts once
    PairDiff d;
    d.fixture = r.fixture;
    d.expected = r.expected;
    d.actual = r.actual;
    d.before = stateOf(r);
    if (const auto it = later.find(key); it != later.end()) {
      d.after = stateOf(*it->second);
      d.kind = kindOf(*d.before, *d.after);
      for (std::size_t c = 0; c < kDiffClasses.size(); ++c) {
        const ClassState& a = d.before->classes[c];
        const ClassState& b = d.after->classes[c];
        ++out.transitions[c][static_cast<int>(a.status)][static_cast<int>(b.status)];
        out.pixels[c][0] += a.pixels;
        out.pixels[c][1] += b.pixels;
      }
    } else {
      d.kind = PairDiff::Kind::Vanished;
    }
    out.pairs.push_back(std::move(d));
  }
  for (const PairResult& r : after.results) {
    const Key key{r.fixture, r.expected, r.actual};
    if (!seen.emplace(key, true).second) continue;
    PairDiff d;
    d.fixture = r.fixture;
    d.expected = r.expected;
    d.actual = r.actual;
    d.after = stateOf(r);
    d.kind = PairDiff::Kind::New;
    out.pairs.push_back(std::move(d));
  }
  return out;
}

int exitCodeFor(const RunDiff& diff) { return diff.count(PairDiff::Kind::Regression) > 0 ? 1 : 0; }

std::string runDiffText(const RunDiff& diff) {
  std::string out = fmt::format("{} -> {}\n", diff.old_name, diff.new_name);
  out += fmt::format("{} regressions, {} fixes, {} changed, {} unchanged, {} new, {} vanished\n",
                     diff.count(PairDiff::Kind::Regression), diff.count(PairDiff::Kind::Fix),
                     diff.count(PairDiff::Kind::Changed), diff.count(PairDiff::Kind::Unchanged),
                     diff.count(PairDiff::Kind::New), diff.count(PairDiff::Kind::Vanished));
  for (const PairDiff::Kind kind : kListed) {
    if (diff.count(kind) == 0) continue;
    out += fmt::format("\n{}:\n", heading(kind));
    for (const PairDiff& d : diff.pairs) {
      if (d.kind != kind) continue;
      std::string line = fmt::format("  {}: {}", pairName(d), statusChange(d));
      const std::string classes = classChanges(d, false);
      if (!classes.empty()) line += "; " + classes;
      const std::optional<PairState>& s = d.after ? d.after : d.before;
      if (!d.before || !d.after)
        if (!s->error.empty()) line += ": " + s->error;
      out += line + '\n';
    }
  }
  out += "\nPer class, pairs in both runs (verdict transitions; pixels before -> after):\n";
  for (std::size_t c = 0; c < kDiffClasses.size(); ++c) {
    std::vector<std::string> moves;
    for (int a = 0; a < kStatusCount; ++a)
      for (int b = 0; b < kStatusCount; ++b)
        if (a != b && diff.transitions[c][a][b] > 0)
          moves.push_back(fmt::format("{} {} -> {}", diff.transitions[c][a][b],
                                      toString(static_cast<Status>(a)),
                                      toString(static_cast<Status>(b))));
    out +=
        fmt::format("  {}: {}; {} {} -> {}\n", kDiffClasses[c],
                    moves.empty() ? std::string("no verdict changed")
                                  : fmt::format("{}", fmt::join(moves, ", ")),
                    c == 0 ? "hard px" : "px over tolerance", diff.pixels[c][0], diff.pixels[c][1]);
  }
  out += diff.count(PairDiff::Kind::Regression) > 0 ? "REGRESSIONS\n" : "NO REGRESSIONS\n";
  return out;
}

nlohmann::json runDiffJson(const RunDiff& diff) {
  nlohmann::json counts = nlohmann::json::object();
  for (const PairDiff::Kind k :
       {PairDiff::Kind::Regression, PairDiff::Kind::Fix, PairDiff::Kind::Changed,
        PairDiff::Kind::Unchanged, PairDiff::Kind::New, PairDiff::Kind::Vanished})
    counts[toString(k)] = diff.count(k);
  nlohmann::json classes = nlohmann::json::object();
  for (std::size_t c = 0; c < kDiffClasses.size(); ++c) {
    nlohmann::json t = nlohmann::json::object();
    for (int a = 0; a < kStatusCount; ++a)
      for (int b = 0; b < kStatusCount; ++b)
        if (diff.transitions[c][a][b] > 0)
          t[fmt::format("{}->{}", toString(static_cast<Status>(a)),
                        toString(static_cast<Status>(b)))] = diff.transitions[c][a][b];
    classes[kDiffClasses[c]] = {{"transitions", t},
                                {"pixels_before", diff.pixels[c][0]},
                                {"pixels_after", diff.pixels[c][1]}};
  }
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairDiff& d : diff.pairs) {
    if (d.kind == PairDiff::Kind::Unchanged) continue;
    pairs.push_back({{"kind", toString(d.kind)},
                     {"fixture", d.fixture},
                     {"expected", d.expected},
                     {"actual", d.actual},
                     {"before", stateJson(d.before)},
                     {"after", stateJson(d.after)}});
  }
  return {{"format", "rastercheck-run-diff/1"},
          {"old", diff.old_name},
          {"new", diff.new_name},
          {"counts", counts},
          {"classes", classes},
          {"pairs", pairs},
          {"exit_code", exitCodeFor(diff)}};
}

std::string runDiffHtml(const RunDiff& diff) {
  constexpr const char* kStyle = R"CSS(
body{font:14px/1.4 system-ui,sans-serif;margin:0 24px 48px;color:#222;background:#fafafa}
h1{font-size:22px;margin:18px 0 4px}h2{font-size:18px;margin:24px 0 8px}
.meta{color:#666;font-size:12px}
.summary{display:flex;gap:12px;margin:12px 0}
.summary div{padding:8px 14px;border-radius:6px;background:#fff;border:1px solid #ddd}
.summary b{display:block;font-size:20px}
table{border-collapse:collapse;background:#fff}
th,td{border:1px solid #ddd;padding:3px 7px;text-align:left}
th{background:#f0f0f0}td.n{text-align:right;font-variant-numeric:tabular-nums}
.badge{display:inline-block;padding:0 6px;border-radius:4px;font-size:12px;font-weight:600;
  text-transform:uppercase;color:#fff}
.pass{background:#2e7d32}.warn{background:#e6a100}.fail{background:#c62828}.error{background:#6a1b9a}
.regression td:first-child{border-left:4px solid #c62828}.fix td:first-child{border-left:4px solid #2e7d32}
.controls{margin:8px 0}.controls input{width:320px;padding:4px}.hidden{display:none}
)CSS";
  constexpr const char* kScript = R"JS(
(function () {
  var filter = document.getElementById('filter');
  filter.addEventListener('input', function () {
    var text = filter.value.toLowerCase();
    var rows = document.querySelectorAll('tr[data-text]');
    for (var i = 0; i < rows.length; i++)
      rows[i].classList.toggle('hidden', text && rows[i].getAttribute('data-text').indexOf(text) < 0);
  });
  document.body.setAttribute('data-ready', '1');
})();
)JS";
  auto badge = [](Status s) {
    return fmt::format("<span class=\"badge {0}\">{0}</span>", toString(s));
  };
  std::string out = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">";
  out += fmt::format("<title>rastercheck diff-runs</title><style>{}</style></head><body>", kStyle);
  out += fmt::format("<h1>rastercheck diff-runs</h1><div class=\"meta\">{} &rarr; {}</div>",
                     htmlEscape(diff.old_name), htmlEscape(diff.new_name));
  out += "<div class=\"summary\">";
  for (const PairDiff::Kind k :
       {PairDiff::Kind::Regression, PairDiff::Kind::Fix, PairDiff::Kind::Changed,
        PairDiff::Kind::Unchanged, PairDiff::Kind::New, PairDiff::Kind::Vanished})
    out += fmt::format("<div>{}<b id=\"count-{}\">{}</b></div>", heading(k), toString(k),
                       diff.count(k));
  out += "</div>";

  out +=
      "<h2>Per class</h2><table><tr><th>class</th><th>verdict transitions (pairs in both "
      "runs)</th><th>pixels before</th><th>pixels after</th></tr>";
  for (std::size_t c = 0; c < kDiffClasses.size(); ++c) {
    std::vector<std::string> moves;
    for (int a = 0; a < kStatusCount; ++a)
      for (int b = 0; b < kStatusCount; ++b)
        if (a != b && diff.transitions[c][a][b] > 0)
          moves.push_back(fmt::format("{} {} &rarr; {}", diff.transitions[c][a][b],
                                      badge(static_cast<Status>(a)),
                                      badge(static_cast<Status>(b))));
    out +=
        fmt::format("<tr><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
                    kDiffClasses[c],
                    moves.empty() ? std::string("none") : fmt::format("{}", fmt::join(moves, ", ")),
                    diff.pixels[c][0], diff.pixels[c][1]);
  }
  out += "</table>";

  out +=
      "<div class=\"controls\"><input id=\"filter\" type=\"search\" placeholder=\"filter: "
      "fixture, backend...\"></div>";
  for (const PairDiff::Kind kind : kListed) {
    if (diff.count(kind) == 0) continue;
    out +=
        fmt::format("<h2 id=\"{}\">{} ({})</h2>", toString(kind), heading(kind), diff.count(kind));
    out +=
        "<table><tr><th>fixture</th><th>expected</th><th>actual</th><th>before</th>"
        "<th>after</th><th>what moved</th></tr>";
    for (const PairDiff& d : diff.pairs) {
      if (d.kind != kind) continue;
      std::string text = d.fixture + " " + d.expected + " " + d.actual;
      std::transform(text.begin(), text.end(), text.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      const std::optional<PairState>& s = d.after ? d.after : d.before;
      std::string moved = classChanges(d, true);
      if ((!d.before || !d.after) && !s->error.empty()) moved = htmlEscape(s->error);
      out += fmt::format(
          "<tr class=\"{}\" data-text=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
          "<td>{}</td><td>{}</td></tr>",
          toString(kind), htmlEscape(text), htmlEscape(d.fixture), htmlEscape(d.expected),
          htmlEscape(d.actual), d.before ? badge(d.before->status) : "&mdash;",
          d.after ? badge(d.after->status) : "&mdash;", moved);
    }
    out += "</table>";
  }
  out += fmt::format("<script>{}</script></body></html>\n", kScript);
  return out;
}

}  // namespace rc
