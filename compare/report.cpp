// report.json, one-line descriptions, exit codes and the all-or-nothing report writer:
// see report.h. The JSON layout is pinned by docs/report-schema.json.
#include "compare/report.h"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "compare/atomic_file.h"
#include "compare/deqp_results.h"
#include "compare/report_text.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;
namespace {

// JSON has no NaN or Inf.
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json clearedJson(std::uint64_t checked, std::uint64_t mismatched) {
  return {{"checked", checked}, {"mismatched", mismatched}};
}

json pixel(const PixelRef& p) { return p.valid() ? json::array({p.x, p.y}) : json(nullptr); }
json windowPixel(const PixelRef& p, int height) {
  return p.valid() ? json::array({p.x, height - 1 - p.y}) : json(nullptr);
}

json thresholds(const Thresholds& t) { return {{"warn", num(t.warn)}, {"fail", num(t.fail)}}; }

json histogram(const ErrorHistogram& h, double max_value, const char* unit) {
  const ErrorHistogram::Coarse c = h.coarse(max_value);
  json edges = json::array();
  for (double e : c.edges) edges.push_back(num(e));
  return {{"unit", unit},
          {"exact_zero_bin", h.exactMultiples()},
          {"edges", edges},
          {"counts", c.counts}};
}

json nonfinite(const NonFiniteCounts& n) {
  json j = json::object();
  for (std::size_t c = 0; c < kFrameChannels.size(); ++c)
    j[kFrameChannels[c]] = {{"nan", n.nan[c]}, {"inf", n.inf[c]}};
  return j;
}

std::string relativePath(const fs::path& file, const fs::path& base) {
  std::error_code ec;
  fs::path rel = fs::proximate(file, base.empty() ? fs::path(".") : base, ec);
  if (ec) rel = file;
  return rel.generic_string();
}

}  // namespace

std::string where(const PixelRef& p, int height) {
  return p.valid() ? fmt::format("({},{}) window ({},{})", p.x, p.y, p.x, height - 1 - p.y)
                   : std::string("(none)");
}

std::string visibilityText(const PairResult& r) {
  const VisibilityStats& v = r.visibility;
  return fmt::format(
      "visibility {}: {} hard mismatched px (missing {}, extra {}, wrong_primitive {}; "
      "warn above {}, fail above {}), {} ambiguous within {:.4g} px{}; worst {}",
      toString(v.status), v.hard, v.missing_hard, v.extra_hard, v.wrong_primitive_hard,
      r.tolerances.visibility.warn, r.tolerances.visibility.fail, v.ambiguous, v.band_px,
      v.uncertainty_available ? "" : " (no uncertainty channels: every mismatch is hard)",
      where(v.worst, r.height));
}

std::string depthText(const PairResult& r) {
  const DepthStats& d = r.depth;
  std::string s = fmt::format(
      "depth {}: {} px over tolerance ({} over fail; tolerance = warn {} / fail {} steps + "
      "slope allowance), max {} steps, p99 {} steps",
      toString(d.status), d.over_tolerance, d.over_fail, r.tolerances.depth.warn,
      r.tolerances.depth.fail, d.max_steps, d.p99_steps);
  if (d.nonfinite) s += fmt::format(", {} px with non-finite Z", d.nonfinite);
  s += fmt::format("; worst {}", where(d.worst, r.height));
  if (d.worst.valid())
    s += std::isfinite(d.worst_steps)
             ? fmt::format(": {:.6g} steps, allowance {:.4g}", d.worst_steps, d.worst_allowance)
             : std::string(": non-finite Z");
  return s;
}

