// The accuracy report: see accuracy.h.
#include "compare/accuracy.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "compare/report_read.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// --- reading -------------------------------------------------------------------------

// The "tags" of a fixture file, or nullopt when it cannot be read.
std::optional<std::vector<std::string>> fixtureTags(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  const json doc = json::parse(in, nullptr, false);
  if (!doc.is_object()) return std::nullopt;
  std::vector<std::string> tags;
  if (doc.contains("tags") && doc["tags"].is_array())
    for (const json& t : doc["tags"])
      if (t.is_string()) tags.push_back(t.get<std::string>());
  return tags;
}

// fixture name -> fixture file, from the frame.json files of a run folder.
void collectFixtureFiles(const fs::path& run, std::map<std::string, fs::path>& out) {
  std::error_code ec;
  const fs::path frames = run / "frames";
  if (!fs::is_directory(frames, ec)) return;
  for (const auto& entry : fs::recursive_directory_iterator(frames, ec)) {
    if (!entry.is_regular_file() || entry.path().filename() != "frame.json") continue;
    std::ifstream in(entry.path());
    const json meta = json::parse(in, nullptr, false);
    if (meta.is_object() && meta.contains("fixture") && meta["fixture"].is_string() &&
        meta.contains("fixture_file") && meta["fixture_file"].is_string())
      out.emplace(meta["fixture"].get<std::string>(), meta["fixture_file"].get<std::string>());
  }
}

AccuracyPair readPair(const ReportReader& r, const json& j, const std::string& at) {
  AccuracyPair p;
  p.fixture = r.text(j, "fixture", at);
  p.expected = r.text(j, "expected", at);
  p.actual = r.text(j, "actual", at);
  p.status = r.status(j, "status", at);
  if (j.contains("error") && j["error"].is_string()) p.error = j["error"].get<std::string>();
  if (j.contains("not_supported") && j["not_supported"].is_string())
    p.error = j["not_supported"].get<std::string>();
  p.height = static_cast<int>(r.number(j, "height", at));
  p.pixels = r.count(j, "pixels", at);
  if (j.contains("subpixel_bits") && j["subpixel_bits"].is_object()) {
    p.expected_subpixel_bits = static_cast<int>(r.number(j["subpixel_bits"], "expected", at));
    p.actual_subpixel_bits = static_cast<int>(r.number(j["subpixel_bits"], "actual", at));
  }
  static const json kEmpty = json::object();
  const json& v = j.contains("visibility") ? j["visibility"] : kEmpty;
  const std::string vat = at + ".visibility";
  p.visibility_status = r.status(v, "status", vat);
  p.mismatched = r.count(v, "mismatched", vat);
  p.ambiguous = r.count(v, "ambiguous", vat);
  p.hard = r.count(v, "hard", vat);
  p.ambiguous_by_depth_gap = r.count(v, "ambiguous_by_depth_gap", vat);
  p.visibility_worst = r.pixel(v, "worst", vat);
  const json& d = j.contains("depth") ? j["depth"] : kEmpty;
  const std::string dat = at + ".depth";
  p.depth_status = r.status(d, "status", dat);
  p.depth_compared = r.count(d, "compared", dat);
  p.depth_max = r.number(d, "max_steps", dat);
  p.depth_mean = r.number(d, "mean_steps", dat);
  p.depth_p99 = r.number(d, "p99_steps", dat);
  p.depth_over = r.count(d, "over_tolerance", dat);
  p.depth_worst = r.pixel(d, "worst", dat);
  const json& s = j.contains("shading") ? j["shading"] : kEmpty;
  const std::string sat = at + ".shading";
  p.shading_status = r.status(s, "status", sat);
  p.shading_compared = r.count(s, "compared", sat);
  p.shading_max = r.number(s, "max_abs", sat);
  p.shading_mean = r.number(s, "mean_abs", sat);
  p.shading_rmse = r.number(s, "rmse", sat);
  p.psnr_db = r.optionalNumber(s, "psnr_db", sat);
  p.shading_over = r.count(s, "over_tolerance", sat);
  p.shading_worst = r.pixel(s, "worst", sat);
  if (j.contains("flip") && j["flip"].is_object()) {
    p.flip_mean = r.number(j["flip"], "mean", at + ".flip");
    p.flip_max = r.number(j["flip"], "max", at + ".flip");
  }
  if (j.contains("ciede2000") && j["ciede2000"].is_object()) {
    p.ciede2000_mean = r.number(j["ciede2000"], "mean", at + ".ciede2000");
    p.ciede2000_max = r.number(j["ciede2000"], "max", at + ".ciede2000");
  }
  if (j.contains("oit") && j["oit"].is_object()) {
    const json& o = j["oit"];
    const std::string oat = at + ".oit";
    p.oit = true;
    p.oit_blended = r.count(o, "blended_pixels", oat);
    p.oit_unsorted = r.count(o, "unsorted_pixels", oat);
    p.oit_pixels = r.count(o, "pixels", oat);
    p.oit_max_abs = r.optionalNumber(o, "max_abs", oat).value_or(0.0);
    p.oit_mean_abs = r.optionalNumber(o, "mean_abs", oat).value_or(0.0);
    p.oit_pairs = r.count(o, "out_of_order_pairs", oat);
  }
  return p;
}

