// See report_read.h. Field by field the mirror of report.cpp's toJson.
#include "compare/report_read.h"

#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

json readJsonFile(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot be read", file.string()));
  json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) throw InputError(fmt::format("{}: not valid JSON", file.string()));
  return doc;
}

void ReportReader::fail(const std::string& path, const std::string& what) const {
  throw InputError(fmt::format("{}: {}: {}", file_.string(), path, what));
}

const json& ReportReader::member(const json& j, const char* key, const std::string& path) const {
  if (!j.is_object() || !j.contains(key)) fail(path + "." + key, "missing");
  return j[key];
}

std::string ReportReader::text(const json& j, const char* key, const std::string& path) const {
  const json& v = member(j, key, path);
  if (!v.is_string()) fail(path + "." + key, "must be a string");
  return v.get<std::string>();
}

double ReportReader::number(const json& j, const char* key, const std::string& path) const {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return 0.0;
  if (!j[key].is_number()) fail(path + "." + key, "must be a number");
  return j[key].get<double>();
}

std::uint64_t ReportReader::count(const json& j, const char* key, const std::string& path) const {
  const double v = number(j, key, path);
  if (v < 0) fail(path + "." + key, "must not be negative");
  // Exact above 2^53 too.
  if (j.contains(key) && j[key].is_number_unsigned()) return j[key].get<std::uint64_t>();
  return static_cast<std::uint64_t>(v);
}

std::optional<double> ReportReader::optionalNumber(const json& j, const char* key,
                                                   const std::string& path) const {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return std::nullopt;
  return number(j, key, path);
}

std::optional<PixelRef> ReportReader::pixel(const json& j, const char* key,
                                            const std::string& path) const {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return std::nullopt;
  const json& v = j[key];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() || !v[1].is_number_integer())
    fail(path + "." + key, "must be [x, y]");
  return PixelRef{v[0].get<int>(), v[1].get<int>()};
}

Status ReportReader::status(const json& j, const char* key, const std::string& path) const {
  if (!j.is_object() || !j.contains(key)) return Status::Pass;
  const std::string s = text(j, key, path);
  for (Status st : {Status::Pass, Status::Warn, Status::Fail, Status::Error, Status::NotSupported,
                    Status::Flake})
    if (s == toString(st)) return st;
  fail(path + "." + key, fmt::format("unknown status \"{}\"", s));
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A number toJson wrote with num(): null stands for a non-finite value when the field
// was meaningful (`meaningful`), else for the field's default of 0.
double finiteOr(const ReportReader& r, const json& j, const char* key, const std::string& at,
                bool meaningful, double non_finite = kNaN) {
  if (j.is_object() && j.contains(key) && j[key].is_null()) return meaningful ? non_finite : 0.0;
  return r.number(j, key, at);
}

template <typename Enum, std::size_t N>
Enum enumFrom(const ReportReader& r, const json& j, const char* key, const std::string& at,
              const Enum (&values)[N]) {
  const std::string text = r.text(j, key, at);
  for (Enum v : values)
    if (text == toString(v)) return v;
  r.fail(at + "." + key, fmt::format("unknown value \"{}\"", text));
}

ErrorHistogram histogramFrom(const ReportReader& r, const json& h, const std::string& at,
                             ErrorHistogram fallback) {
  if (!h.is_object()) return fallback;
  const json& edges = r.member(h, "edges", at);
  const json& counts = r.member(h, "counts", at);
  if (!edges.is_array() || !counts.is_array() || edges.size() < 2 ||
      counts.size() + 1 != edges.size())
    r.fail(at, "edges and counts do not match");
  const double quantum = edges[1].is_number() ? edges[1].get<double>() : 0.0;
  if (!(quantum > 0.0)) r.fail(at + ".edges", "must start 0, quantum");
  const bool exact = h.contains("exact_zero_bin") && h["exact_zero_bin"].is_boolean() &&
                     h["exact_zero_bin"].get<bool>();
  ErrorHistogram out(quantum, exact);
  // Each coarse bin's count at its lower edge: coarse() gives the same bins back.
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (!counts[i].is_number_unsigned() && !counts[i].is_number_integer())
      r.fail(fmt::format("{}.counts[{}]", at, i), "must be a count");
    const auto n = counts[i].get<std::uint64_t>();
    if (n > 0) out.add(edges[i].is_number() ? edges[i].get<double>() : 0.0, n);
  }
  return out;
}

