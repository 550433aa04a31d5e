// Backend SPEC strings of the GL backend ("gl:egl:llvmpipe", ...): parsing and printing.
#include <charconv>

#include <fmt/format.h>

#include "fixtures/errors.h"
#include "gl_backend/gl_backend.h"

namespace rc {
namespace {

constexpr const char* kValidGlSpecs =
    "gl, gl:egl, gl:egl:llvmpipe, gl:egl:softpipe, gl:osmesa, gl:osmesa:llvmpipe, "
    "gl:osmesa:softpipe, gl:egl-device, gl:egl-device:N";

[[noreturn]] void unknownSpec(std::string_view spec) {
  throw InputError(fmt::format("unknown GL backend '{}' (valid: {})", spec, kValidGlSpecs));
}

}  // namespace

GlSpec parseGlSpec(std::string_view spec) {
  GlSpec out;
  if (spec == "gl") return out;
  if (spec.substr(0, 3) != "gl:") unknownSpec(spec);
  const std::string_view rest = spec.substr(3);
  const std::size_t colon = rest.find(':');
  const std::string_view platform = rest.substr(0, colon);
  const bool has_arg = colon != std::string_view::npos;
  const std::string_view arg = has_arg ? rest.substr(colon + 1) : std::string_view{};

  if (platform == "egl" || platform == "osmesa") {
    out.platform = platform == "egl" ? GlSpec::Platform::EglSurfaceless : GlSpec::Platform::OSMesa;
    if (has_arg) {
      if (arg != "llvmpipe" && arg != "softpipe") unknownSpec(spec);
      out.driver = std::string(arg);
    }
    return out;
  }
  if (platform == "egl-device") {
    out.platform = GlSpec::Platform::EglDevice;
    if (has_arg) {
      int index = -1;
      const auto [end, ec] = std::from_chars(arg.data(), arg.data() + arg.size(), index);
      if (arg.empty() || ec != std::errc() || end != arg.data() + arg.size() || index < 0)
        unknownSpec(spec);
      out.device = index;
    }
    return out;
  }
  unknownSpec(spec);
}

std::string toString(const GlSpec& spec) {
  switch (spec.platform) {
    case GlSpec::Platform::EglSurfaceless:
      return spec.driver.empty() ? "gl" : "gl:egl:" + spec.driver;
    case GlSpec::Platform::OSMesa:
      return spec.driver.empty() ? "gl:osmesa" : "gl:osmesa:" + spec.driver;
    case GlSpec::Platform::EglDevice:
      return spec.device < 0 ? "gl:egl-device" : fmt::format("gl:egl-device:{}", spec.device);
  }
  return "gl";
}

}  // namespace rc