// --- writing -------------------------------------------------------------------------

// Short numbers for tables: 3 significant digits, no exponent below 1e6.
std::string shortNumber(double v) {
  if (v == 0.0) return "0";
  if (std::abs(v) >= 1000.0) return fmt::format("{:.0f}", v);
  return fmt::format("{:.3g}", v);
}

std::string at(const std::optional<PixelRef>& p, int height) {
  if (!p || !p->valid()) return "";
  return fmt::format(" at ({},{}) [window {},{}]", p->x, p->y, p->x, height - 1 - p->y);
}

std::string cell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

bool isReference(const std::string& spec) { return spec == "ref" || spec.rfind("ref:", 0) == 0; }

struct Totals {
  std::uint64_t pairs = 0;
  std::array<std::uint64_t, kStatusCount> by_status{};  // indexed by Status
  std::uint64_t hard = 0;
  std::uint64_t ambiguous = 0;
  double depth_max = 0.0;
  double depth_p99 = 0.0;
  double shading_max = 0.0;
  double shading_sum = 0.0;  // mean_abs x compared, for a pixel-weighted mean
  std::uint64_t shading_compared = 0;
  std::optional<double> psnr_min;

  void add(const AccuracyPair& p) {
    ++pairs;
    ++by_status[static_cast<int>(p.status)];
    hard += p.hard;
    ambiguous += p.ambiguous;
    depth_max = std::max(depth_max, p.depth_max);
    depth_p99 = std::max(depth_p99, p.depth_p99);
    shading_max = std::max(shading_max, p.shading_max);
    shading_sum += p.shading_mean * static_cast<double>(p.shading_compared);
    shading_compared += p.shading_compared;
    if (p.psnr_db) psnr_min = std::min(psnr_min.value_or(*p.psnr_db), *p.psnr_db);
  }
  double shadingMean() const {
    return shading_compared ? shading_sum / static_cast<double>(shading_compared) : 0.0;
  }
  std::string verdicts() const {
    return fmt::format("{} | {} | {} | {}", by_status[0], by_status[1], by_status[2], by_status[3]);
  }
};

using Group = std::pair<std::string, std::string>;  // expected, actual

// "warn: shading 1.25 at (..)" for a cell of the per-fixture table.
std::string verdictCell(const AccuracyPair& p) {
  if (p.status == Status::Error) return "error: " + cell(p.error);
  if (p.status == Status::NotSupported) return "not supported: " + cell(p.error);
  if (p.status == Status::Flake) return "flake: renders differ between attempts";
  if (p.status == Status::Pass) return "pass";
  std::vector<std::string> parts;
  if (p.visibility_status != Status::Pass)
    parts.push_back(
        fmt::format("visibility {} hard px{}", p.hard, at(p.visibility_worst, p.height)));
  if (p.depth_status != Status::Pass)
    parts.push_back(
        fmt::format("depth {} steps{}", shortNumber(p.depth_max), at(p.depth_worst, p.height)));
  if (p.shading_status != Status::Pass)
    parts.push_back(
        fmt::format("shading {}{}", shortNumber(p.shading_max), at(p.shading_worst, p.height)));
  std::string out = toString(p.status);
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? "; " : ": ") + parts[i];
  return out;
}