void nonfiniteFrom(const ReportReader& r, const json& j, const std::string& at,
                   NonFiniteCounts& out) {
  if (!j.is_object()) return;
  for (std::size_t c = 0; c < kFrameChannels.size(); ++c) {
    if (!j.contains(kFrameChannels[c])) continue;
    const json& ch = j[kFrameChannels[c]];
    const std::string cat = at + "." + kFrameChannels[c];
    out.nan[c] = r.count(ch, "nan", cat);
    out.inf[c] = r.count(ch, "inf", cat);
  }
}

Thresholds thresholdsFrom(const ReportReader& r, const json& t, const char* key,
                          const std::string& at) {
  const json& j = r.member(t, key, at);
  return {r.number(j, "warn", at + "." + key), r.number(j, "fail", at + "." + key)};
}

}  // namespace

namespace {

// The retries and deqp-runner status of a row (report.cpp addRunnerFields).
void runnerFieldsFrom(const ReportReader& r, const json& row, const std::string& at,
                      const fs::path& report_dir, PairResult& p) {
  if (row.contains("attempts")) {
    const json& attempts = row["attempts"];
    if (!attempts.is_array()) r.fail(at + ".attempts", "must be an array");
    for (std::size_t k = 0; k < attempts.size(); ++k) {
      const std::string kat = fmt::format("{}.attempts[{}]", at, k);
      PairResult::Attempt a;
      if (attempts[k].contains("error")) {
        a.error = r.text(attempts[k], "error", kat);
      } else {
        a.digest = r.text(attempts[k], "digest", kat);
      }
      if (attempts[k].contains("frame"))
        a.frame = (report_dir / fs::path(r.text(attempts[k], "frame", kat))).string();
      p.attempts.push_back(std::move(a));
    }
  }
  if (row.contains("flake") && row["flake"].is_object()) {
    p.flake_pixels = r.count(row["flake"], "differing_pixels", at + ".flake");
    p.flake_first = r.pixel(row["flake"], "first", at + ".flake").value_or(PixelRef{});
  }
  if (row.contains("render_seconds")) p.render_seconds = r.number(row, "render_seconds", at);
  if (row.contains("runner_status")) p.runner_status = r.text(row, "runner_status", at);
}

}  // namespace

