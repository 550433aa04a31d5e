// Backend SPEC parsing and dispatch: see backends.h.
#include "app/backends.h"

#include <charconv>
#include <chrono>

#include <fmt/format.h>

#include "app/version.h"
#include "compare/pair_images.h"
#include "compare/tolerances.h"
#include "fixtures/errors.h"

namespace rc {
namespace {

constexpr const char* kValidSpecs =
    "ref, ref:painter, ref:abuffer, ref:subpixel=N, gl, gl:egl[:llvmpipe|:softpipe|:zink], "
    "gl:osmesa[:llvmpipe|:softpipe], gl:egl-device[:N], a gl SPEC followed by @MESA_LIB_DIR";

ReferenceOptions parseReferenceSpec(std::string_view spec) {
  ReferenceOptions opts;
  std::string_view rest = spec.substr(3);  // after "ref"
  while (!rest.empty()) {
    if (rest.front() != ':') break;
    rest.remove_prefix(1);
    const std::size_t end = rest.find(':');
    const std::string_view part = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end);
    if (part == "painter") {
      opts.force_painter = true;
    } else if (part == "abuffer") {
      opts.abuffer = true;
    } else if (part.substr(0, 9) == "subpixel=") {
      const std::string_view num = part.substr(9);
      int bits = -1;
      auto [ptr, ec] = std::from_chars(num.data(), num.data() + num.size(), bits);
      if (ec != std::errc() || ptr != num.data() + num.size() || bits < 0 || bits > 12) {
        throw InputError(
            fmt::format("backend '{}': subpixel bits must be an integer in [0, 12]", spec));
      }
      opts.subpixel_bits = bits;
    } else {
      throw InputError(fmt::format("backend '{}': unknown reference option '{}' (valid: {})", spec,
                                   part, kValidSpecs));
    }
  }
  if (!rest.empty())
    throw InputError(fmt::format("unknown backend '{}' (valid: {})", spec, kValidSpecs));
  return opts;
}

}  // namespace

BackendSpec parseBackendSpec(std::string_view spec) {
  BackendSpec out;
  out.text = std::string(spec);
  if (spec == "ref" || spec.substr(0, 4) == "ref:") {
    out.kind = BackendSpec::Kind::Reference;
    out.reference = parseReferenceSpec(spec);
    return out;
  }
  if (spec == "gl" || spec.substr(0, 3) == "gl:") {
    out.kind = BackendSpec::Kind::Gl;
    out.gl = parseGlSpec(spec);
    return out;
  }
  throw InputError(fmt::format("unknown backend '{}' (valid: {})", spec, kValidSpecs));
}

Frame renderWith(const BackendSpec& backend, const Scene& scene, bool pass_frames) {
  const auto start = std::chrono::steady_clock::now();
  Frame frame = backend.kind == BackendSpec::Kind::Reference
                    ? renderReference(scene, backend.reference)
                    : renderGl(scene, backend.gl, pass_frames);
  // The reference draws its passes' frames whatever is asked (it samples them itself).
  if (!pass_frames) frame.passes.clear();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json& m = frame.meta;
  m["tool"] = {{"name", "rastercheck"}, {"version", kVersion}};
  m["backend"] = backend.text;
  m["fixture"] = scene.name;
  if (!scene.source.empty()) m["fixture_file"] = scene.source.string();
  if (!scene.tags.empty()) m["tags"] = scene.tags;
  m["width"] = scene.width;
  m["height"] = scene.height;
  m["clear_depth"] = scene.clear_depth;
  // (The formats and texture facts are frame.drawn, set by the renderer.)
  m["state"] = stateJson(scene.state);     // what expected failures are scoped by
  m["color_digest"] = colorDigest(frame);  // tells `compare` color.png shows this frame
  // Every plane's bits (colour, depth, ids, stencil, samples): what `scripts/same-bits.sh`
  // compares between two runs (the isolation check: one fixture, two orders).
  m["frame_digest"] = frameDigest(frame);
  if (!m.contains("subpixel_bits")) m["subpixel_bits"] = backend.reference.subpixel_bits;
  m["time_ms"] = ms;
  return frame;
}

}  // namespace rc