// The kinds of difference between two drivers, one sentence each, from the numbers.
std::vector<std::string> differenceSummary(const std::vector<const AccuracyPair*>& list) {
  std::vector<std::string> out;
  std::uint64_t edge_px = 0, edge_fx = 0, tie_px = 0, tie_fx = 0, hard_px = 0, hard_fx = 0;
  std::uint64_t depth_fx = 0, shading_fx = 0;
  const AccuracyPair* depth_worst = nullptr;
  const AccuracyPair* shading_worst = nullptr;
  for (const AccuracyPair* p : list) {
    const std::uint64_t edge = p->ambiguous - std::min(p->ambiguous, p->ambiguous_by_depth_gap);
    edge_px += edge;
    edge_fx += edge > 0;
    tie_px += p->ambiguous_by_depth_gap;
    tie_fx += p->ambiguous_by_depth_gap > 0;
    hard_px += p->hard;
    hard_fx += p->hard > 0;
    depth_fx += p->depth_max > 0.0;
    shading_fx += p->shading_max > 0.0;
    if (!depth_worst || p->depth_max > depth_worst->depth_max) depth_worst = p;
    if (!shading_worst || p->shading_max > shading_worst->shading_max) shading_worst = p;
  }
  out.push_back(
      fmt::format("Coverage at edges: {} pixels in {} fixtures, all inside the snap "
                  "band of the two drivers' subpixel precisions (ambiguous).",
                  edge_px, edge_fx));
  out.push_back(
      fmt::format("Depth ties: {} pixels in {} fixtures where two surfaces lie within "
                  "the depth tolerance of each other (z-fighting; ambiguous).",
                  tie_px, tie_fx));
  out.push_back(hard_px == 0 ? std::string("Hard visibility differences: none.")
                             : fmt::format("Hard visibility differences: {} pixels in {} fixtures.",
                                           hard_px, hard_fx));
  if (depth_worst && depth_worst->depth_max > 0.0)
    out.push_back(
        fmt::format("Stored depth differs in {} fixtures, by up to {} steps "
                    "(`{}`{}).",
                    depth_fx, shortNumber(depth_worst->depth_max), depth_worst->fixture,
                    at(depth_worst->depth_worst, depth_worst->height)));
  if (shading_worst && shading_worst->shading_max > 0.0)
    out.push_back(fmt::format("Colour differs in {} fixtures, by up to {} 8-bit units (`{}`{}).",
                              shading_fx, shortNumber(shading_worst->shading_max),
                              shading_worst->fixture,
                              at(shading_worst->shading_worst, shading_worst->height)));
  return out;
}

// A report.json variant summary or value as one table cell.
std::string variantText(const json& v, const char* key) {
  if (!v.contains(key)) return "-";
  const json& x = v[key];
  if (x.is_object() && x.contains("summary") && x["summary"].is_string())
    return cell(x["summary"].get<std::string>());
  if (x.is_null()) return "-";
  return cell(x.is_string() ? x.get<std::string>() : x.dump());
}

// A probed rule and whether it is the reference's: "left+bottom (as ref)".
std::string variantRule(const json& v, const char* key) {
  if (!v.contains(key) || !v[key].is_object()) return "-";
  const json& x = v[key];
  return fmt::format("{}{}", cell(x.value("rule", std::string("-"))),
                     x.value("matches_reference", false) ? " (as ref)" : " (differs from ref)");
}