PairResult pairResultFromJson(const ReportReader& r, const json& row, const std::string& at,
                              const fs::path& report_dir) {
  PairResult p;
  p.fixture = r.text(row, "fixture", at);
  p.expected = r.text(row, "expected", at);
  p.actual = r.text(row, "actual", at);
  p.status = r.status(row, "status", at);
  p.pixels = r.count(row, "pixels", at);
  if (row.contains("fixture_file") && row["fixture_file"].is_string())
    p.fixture_file = row["fixture_file"].get<std::string>();
  if (row.contains("tags") && row["tags"].is_array())
    for (const json& t : row["tags"])
      if (t.is_string()) p.tags.push_back(t.get<std::string>());
  if (row.contains("state") && row["state"].is_object()) p.state = row["state"];
  if (row.contains("known") && row["known"].is_array()) {
    const json& known = row["known"];
    for (std::size_t k = 0; k < known.size(); ++k) {
      const std::string kat = fmt::format("{}.known[{}]", at, k);
      p.known.push_back({r.text(known[k], "id", kat), r.text(known[k], "class", kat),
                         r.text(known[k], "reason", kat)});
    }
  }
  runnerFieldsFrom(r, row, at, report_dir, p);
  if (p.status == Status::Error || p.status == Status::NotSupported) {
    const char* why = p.status == Status::Error ? "error" : "not_supported";
    p.error =
        row.contains(why) && row[why].is_string() ? row[why].get<std::string>() : std::string();
    p.visibility.status = p.depth.status = p.shading.status = p.status;
    return p;
  }
  p.width = static_cast<int>(r.number(row, "width", at));
  p.height = static_cast<int>(r.number(row, "height", at));
  if (row.contains("subpixel_bits")) {
    p.expected_subpixel_bits = static_cast<int>(r.number(row["subpixel_bits"], "expected", at));
    p.actual_subpixel_bits = static_cast<int>(r.number(row["subpixel_bits"], "actual", at));
  }

  if (row.contains("stacks") && row["stacks"].is_object()) {
    const json& stacks = row["stacks"];
    if (stacks.contains("expected")) p.expected_stack = stacks["expected"];
    if (stacks.contains("actual")) p.actual_stack = stacks["actual"];
  }
  // The actual side's GL version, which expectations entries may be scoped to.
  if (p.actual_stack.is_object() && p.actual_stack.contains("gl_version") &&
      p.actual_stack["gl_version"].is_string())
    p.actual_driver = p.actual_stack["gl_version"].get<std::string>();

  const std::string tat = at + ".tolerances";
  const json& t = r.member(row, "tolerances", at);
  Tolerances& tol = p.tolerances;
  tol.depth_format =
      enumFrom(r, t, "depth_format", tat, {DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F});
  tol.color_format =
      enumFrom(r, t, "color_format", tat, {ColorFormat::RGBA32F, ColorFormat::RGBA8});
  tol.visibility = thresholdsFrom(r, t, "visibility", tat);
  tol.depth = thresholdsFrom(r, t, "depth", tat);
  tol.shading = thresholdsFrom(r, t, "shading", tat);
  tol.depth_slope_factor = r.number(t, "depth_slope_factor", tat);
  tol.shading_relative = r.number(t, "shading_relative", tat);
  tol.shading_slope_factor = r.number(t, "shading_slope_factor", tat);
  tol.texture_weight_error = r.number(t, "texture_weight_error", tat);
  tol.texture_rounding_units = r.number(t, "texture_rounding_units", tat);
  tol.texel_choice = r.number(t, "texel_choice", tat);
  tol.blend_rounding_units = r.number(t, "blend_rounding_units", tat);
  tol.window_error_ulps = r.number(t, "window_error_ulps", tat);
  tol.band_px = r.optionalNumber(t, "band_px_override", tat);

  const std::string vat = at + ".visibility";
  const json& v = r.member(row, "visibility", at);
  VisibilityStats& vs = p.visibility;
  vs.status = r.status(v, "status", vat);
  vs.mismatched = r.count(v, "mismatched", vat);
  vs.ambiguous = r.count(v, "ambiguous", vat);
  vs.hard = r.count(v, "hard", vat);
  vs.missing = r.count(v, "missing", vat);
  vs.extra = r.count(v, "extra", vat);
  vs.wrong_primitive = r.count(v, "wrong_primitive", vat);
  vs.missing_hard = r.count(v, "missing_hard", vat);
  vs.extra_hard = r.count(v, "extra_hard", vat);
  vs.wrong_primitive_hard = r.count(v, "wrong_primitive_hard", vat);
  vs.ambiguous_by_depth_gap = r.count(v, "ambiguous_by_depth_gap", vat);
  vs.band_px = r.number(v, "band_px", vat);
  vs.uncertainty_available = v.contains("uncertainty_available") &&
                             v["uncertainty_available"].is_boolean() &&
                             v["uncertainty_available"].get<bool>();
  vs.worst = r.pixel(v, "worst", vat).value_or(PixelRef{});
  vs.worst_edge_dist = finiteOr(r, v, "worst_edge_dist", vat, vs.worst.valid(),
                                std::numeric_limits<double>::infinity());
  if (v.contains("samples")) {  // multisampled pairs (report.cpp writes them when > 1)
    vs.samples = static_cast<int>(r.count(v, "samples", vat));
    vs.mismatched_samples = r.count(v, "mismatched_samples", vat);
  }

  const std::string dat = at + ".depth";
  const json& d = r.member(row, "depth", at);
  DepthStats& ds = p.depth;
  ds.status = r.status(d, "status", dat);
  ds.compared = r.count(d, "compared", dat);
  ds.max_steps = r.number(d, "max_steps", dat);
  ds.mean_steps = r.number(d, "mean_steps", dat);
  ds.p99_steps = r.number(d, "p99_steps", dat);
  ds.over_tolerance = r.count(d, "over_tolerance", dat);
  ds.over_fail = r.count(d, "over_fail", dat);
  ds.nonfinite = r.count(d, "nonfinite", dat);
  ds.blend_uncertain = r.count(d, "blend_uncertain", dat);
  ds.band_px = r.number(d, "band_px", dat);
  ds.max_slope = r.number(d, "max_slope", dat);
  ds.worst = r.pixel(d, "worst", dat).value_or(PixelRef{});
  ds.worst_steps = finiteOr(r, d, "worst_steps", dat, ds.worst.valid());
  ds.worst_allowance = finiteOr(r, d, "worst_allowance", dat, ds.worst.valid());
  // Reports written before cleared buffers and stencil were compared lack these.
  if (d.contains("cleared") && d["cleared"].is_object()) {
    ds.cleared_checked = r.count(d["cleared"], "checked", dat + ".cleared");
    ds.cleared_mismatched = r.count(d["cleared"], "mismatched", dat + ".cleared");
  }
  if (d.contains("stencil") && d["stencil"].is_object()) {
    const json& st = d["stencil"];
    const std::string stat = dat + ".stencil";
    ds.stencil.compared = st.value("compared", false);
    ds.stencil.pixels = r.count(st, "pixels", stat);
    ds.stencil.mismatched = r.count(st, "mismatched", stat);
    ds.stencil.ambiguous = r.count(st, "ambiguous", stat);
    ds.stencil.hard = r.count(st, "hard", stat);
    ds.stencil.worst = r.pixel(st, "worst", stat).value_or(PixelRef{});
    if (st.contains("worst_expected") && st["worst_expected"].is_number_integer())
      ds.stencil.worst_expected = st["worst_expected"].get<int>();
    if (st.contains("worst_actual") && st["worst_actual"].is_number_integer())
      ds.stencil.worst_actual = st["worst_actual"].get<int>();
  }
  if (d.contains("polygon_offset_r") && d["polygon_offset_r"].is_object()) {
    const json& o = d["polygon_offset_r"];
    auto value = [&](const char* key) {
      return o.contains(key) && o[key].is_number() ? o[key].get<double>()
                                                   : std::numeric_limits<double>::quiet_NaN();
    };
    ds.offset_r_expected = value("expected");
    ds.offset_r_actual = value("actual");
    ds.offset_r_spread = value("spread");
  }
  ds.histogram = histogramFrom(r, d.contains("histogram") ? d["histogram"] : json(),
                               dat + ".histogram", ds.histogram);

  const std::string sat = at + ".shading";
  const json& s = r.member(row, "shading", at);
  ShadingStats& ss = p.shading;
  ss.status = r.status(s, "status", sat);
  ss.compared = r.count(s, "compared", sat);
  ss.max_abs = r.number(s, "max_abs", sat);
  ss.mean_abs = r.number(s, "mean_abs", sat);
  ss.rmse = r.number(s, "rmse", sat);
  ss.psnr_db = r.number(s, "psnr_db", sat);
  ss.p99_abs = r.number(s, "p99_abs", sat);
  ss.over_tolerance = r.count(s, "over_tolerance", sat);
  ss.over_fail = r.count(s, "over_fail", sat);
  ss.nonfinite = r.count(s, "nonfinite", sat);
  ss.texel_choice = r.count(s, "texel_choice", sat);
  ss.blend_uncertain = r.count(s, "blend_uncertain", sat);
  if (s.contains("cleared") && s["cleared"].is_object()) {
    ss.cleared_checked = r.count(s["cleared"], "checked", sat + ".cleared");
    ss.cleared_mismatched = r.count(s["cleared"], "mismatched", sat + ".cleared");
  }
  if (s.contains("depth_tied")) ss.depth_tied = r.count(s, "depth_tied", sat);
  if (s.contains("max_abs_rgba") && s["max_abs_rgba"].is_array() && s["max_abs_rgba"].size() == 4) {
    for (std::size_t c = 0; c < 4; ++c)
      ss.max_abs_rgba[c] =
          s["max_abs_rgba"][c].is_number() ? s["max_abs_rgba"][c].get<double>() : kNaN;
  }
  ss.worst = r.pixel(s, "worst", sat).value_or(PixelRef{});
  ss.worst_abs = finiteOr(r, s, "worst_abs", sat, ss.worst.valid());
  ss.worst_allowance = finiteOr(r, s, "worst_allowance", sat, ss.worst.valid());
  ss.histogram = histogramFrom(r, s.contains("histogram") ? s["histogram"] : json(),
                               sat + ".histogram", ss.histogram);

  if (row.contains("nonfinite") && row["nonfinite"].is_object()) {
    const json& nf = row["nonfinite"];
    if (nf.contains("expected"))
      nonfiniteFrom(r, nf["expected"], at + ".nonfinite.expected", p.nonfinite_expected);
    if (nf.contains("actual"))
      nonfiniteFrom(r, nf["actual"], at + ".nonfinite.actual", p.nonfinite_actual);
  }
  if (row.contains("images") && row["images"].is_object()) {
    for (const auto& [kind, file] : row["images"].items()) {
      if (!file.is_string()) r.fail(fmt::format("{}.images.{}", at, kind), "must be a string");
      p.images[kind] = report_dir / fs::path(file.get<std::string>());
    }
  }
  if (row.contains("heat_scales")) {
    p.depth_heat_scale = r.number(row["heat_scales"], "depth_steps", at + ".heat_scales");
    p.shading_heat_scale = r.number(row["heat_scales"], "shading_abs", at + ".heat_scales");
  }
  // The additive blocks (compare/flip.h, compare/ciede2000.h, compare/oit.h), so that merged
  // shards keep them.
  if (row.contains("flip") && row["flip"].is_object()) {
    const json& f = row["flip"];
    const std::string fat = at + ".flip";
    FlipStats fs;
    fs.status = r.text(f, "status", fat) == "fail" ? Status::Fail : Status::Pass;
    fs.mean = r.number(f, "mean", fat);
    fs.weighted_median = r.number(f, "weighted_median", fat);
    fs.weighted_q1 = r.number(f, "weighted_q1", fat);
    fs.weighted_q3 = r.number(f, "weighted_q3", fat);
    fs.min = r.number(f, "min", fat);
    fs.max = r.number(f, "max", fat);
    fs.threshold = r.optionalNumber(f, "threshold", fat);
    fs.ppd = r.number(f, "pixels_per_degree", fat);
    p.flip = fs;
  }
  if (row.contains("ciede2000") && row["ciede2000"].is_object()) {
    const json& c = row["ciede2000"];
    const std::string cat = at + ".ciede2000";
    DeltaE2000Stats cs;
    cs.mean = r.number(c, "mean", cat);
    cs.weighted_median = r.number(c, "weighted_median", cat);
    cs.weighted_q1 = r.number(c, "weighted_q1", cat);
    cs.weighted_q3 = r.number(c, "weighted_q3", cat);
    cs.min = r.number(c, "min", cat);
    cs.max = r.number(c, "max", cat);
    cs.differing = r.count(c, "differing", cat);
    const PixelRef worst = r.pixel(c, "worst", cat).value_or(PixelRef{});
    cs.worst_x = worst.x;
    cs.worst_y = worst.y;
    p.ciede2000 = cs;
  }
  if (row.contains("oit") && row["oit"].is_object()) {
    const json& o = row["oit"];
    const std::string oat = at + ".oit";
    OitStats os;
    os.blended_pixels = r.count(o, "blended_pixels", oat);
    os.unsorted_pixels = r.count(o, "unsorted_pixels", oat);
    os.pixels = r.count(o, "pixels", oat);
    os.threshold = r.number(o, "threshold", oat);
    os.max_abs = r.optionalNumber(o, "max_abs", oat).value_or(HUGE_VAL);
    os.mean_abs = r.optionalNumber(o, "mean_abs", oat).value_or(HUGE_VAL);
    const PixelRef worst = r.pixel(o, "worst", oat).value_or(PixelRef{});
    os.worst_x = worst.x;
    os.worst_y = worst.y;
    os.pairs_total = r.count(o, "out_of_order_pairs", oat);
    if (o.contains("out_of_order") && o["out_of_order"].is_array()) {
      for (const json& q : o["out_of_order"]) {
        const std::string qat = oat + ".out_of_order[]";
        OitPair pair;
        pair.near_id = static_cast<std::uint32_t>(r.count(q, "near", qat));
        pair.far_id = static_cast<std::uint32_t>(r.count(q, "far", qat));
        pair.pixels = r.count(q, "pixels", qat);
        const PixelRef first = r.pixel(q, "first", qat).value_or(PixelRef{});
        pair.first_x = first.x;
        pair.first_y = first.y;
        os.out_of_order.push_back(pair);
      }
    }
    p.oit = os;
  }
  p.seconds = r.number(row, "seconds", at);
  return p;
}