std::string shadingAllowanceText(const Tolerances& t, double slope_band_px) {
  std::string s =
      fmt::format("{:.3g} x 255 x |C| + {:.3g} x {:.3g} px x max(|dC/dpx|, shade_reach)",
                  t.shading_relative, t.shading_slope_factor, slope_band_px);
  if (t.texture_weight_error > 0.0 || t.texture_rounding_units > 0.0)
    s += fmt::format(" + {:.3g} x texel_alt + {:.3g} x texel_gain (linear texture filtering)",
                     t.texture_weight_error, t.texture_rounding_units);
  if (t.texel_choice > 0.0)
    s += fmt::format(" + {:.3g} x texel_alt where texel_dist <= {:.3g} px", t.texel_choice,
                     slope_band_px);
  if (t.blend_rounding_units > 0.0)
    s += fmt::format(" + {:.3g} x blend_count", t.blend_rounding_units);
  return s;
}

std::string shadingText(const PairResult& r) {
  const ShadingStats& s = r.shading;
  std::string t = fmt::format(
      "shading {}: {} px over tolerance ({} over fail; tolerance = warn {:.4g} / fail {:.4g} "
      "8-bit units + allowance), max_abs {:.4g}, p99 {:.4g}",
      toString(s.status), s.over_tolerance, s.over_fail, r.tolerances.shading.warn,
      r.tolerances.shading.fail, s.max_abs, s.p99_abs);
  if (s.nonfinite) t += fmt::format(", {} px with non-finite colour", s.nonfinite);
  t += fmt::format("; worst {}", where(s.worst, r.height));
  if (s.worst.valid())
    t += std::isfinite(s.worst_abs)
             ? fmt::format(": {:.4g} units, allowance {:.4g}", s.worst_abs, s.worst_allowance)
             : std::string(": non-finite colour");
  return t;
}

ReportSummary Report::summary() const {
  ReportSummary s;
  for (const PairResult& r : results) {
    switch (r.status) {
      case Status::Pass:
        ++s.pass;
        break;
      case Status::Warn:
        ++s.warn;
        break;
      case Status::Fail:
        ++s.fail;
        if (!r.known.empty()) ++s.known_fail;
        break;
      case Status::Error:
        ++s.error;
        break;
      case Status::NotSupported:
        ++s.not_supported;
        break;
      case Status::Flake:
        ++s.flake;
        break;
    }
  }
  return s;
}

int exitCodeFor(const Report& report) {
  if (!report.runner.empty()) {
    int code = kExitPass;
    for (const PairResult& r : report.results) {
      if (runnerSuccess(r.runner_status)) continue;
      if (r.runner_status == "Crash" || r.runner_status == "Timeout") return kExitBackend;
      code = kExitFail;
    }
    return code;
  }
  const ReportSummary s = report.summary();
  if (s.error) return kExitBackend;
  if (s.fail > s.known_fail) return kExitFail;
  return kExitPass;
}

// The retries of a pair and its deqp-runner status (app/run_command.cpp, compare/deqp_results.h).
void addRunnerFields(json& j, const PairResult& r, const fs::path& report_dir) {
  if (!r.attempts.empty()) {
    json attempts = json::array();
    for (const PairResult::Attempt& a : r.attempts) {
      json x = json::object();
      if (a.error.empty()) {
        x["digest"] = a.digest;
      } else {
        x["error"] = a.error;
      }
      if (!a.frame.empty()) x["frame"] = relativePath(a.frame, report_dir);
      attempts.push_back(x);
    }
    j["attempts"] = attempts;
  }
  if (r.status == Status::Flake)
    j["flake"] = {{"differing_pixels", r.flake_pixels}, {"first", pixel(r.flake_first)}};
  if (r.render_seconds > 0.0) j["render_seconds"] = num(r.render_seconds);
  if (!r.runner_status.empty()) j["runner_status"] = r.runner_status;
}