// "Driver stacks and variants": what each GL backend ran on, the legal variants the probes
// found, and the findings (a driver's answer contradicted by what it does).
template <typename Line>
void variantsSection(const AccuracyData& data, const Line& line) {
  if (data.variants.empty()) return;
  line();
  line("## Driver stacks and variants");
  line();
  line("Probed once per backend and run (docs/debugging.md, \"Variant detection\").");
  line("*GL_SUBPIXEL_BITS* is the driver's answer; *rasterizes like* is what the subpixel");
  line("probe measured; *snap band* is the precision the backend's frames carry, which the");
  line("comparator's visibility band uses (docs/gl_backend.md: zink's comes from its Vulkan");
  line("device).");
  line();
  line(
      "| backend | stack | GL_SUBPIXEL_BITS | rasterizes like | snap band | tie-break | depth "
      "rounding | lines and points |");
  line("|---|---|---|---|---|---|---|---|");
  std::vector<std::string> findings;
  for (const auto& [spec, v] : data.variants) {
    if (!v.is_object()) continue;
    if (v.contains("error")) {
      line(fmt::format("| `{}` | error: {} | | | | | | |", spec, variantText(v, "error")));
      continue;
    }
    std::string observed = "-";
    if (v.contains("subpixel") && v["subpixel"].is_object()) {
      const json& sub = v["subpixel"];
      if (sub.value("exact", false) && sub.contains("best") && sub["best"].is_number())
        observed = fmt::format("{} bits", sub["best"].get<int>());
      else if (sub.contains("best") && sub["best"].is_number())
        observed = fmt::format("no fixed grid (closest {})", sub["best"].get<int>());
    }
    const std::string band = v.contains("band_subpixel_bits") ? variantText(v, "band_subpixel_bits")
                                                              : variantText(v, "subpixel_bits");
    line(fmt::format("| `{}` | {} | {} | {} | {} | {} | {} | {} |", spec,
                     v.contains("stack") ? variantText(v, "stack") : variantText(v, "renderer"),
                     variantText(v, "subpixel_bits"), observed, band, variantRule(v, "tie_break"),
                     variantRule(v, "depth_rounding"), variantRule(v, "lines")));
    if (v.contains("findings") && v["findings"].is_array())
      for (const json& f : v["findings"])
        if (f.is_string()) findings.push_back(fmt::format("`{}`: {}", spec, f.get<std::string>()));
  }
  line();
  if (findings.empty()) {
    line("Findings: none (every driver rasterizes as it says).");
    return;
  }
  line("Findings (not failures: every comparison used what the driver really does):");
  line();
  for (const std::string& f : findings) line("- " + f);
}

}  // namespace

AccuracyData readAccuracyRuns(const std::vector<fs::path>& runs,
                              const std::vector<fs::path>& catalogs) {
  AccuracyData data;
  std::map<std::string, fs::path> files;
  std::map<std::string, std::vector<std::string>> row_tags;  // rows that carry their tags
  std::map<std::tuple<std::string, std::string, std::string>, AccuracyPair> pairs;
  for (const fs::path& run : runs) {
    data.sources.push_back(run.string());
    const fs::path file = run / "report.json";
    const json doc = readJsonFile(file);
    const ReportReader r(file);
    const json& results = r.member(doc, "results", "");
    if (!results.is_array()) r.fail("results", "must be an array");
    for (std::size_t i = 0; i < results.size(); ++i) {
      AccuracyPair p = readPair(r, results[i], fmt::format("results[{}]", i));
      // Rows name their fixture's file and tags since runs keep frames of failing pairs only.
      const json& row = results[i];
      if (row.contains("tags") && row["tags"].is_array()) {
        std::vector<std::string>& t = row_tags[p.fixture];
        t.clear();
        for (const json& tag : row["tags"])
          if (tag.is_string()) t.push_back(tag.get<std::string>());
      }
      if (row.contains("fixture_file") && row["fixture_file"].is_string())
        files.emplace(p.fixture, row["fixture_file"].get<std::string>());
      pairs[{p.expected, p.actual, p.fixture}] = std::move(p);
    }
    if (doc.contains("variants")) {
      const json& variants = doc["variants"];
      if (!variants.is_object()) r.fail("variants", "must be an object");
      for (const auto& [spec, v] : variants.items()) data.variants[spec] = v;
    }
    collectFixtureFiles(run, files);
  }
  std::map<std::string, fs::path> catalog;
  if (!catalogs.empty()) {
    for (const fs::path& f : findFixtures(catalogs)) {
      std::ifstream in(f);
      const json doc = json::parse(in, nullptr, false);
      if (doc.is_object() && doc.contains("name") && doc["name"].is_string())
        catalog.emplace(doc["name"].get<std::string>(), f);
    }
  }
  std::map<std::string, std::vector<std::string>> tags;
  for (auto& [key, p] : pairs) {
    auto it = tags.find(p.fixture);
    if (it == tags.end()) {
      std::optional<std::vector<std::string>> found;
      if (auto t = row_tags.find(p.fixture); t != row_tags.end()) found = t->second;
      if (!found)
        if (auto f = files.find(p.fixture); f != files.end()) found = fixtureTags(f->second);
      if (!found)
        if (auto c = catalog.find(p.fixture); c != catalog.end()) found = fixtureTags(c->second);
      it = tags.emplace(p.fixture, found.value_or(std::vector<std::string>{})).first;
    }
    p.tags = it->second;
    data.pairs.push_back(std::move(p));
  }
  return data;
}