Report readReportFile(const fs::path& file) {
  const json doc = readJsonFile(file);
  const ReportReader r(file);
  Report report;
  if (doc.contains("tool") && doc["tool"].is_object()) {
    const json& tool = doc["tool"];
    if (tool.contains("name") && tool["name"].is_string())
      report.tool_name = tool["name"].get<std::string>();
    if (tool.contains("version") && tool["version"].is_string())
      report.tool_version = tool["version"].get<std::string>();
  }
  if (doc.contains("command") && doc["command"].is_string())
    report.command = doc["command"].get<std::string>();
  if (doc.contains("variants") && doc["variants"].is_object()) report.variants = doc["variants"];
  if (doc.contains("shard") && doc["shard"].is_object()) report.shard = doc["shard"];
  if (doc.contains("runner") && doc["runner"].is_object()) report.runner = doc["runner"];
  if (doc.contains("skipped") && doc["skipped"].is_array())
    for (const json& s : doc["skipped"])
      if (s.is_string()) report.skipped.push_back(s.get<std::string>());
  const json& results = r.member(doc, "results", "");
  if (!results.is_array()) r.fail("results", "must be an array");
  const fs::path dir = file.parent_path();
  for (std::size_t i = 0; i < results.size(); ++i)
    report.results.push_back(pairResultFromJson(r, results[i], fmt::format("results[{}]", i), dir));
  return report;
}

}  // namespace rc
