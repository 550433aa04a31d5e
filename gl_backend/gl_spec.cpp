// Backend SPEC strings of the GL backend ("gl:egl:llvmpipe", "gl:egl:zink@/opt/mesa/lib",
// ...): parsing and printing.
#include <charconv>

#include <fmt/format.h>

#include "fixtures/errors.h"
#include "gl_backend/gl_backend.h"
#include "gl_backend/mesa_libraries.h"

namespace rc {
namespace {

constexpr const char* kValidGlSpecs =
    "gl, gl:egl, gl:egl:llvmpipe, gl:egl:softpipe, gl:egl:zink, gl:osmesa, gl:osmesa:llvmpipe, "
    "gl:osmesa:softpipe, gl:egl-device, gl:egl-device:N, each optionally @MESA_LIB_DIR";

[[noreturn]] void unknownSpec(std::string_view spec) {
  throw InputError(fmt::format("unknown GL backend '{}' (valid: {})", spec, kValidGlSpecs));
}

}  // namespace

GlSpec parseGlSpec(std::string_view spec) {
  GlSpec out = parseGlSpecSyntax(spec);
  gl::checkMesaDir(spec, out);
  return out;
}

GlSpec parseGlSpecSyntax(std::string_view spec) {
  // "SPEC@DIR": everything after the first '@' is the Mesa folder (paths may hold ':').
  const std::size_t at = spec.find('@');
  if (at != std::string_view::npos) {
    if (at + 1 == spec.size()) unknownSpec(spec);
    GlSpec out;
    try {
      out = parseGlSpecSyntax(spec.substr(0, at));
    } catch (const InputError&) {
      unknownSpec(spec);  // name the whole SPEC, not the part before '@'
    }
    out.mesa_dir = std::string(spec.substr(at + 1));
    return out;
  }
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
      // zink is a Gallium driver of Mesa's EGL; OSMesa's library has only the software
      // rasterizers.
      const bool zink = arg == "zink" && out.platform == GlSpec::Platform::EglSurfaceless;
      if (arg != "llvmpipe" && arg != "softpipe" && !zink) unknownSpec(spec);
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
  const std::string mesa = spec.mesa_dir.empty() ? "" : "@" + spec.mesa_dir;
  switch (spec.platform) {
    case GlSpec::Platform::EglSurfaceless:
      return (spec.driver.empty() ? "gl" : "gl:egl:" + spec.driver) + mesa;
    case GlSpec::Platform::OSMesa:
      return (spec.driver.empty() ? "gl:osmesa" : "gl:osmesa:" + spec.driver) + mesa;
    case GlSpec::Platform::EglDevice:
      return (spec.device < 0 ? "gl:egl-device" : fmt::format("gl:egl-device:{}", spec.device)) +
             mesa;
  }
  return "gl" + mesa;
}

}  // namespace rc