// One perceptual measure per driver pair: the pairs' means averaged, the worst pair mean,
// the largest pixel. `mean` and `max` read the measure of a pair (no mean: not measured).
template <class Line, class Mean, class Max>
void perceptualTable(const std::map<Group, std::vector<const AccuracyPair*>>& groups, Mean mean,
                     Max max_of, Line& line) {
  line("| driver | against | pairs | mean | worst pair | largest pixel |");
  line("|---|---|---|---|---|---|");
  for (const auto& [g, list] : groups) {
    std::size_t n = 0;
    double sum = 0.0, worst = 0.0, max = 0.0;
    std::string worst_fixture;
    for (const AccuracyPair* p : list) {
      const std::optional<double> m = mean(*p);
      if (!m) continue;
      ++n;
      sum += *m;
      max = std::max(max, max_of(*p));
      if (*m > worst || worst_fixture.empty()) {
        worst = *m;
        worst_fixture = p->fixture;
      }
    }
    if (n == 0) continue;
    line(fmt::format("| `{}` | `{}` | {} | {} | {} (`{}`) | {} |", g.second, g.first, n,
                     shortNumber(sum / static_cast<double>(n)), shortNumber(worst), worst_fixture,
                     shortNumber(max)));
  }
}

// LDR-FLIP (report.json "flip", runs with --flip) and CIEDE2000 ("ciede2000") per driver
// pair: how large the differences look.
template <class Line>
void perceptualSection(const AccuracyData& data,
                       const std::map<Group, std::vector<const AccuracyPair*>>& groups,
                       Line& line) {
  const bool flip = std::any_of(data.pairs.begin(), data.pairs.end(),
                                [](const AccuracyPair& p) { return p.flip_mean.has_value(); });
  const bool de = std::any_of(data.pairs.begin(), data.pairs.end(),
                              [](const AccuracyPair& p) { return p.ciede2000_mean.has_value(); });
  if (flip) {
    line();
    line("## Perceptual error (LDR-FLIP)");
    line();
    line("LDR-FLIP (docs/tolerances.md, section 6) of each pair's 8-bit pictures, 0 (identical)");
    line("to 1; *mean* averages the pairs' mean errors, *worst pair* is the largest pair mean.");
    line();
    perceptualTable(
        groups, [](const AccuracyPair& p) { return p.flip_mean; },
        [](const AccuracyPair& p) { return p.flip_max; }, line);
  }
  if (de) {
    line();
    line("## Colour difference (CIEDE2000)");
    line();
    line("CIEDE2000 (docs/tolerances.md, section 7) of each pair's 8-bit pictures, per pixel;");
    line("*mean* averages the pairs' means over all their pixels, *worst pair* is the largest");
    line("pair mean.");
    line();
    perceptualTable(
        groups, [](const AccuracyPair& p) { return p.ciede2000_mean; },
        [](const AccuracyPair& p) { return p.ciede2000_max; }, line);
  }
}

// Against ref:abuffer (report.json "oit"): how far each pair's sorted alpha pass is from
// exact transparency.
template <class Line>
void transparencySection(const AccuracyData& data, Line& line) {
  std::vector<const AccuracyPair*> rows;
  for (const AccuracyPair& p : data.pairs)
    if (p.oit) rows.push_back(&p);
  if (rows.empty()) return;
  line();
  line("## Exact transparency (against `ref:abuffer`)");
  line();
  line("How far each backend's sorted-triangle alpha pass is from the A-buffer's exact");
  line("answer (docs/reports.md, `oit`): *unsorted* pixels are where the draw order is not the");
  line("depth order (a property of the scene); *over warn* counts pixels whose colour differs by");
  line("more than the shading warn threshold; errors in 8-bit units.");
  line();
  line(
      "| fixture | backend | blended px | unsorted px | over warn | max abs | mean abs | "
      "out-of-order triangle pairs |");
  line("|---|---|---|---|---|---|---|---|");
  for (const AccuracyPair* p : rows)
    line(fmt::format("| `{}` | `{}` | {} | {} | {} | {} | {} | {} |", p->fixture, p->actual,
                     p->oit_blended, p->oit_unsorted, p->oit_pixels, shortNumber(p->oit_max_abs),
                     shortNumber(p->oit_mean_abs), p->oit_pairs));
}