json toJson(const PairResult& r, const fs::path& report_dir) {
  json j = {{"fixture", r.fixture},
            {"expected", r.expected},
            {"actual", r.actual},
            {"status", toString(r.status)},
            {"pixels", r.pixels}};
  if (!r.state.empty()) j["state"] = r.state;
  if (!r.known.empty()) {
    json known = json::array();
    for (const KnownFailure& k : r.known)
      known.push_back({{"id", k.id}, {"class", k.cls}, {"reason", k.reason}});
    j["known"] = known;
  }
  if (!r.fixture_file.empty()) j["fixture_file"] = r.fixture_file;
  if (!r.tags.empty()) j["tags"] = r.tags;
  if (r.status == Status::Error || r.status == Status::NotSupported) {
    // The contract's shape with nothing compared: every class "error" (or
    // "not_supported"), zero counts.
    const char* e = toString(r.status);
    j[r.status == Status::Error ? "error" : "not_supported"] = r.error;
    addRunnerFields(j, r, report_dir);
    j["visibility"] = {{"status", e},  {"mismatched", 0}, {"ambiguous", 0},      {"hard", 0},
                       {"missing", 0}, {"extra", 0},      {"wrong_primitive", 0}};
    j["depth"] = {{"status", e},    {"compared", 0},       {"max_steps", 0},  {"mean_steps", 0},
                  {"p99_steps", 0}, {"over_tolerance", 0}, {"worst", nullptr}};
    j["shading"] = {{"status", e},         {"compared", 0},   {"max_abs", 0},
                    {"mean_abs", 0},       {"rmse", 0},       {"psnr_db", kPsnrCapDb},
                    {"over_tolerance", 0}, {"worst", nullptr}};
    j["images"] = json::object();
    return j;
  }
  const Tolerances& t = r.tolerances;
  const VisibilityStats& v = r.visibility;
  const DepthStats& d = r.depth;
  const ShadingStats& s = r.shading;
  j["width"] = r.width;
  j["height"] = r.height;
  j["subpixel_bits"] = {{"expected", r.expected_subpixel_bits}, {"actual", r.actual_subpixel_bits}};
  if (!r.expected_stack.is_null() || !r.actual_stack.is_null())
    j["stacks"] = {{"expected", r.expected_stack}, {"actual", r.actual_stack}};
  j["tolerances"] = {{"depth_format", toString(t.depth_format)},
                     {"color_format", toString(t.color_format)},
                     {"visibility", thresholds(t.visibility)},
                     {"depth", thresholds(t.depth)},
                     {"shading", thresholds(t.shading)},
                     {"depth_slope_factor", num(t.depth_slope_factor)},
                     {"shading_relative", num(t.shading_relative)},
                     {"shading_slope_factor", num(t.shading_slope_factor)},
                     {"texture_weight_error", num(t.texture_weight_error)},
                     {"texture_rounding_units", num(t.texture_rounding_units)},
                     {"texel_choice", num(t.texel_choice)},
                     {"blend_rounding_units", num(t.blend_rounding_units)},
                     {"window_error_ulps", num(t.window_error_ulps)},
                     {"band_px_override", t.band_px ? num(*t.band_px) : json(nullptr)}};
  j["visibility"] = {{"status", toString(v.status)},
                     {"mismatched", v.mismatched},
                     {"ambiguous", v.ambiguous},
                     {"hard", v.hard},
                     {"missing", v.missing},
                     {"extra", v.extra},
                     {"wrong_primitive", v.wrong_primitive},
                     {"missing_hard", v.missing_hard},
                     {"extra_hard", v.extra_hard},
                     {"wrong_primitive_hard", v.wrong_primitive_hard},
                     {"ambiguous_by_depth_gap", v.ambiguous_by_depth_gap},
                     {"band_px", num(v.band_px)},
                     {"uncertainty_available", v.uncertainty_available},
                     {"worst", pixel(v.worst)},
                     {"worst_window", windowPixel(v.worst, r.height)},
                     {"worst_edge_dist", v.worst.valid() ? num(v.worst_edge_dist) : json(nullptr)}};
  j["depth"] = {
      {"status", toString(d.status)},
      {"compared", d.compared},
      {"max_steps", num(d.max_steps)},
      {"mean_steps", num(d.mean_steps)},
      {"p99_steps", num(d.p99_steps)},
      {"over_tolerance", d.over_tolerance},
      {"over_fail", d.over_fail},
      {"nonfinite", d.nonfinite},
      {"blend_uncertain", d.blend_uncertain},
      {"band_px", num(d.band_px)},
      {"max_slope", num(d.max_slope)},
      {"worst", pixel(d.worst)},
      {"worst_window", windowPixel(d.worst, r.height)},
      {"worst_steps", d.worst.valid() ? num(d.worst_steps) : json(nullptr)},
      {"worst_allowance", d.worst.valid() ? num(d.worst_allowance) : json(nullptr)},
      {"step", num(1.0 / depthStepsPerUnit(t.depth_format))},
      {"histogram", histogram(d.histogram, d.max_steps, "steps")},
      {"cleared", clearedJson(d.cleared_checked, d.cleared_mismatched)},
      {"polygon_offset_r",
       {{"expected", num(d.offset_r_expected)},
        {"actual", num(d.offset_r_actual)},
        {"spread", num(d.offset_r_spread)}}},
      {"stencil",
       {{"compared", d.stencil.compared},
        {"pixels", d.stencil.pixels},
        {"mismatched", d.stencil.mismatched},
        {"ambiguous", d.stencil.ambiguous},
        {"hard", d.stencil.hard},
        {"worst", pixel(d.stencil.worst)},
        {"worst_window", windowPixel(d.stencil.worst, r.height)},
        {"worst_expected",
         d.stencil.worst.valid() ? json(d.stencil.worst_expected) : json(nullptr)},
        {"worst_actual", d.stencil.worst.valid() ? json(d.stencil.worst_actual) : json(nullptr)}}}};
  j["shading"] = {{"status", toString(s.status)},
                  {"compared", s.compared},
                  {"max_abs", num(s.max_abs)},
                  {"mean_abs", num(s.mean_abs)},
                  {"rmse", num(s.rmse)},
                  {"psnr_db", num(s.psnr_db)},
                  {"p99_abs", num(s.p99_abs)},
                  {"over_tolerance", s.over_tolerance},
                  {"over_fail", s.over_fail},
                  {"nonfinite", s.nonfinite},
                  {"texel_choice", s.texel_choice},
                  {"cleared", clearedJson(s.cleared_checked, s.cleared_mismatched)},
                  {"blend_uncertain", s.blend_uncertain},
                  {"max_abs_rgba",
                   {num(s.max_abs_rgba[0]), num(s.max_abs_rgba[1]), num(s.max_abs_rgba[2]),
                    num(s.max_abs_rgba[3])}},
                  {"worst", pixel(s.worst)},
                  {"worst_window", windowPixel(s.worst, r.height)},
                  {"worst_abs", s.worst.valid() ? num(s.worst_abs) : json(nullptr)},
                  {"worst_allowance", s.worst.valid() ? num(s.worst_allowance) : json(nullptr)},
                  {"histogram", histogram(s.histogram, s.max_abs, "8-bit units")}};
  if (v.samples > 1) {  // multisampled: pixels count as mismatched when any sample differs
    j["visibility"]["samples"] = v.samples;
    j["visibility"]["mismatched_samples"] = v.mismatched_samples;
    j["shading"]["depth_tied"] = s.depth_tied;
  }
  j["nonfinite"] = {{"expected", nonfinite(r.nonfinite_expected)},
                    {"actual", nonfinite(r.nonfinite_actual)}};
  // Additive blocks kept in their own modules (compare/oit.h, compare/flip.h,
  // compare/ciede2000.h).
  if (r.oit) j["oit"] = oitJson(*r.oit, r.height);
  if (r.flip) j["flip"] = flipJson(*r.flip);
  if (r.ciede2000) j["ciede2000"] = deltaE2000Json(*r.ciede2000, r.height);
  json images = json::object();
  for (const auto& [kind, file] : r.images) images[kind] = relativePath(file, report_dir);
  j["images"] = images;
  j["heat_scales"] = {{"depth_steps", num(r.depth_heat_scale)},
                      {"shading_abs", num(r.shading_heat_scale)}};
  j["seconds"] = num(r.seconds);
  addRunnerFields(j, r, report_dir);
  return j;
}

