// Command-line tolerance overrides (`--tolerance depth.fail=8`), applied after the
// fixture's own "tolerance" block.
#include <charconv>
#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "app/commands.h"
#include "compare/tolerances.h"
#include "fixtures/errors.h"

namespace rc {

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
