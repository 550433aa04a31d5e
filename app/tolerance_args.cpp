// Command-line tolerance overrides (`--tolerance depth.fail=8`), applied after the
// fixture's own "tolerance" block.
#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "app/commands.h"
#include "fixtures/errors.h"
#include "fixtures/scene.h"

namespace rc {

void parseToleranceArgs(const std::vector<std::string>& args, ToleranceOverrides& out) {
  for (const std::string& arg : args) {
    const std::size_t dot = arg.find('.');
    const std::size_t eq = arg.find('=');
    if (dot == std::string::npos || eq == std::string::npos || eq < dot) {
      throw InputError(fmt::format(
          "--tolerance {}: expected CLASS.KEY=VALUE, e.g. depth.fail=8 (classes: visibility, "
          "depth, shading; keys: warn, fail, and depth.slope_factor)",
          arg));
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
    ClassThresholds* t = cls == "visibility" ? &out.visibility
                         : cls == "depth"    ? &out.depth
                         : cls == "shading"  ? &out.shading
                                             : nullptr;
    if (t && key == "warn") {
      t->warn = value;
    } else if (t && key == "fail") {
      t->fail = value;
    } else if (cls == "depth" && key == "slope_factor") {
      out.depth_slope_factor = value;
    } else {
      throw InputError(fmt::format("--tolerance {}: unknown class or key", arg));
    }
  }
}

}  // namespace rc