std::string accuracyMarkdown(const AccuracyData& data, const std::string& command) {
  std::string md;
  auto line = [&md](const std::string& s = "") { md += s + "\n"; };

  std::map<Group, std::vector<const AccuracyPair*>> groups;
  for (const AccuracyPair& p : data.pairs) groups[{p.expected, p.actual}].push_back(&p);
  std::vector<Group> against_ref, between_drivers;
  for (const auto& [g, list] : groups) {
    // Against ref:abuffer (exact transparency, pairs with an oit block): a measurement of
    // the sorted alpha pass, not of conformance; only its own section shows it.
    if (std::all_of(list.begin(), list.end(), [](const AccuracyPair* p) { return p->oit; }))
      continue;
    (isReference(g.first) ? against_ref : between_drivers).push_back(g);
  }

  line("# Accuracy of the OpenGL drivers");
  line();
  line(fmt::format("Generated by {}; do not edit by hand.", command));
  line(fmt::format("Sources: {} comparisons from {} run folder(s).", data.pairs.size(),
                   data.sources.size()));
  line();
  line("Units: visibility in pixels (*hard*: outside the snap band and not a depth tie, so");
  line("an error; *ambiguous*: either answer is legal); depth in steps of the fixture's depth");
  line("format; shading as the largest channel error in 8-bit units (x255), mean weighted by");
  line("compared pixels. Pixels are image coordinates (origin top-left, y down), GL window");
  line("coordinates in brackets. Thresholds and their derivation: docs/tolerances.md.");

  if (!against_ref.empty()) {
    line();
    line("## Drivers against the reference");
    line();
    line(
        "| driver | against | pairs | pass | warn | fail | error | hard px | ambiguous px | "
        "depth max | depth p99 (worst pair) | shading max | shading mean | lowest PSNR dB |");
    line("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (const Group& g : against_ref) {
      Totals t;
      for (const AccuracyPair* p : groups[g]) t.add(*p);
      line(fmt::format("| `{}` | `{}` | {} | {} | {} | {} | {} | {} | {} | {} | {} |", g.second,
                       g.first, t.pairs, t.verdicts(), t.hard, t.ambiguous,
                       shortNumber(t.depth_max), shortNumber(t.depth_p99),
                       shortNumber(t.shading_max), shortNumber(t.shadingMean()),
                       t.psnr_min ? shortNumber(*t.psnr_min) : "identical"));
    }

    variantsSection(data, line);
    perceptualSection(data, groups, line);
    transparencySection(data, line);

    line();
    line("## Per topic");
    line();
    line("A fixture counts under each of its tags.");
    for (const Group& g : against_ref) {
      std::map<std::string, Totals> per_tag;
      for (const AccuracyPair* p : groups[g]) {
        if (p->tags.empty()) per_tag["(untagged)"].add(*p);
        for (const std::string& t : p->tags) per_tag[t].add(*p);
      }
      line();
      line(fmt::format("### `{}` against `{}`", g.second, g.first));
      line();
      line(
          "| tag | fixtures | pass | warn | fail | error | hard px | ambiguous px | depth max | "
          "shading max | shading mean |");
      line("|---|---|---|---|---|---|---|---|---|---|---|");
      for (const auto& [tag, t] : per_tag)
        line(fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |", cell(tag), t.pairs,
                         t.verdicts(), t.hard, t.ambiguous, shortNumber(t.depth_max),
                         shortNumber(t.shading_max), shortNumber(t.shadingMean())));
    }

    line();
    line("## Per fixture");
    line();
    std::string head = "| fixture |", rule = "|---|";
    for (const Group& g : against_ref) {
      head += fmt::format(" `{}` |", g.second);
      rule += "---|";
    }
    line(head);
    line(rule);
    std::set<std::string> fixtures;
    for (const Group& g : against_ref)
      for (const AccuracyPair* p : groups[g]) fixtures.insert(p->fixture);
    for (const std::string& f : fixtures) {
      std::string row = fmt::format("| `{}` |", f);
      for (const Group& g : against_ref) {
        const auto& list = groups[g];
        auto it = std::find_if(list.begin(), list.end(),
                               [&](const AccuracyPair* p) { return p->fixture == f; });
        row += fmt::format(" {} |", it == list.end() ? std::string("-") : verdictCell(**it));
      }
      line(row);
    }
  }

  if (against_ref.empty()) variantsSection(data, line);

  for (const Group& g : between_drivers) {
    const auto& list = groups[g];
    line();
    line(fmt::format("## `{}` against `{}`", g.second, g.first));
    line();
    std::set<std::pair<int, int>> bits;
    std::uint64_t identical = 0, edge_only = 0;
    Totals t;
    for (const AccuracyPair* p : list) {
      t.add(*p);
      bits.insert({p->expected_subpixel_bits, p->actual_subpixel_bits});
      const bool same_pixels = p->mismatched == 0;
      const bool same_values = p->depth_max == 0.0 && p->shading_max == 0.0;
      if (same_pixels && same_values) ++identical;
      if (!same_pixels && p->hard == 0 && same_values) ++edge_only;
    }
    line(
        fmt::format("{} fixtures: {} identical, {} differing only in ambiguous pixels, {} "
                    "with other differences. Verdicts: {} pass, {} warn, {} fail, {} error{}.",
                    t.pairs, identical, edge_only, t.pairs - identical - edge_only, t.by_status[0],
                    t.by_status[1], t.by_status[2], t.by_status[3],
                    (t.by_status[4] ? fmt::format(", {} not supported", t.by_status[4]) : "") +
                        (t.by_status[5] ? fmt::format(", {} flake", t.by_status[5]) : "")));
    for (const auto& [a, b] : bits)
      if (a > 0 && b > 0)
        line(fmt::format("Subpixel bits: `{}` {}, `{}` {}.", g.first, a, g.second, b));
    line(
        fmt::format("Visibility: {} hard and {} ambiguous pixels in all; depth up to {} "
                    "steps; shading up to {} (mean {}).",
                    t.hard, t.ambiguous, shortNumber(t.depth_max), shortNumber(t.shading_max),
                    shortNumber(t.shadingMean())));
    line();
    line("What differs:");
    line();
    for (const std::string& item : differenceSummary(list)) line("- " + item);
    line();
    line(
        "Where they differ, and the pixel to look at first (the worst of each class; ambiguous "
        "visibility pixels have no worst pixel: the pair's visibility.png shows them):");
    line();
    line(
        "| fixture | verdict | visibility: hard / ambiguous px (by depth tie) | depth: max, "
        "p99 steps | shading: max, mean |");
    line("|---|---|---|---|---|");
    for (const AccuracyPair* p : list) {
      if (p->mismatched == 0 && p->depth_max == 0.0 && p->shading_max == 0.0) continue;
      line(fmt::format("| `{}` | {} | {} / {} ({}){} | {}, {}{} | {}, {}{} |", p->fixture,
                       toString(p->status), p->hard, p->ambiguous, p->ambiguous_by_depth_gap,
                       at(p->visibility_worst, p->height), shortNumber(p->depth_max),
                       shortNumber(p->depth_p99), at(p->depth_worst, p->height),
                       shortNumber(p->shading_max), shortNumber(p->shading_mean),
                       at(p->shading_worst, p->height)));
    }
    line();
    line(
        fmt::format("To look at one: `rastercheck run fixtures/scenes/FIXTURE.json --backends "
                    "{} --against {} --out /tmp/x`, then open `/tmp/x/report.html` (or "
                    "`rastercheck compare` the two frame folders).",
                    g.second, g.first));
  }

  line();
  line("## Known differences (fixtures/expectations.json)");
  line();
  if (data.known.entries.empty()) {
    line("None: fixtures/expectations.json lists no expected failure.");
  } else {
    line("| id | fixture | backend | driver version | state, tags | class | reason |");
    line("|---|---|---|---|---|---|---|");
    for (const Expectation& k : data.known.entries) {
      std::string state;
      for (const auto& [key, value] : k.state)
        state += fmt::format("{}{} {}", state.empty() ? "" : ", ", key, value);
      for (const std::string& tag : k.tags)
        state += fmt::format("{}tag {}", state.empty() ? "" : ", ", tag);
      line(fmt::format("| {} | `{}` | `{}` | {} | {} | {} | {} |", k.id, k.fixture, k.backend,
                       k.driver_version.empty() ? "any" : "`" + k.driver_version + "`",
                       state.empty() ? "any" : state, k.cls, cell(k.reason)));
    }
  }
  return md;
}

}  // namespace rc