json toJson(const Report& report, const fs::path& report_dir) {
  json results = json::array();
  for (const PairResult& r : report.results) results.push_back(toJson(r, report_dir));
  const ReportSummary s = report.summary();
  json j = {{"format", kReportFormat},
            {"tool", {{"name", report.tool_name}, {"version", report.tool_version}}},
            {"results", results},
            {"summary",
             {{"pass", s.pass},
              {"warn", s.warn},
              {"fail", s.fail},
              {"error", s.error},
              {"not_supported", s.not_supported},
              {"flake", s.flake},
              {"known_fail", s.known_fail},
              {"total", s.total()}}},
            {"exit_code", exitCodeFor(report)}};
  if (!report.command.empty()) j["command"] = report.command;
  if (!report.variants.empty()) j["variants"] = report.variants;
  if (!report.shard.empty()) j["shard"] = report.shard;
  if (!report.runner.empty()) j["runner"] = report.runner;
  if (!report.skipped.empty()) j["skipped"] = report.skipped;
  return j;
}

std::string describe(const PairResult& r) {
  std::string status = toString(r.status);
  for (char& ch : status) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (!r.known.empty()) status = "KNOWN FAIL";
  std::string head = fmt::format("{} {} {} vs {}", status, r.fixture, r.expected, r.actual);
  if (r.status == Status::Error) return head + ": " + r.error;
  if (r.status == Status::NotSupported) return head + ": " + r.error;
  if (r.status == Status::Flake) {
    std::vector<std::string> what;
    for (const PairResult::Attempt& a : r.attempts)
      what.push_back(a.error.empty() ? a.digest.substr(0, 12) : "no frame (" + a.error + ")");
    head += fmt::format(": {} renders disagree: {}", r.attempts.size(), fmt::join(what, " / "));
    if (r.flake_pixels > 0)
      head +=
          fmt::format("; {} px differ, first {}", r.flake_pixels, where(r.flake_first, r.height));
    std::vector<std::string> failing;
    for (const auto& [name, st] :
         {std::pair{"visibility", r.visibility.status}, std::pair{"depth", r.depth.status},
          std::pair{"shading", r.shading.status}})
      if (st == Status::Fail) failing.emplace_back(name);
    if (!failing.empty()) head += fmt::format("; the first failed {}", fmt::join(failing, ", "));
    return head;
  }
  if (!r.known.empty()) {
    std::vector<std::string> ids;
    for (const KnownFailure& k : r.known) ids.push_back(k.id);
    head += fmt::format(" [{}]", fmt::join(ids, ", "));
  }
  // The classes that set the pair's status; at pass, nothing to say.
  std::vector<std::string> parts;
  if (r.visibility.status == r.status && r.status != Status::Pass)
    parts.push_back(visibilityText(r));
  if (r.depth.status == r.status && r.status != Status::Pass) parts.push_back(depthText(r));
  if (r.shading.status == r.status && r.status != Status::Pass) parts.push_back(shadingText(r));
  if (r.flip && r.flip->status == r.status && r.status != Status::Pass)
    parts.push_back(fmt::format("flip: mean {:.4g} over the threshold {:.4g}", r.flip->mean,
                                r.flip->threshold.value_or(0.0)));
  if (parts.empty()) return head;
  return head + ": " + fmt::format("{}", fmt::join(parts, "; "));
}

void writeReport(const Report& report, const fs::path& out_dir) {
  AtomicFileSet files;
  files.stageText(out_dir / "report.json", toJson(report, out_dir).dump(2) + "\n");
  files.stageText(out_dir / "junit.xml", junitXml(report));
  files.stageText(out_dir / "report.html", reportHtml(report, out_dir));
  files.stageText(out_dir / "results.csv", resultsCsv(report));
  files.stageText(out_dir / "failures.csv", failuresCsv(report));
  files.commit();
}

}  // namespace rc
