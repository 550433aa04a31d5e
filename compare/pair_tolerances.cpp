// The tolerance layers of a pair: see pair_tolerances.h.
#include "compare/pair_tolerances.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "compare/compare.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"

namespace rc {
namespace fs = std::filesystem;

ToleranceOverrides fixtureTolerance(const Frame& expected, const Frame& actual) {
  for (const Frame* f : {&expected, &actual}) {
    if (f->drawn.tolerance) return *f->drawn.tolerance;  // set by the renderer in this process
    const auto it = f->meta.find("tolerance");
    if (it == f->meta.end()) continue;
    const std::string backend = f->meta.contains("backend") && f->meta["backend"].is_string()
                                    ? f->meta["backend"].get<std::string>()
                                    : std::string(f == &expected ? "expected" : "actual");
    return toleranceFromJson(*it, fmt::format("frame.json of {}", backend));
  }
  // Frames written before frame.json recorded the block: read the fixture itself.
  if (expected.meta.contains("fixture_file") && expected.meta["fixture_file"].is_string()) {
    const fs::path fixture = expected.meta["fixture_file"].get<std::string>();
    if (fs::exists(fixture)) return loadScene(fixture).tolerance;
  }
  return {};
}

Tolerances pairTolerances(const Frame& expected, const Frame& actual,
                          const ToleranceOverrides& fixture, const CommandLineTolerances& cli) {
  Tolerances tol = tolerancesForFrames(expected, actual);
  applyOverrides(tol, fixture);
  applyOverrides(tol, cli);
  return tol;
}

void parseToleranceArgs(const std::vector<std::string>& args, CommandLineTolerances& out) {
  constexpr const char* kKeys =
      "visibility|depth|shading . warn|fail, depth.slope_factor, shading.relative, "
      "shading.slope_factor, visibility.band";
  for (const std::string& arg : args) {
    const std::size_t dot = arg.find('.');
    const std::size_t eq = arg.find('=');
    if (dot == std::string::npos || eq == std::string::npos || eq < dot) {
      throw InputError(fmt::format(
          "--tolerance {}: expected CLASS.KEY=VALUE, e.g. depth.fail=8 (keys: {})", arg, kKeys));
    }
    const std::string cls = arg.substr(0, dot);
    const std::string key = arg.substr(dot + 1, eq - dot - 1);
    const std::string text = arg.substr(eq + 1);
    double value = 0;
    auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value) ||
        value < 0) {
      throw InputError(fmt::format("--tolerance {}: value must be a non-negative number", arg));
    }
    ToleranceOverrides& t = out.thresholds;
    ClassThresholds* pair = cls == "visibility" ? &t.visibility
                            : cls == "depth"    ? &t.depth
                            : cls == "shading"  ? &t.shading
                                                : nullptr;
    std::optional<double>* single = nullptr;
    if (cls == "depth" && key == "slope_factor") single = &t.depth_slope_factor;
    if (cls == "shading" && key == "relative") single = &out.extra.shading_relative;
    if (cls == "shading" && key == "slope_factor") single = &out.extra.shading_slope_factor;
    if (cls == "visibility" && key == "band") single = &out.extra.band_px;
    if (pair && key == "warn") {
      pair->warn = value;
    } else if (pair && key == "fail") {
      pair->fail = value;
    } else if (single) {
      *single = value;
    } else {
      throw InputError(fmt::format("--tolerance {}: unknown class or key (keys: {})", arg, kKeys));
    }
  }
  // A warn above its fail is refused now, before any command renders or reads anything.
  Tolerances check;
  applyOverrides(check, out);
}

}  // namespace rc
