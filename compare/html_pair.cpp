// What each pair's section of report.html shows, as the data its script builds the section
// from: image files, numbers per class, thresholds, perceptual and transparency blocks.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "compare/html_internal.h"
#include "compare/report.h"
#include "compare/report_text.h"

namespace rc::detail {
namespace fs = std::filesystem;
namespace {

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

}  // namespace

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

}  // namespace rc::detail
