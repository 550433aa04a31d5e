// `rastercheck explain SCENE --pixel X,Y [--backends SPEC,...] [--json]`: arguments,
// renders and output. The pixel history and its story are debug/pixel_history.h; here the
// reference frame is rendered in this process and each listed backend's in a child
// process (GL), and the document is printed as JSON or as the story.
#include <algorithm>
#include <charconv>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/backends.h"
#include "app/commands.h"
#include "app/debug_support.h"
#include "compare/compare.h"
#include "compare/pair_tolerances.h"
#include "debug/pixel_history.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/resource_estimate.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::ordered_json;

glm::ivec2 parsePixel(const std::string& text) {
  const std::size_t comma = text.find(',');
  glm::ivec2 p(0);
  auto parse = [](std::string_view s, int& out) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
  };
  if (comma == std::string::npos || !parse(std::string_view(text).substr(0, comma), p.x) ||
      !parse(std::string_view(text).substr(comma + 1), p.y))
    throw InputError(
        fmt::format("--pixel '{}': expected X,Y (two integers, image coordinates, "
                    "origin top-left)",
                    text));
  return p;
}

}  // namespace

int explainCommand(const ExplainArgs& args) {
  // Usage first: a bad SPEC or pixel costs nothing.
  const BackendSpec reference = parseBackendSpec(args.reference);
  if (reference.kind != BackendSpec::Kind::Reference)
    throw InputError(
        fmt::format("--reference {}: must be a reference SPEC (ref, ref:painter, "
                    "ref:abuffer, ref:subpixel=N)",
                    args.reference));
  std::vector<BackendSpec> backends;
  for (const std::string& s : args.backends) backends.push_back(parseBackendSpec(s));
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  const glm::ivec2 pixel = parsePixel(args.pixel);
  const Scene scene = loadScene(args.scene);
  checkResources(scene, RendererKind::Reference, ResourceLimits::current());
  for (const std::string& spec : args.backends)
    if (parseBackendSpec(spec).kind == BackendSpec::Kind::Gl)
      checkResources(scene, RendererKind::Gl, ResourceLimits::current());
  if (pixel.x < 0 || pixel.y < 0 || pixel.x >= scene.width || pixel.y >= scene.height)
    throw InputError(fmt::format("{}: pixel {},{} is outside the {}x{} image", args.scene.string(),
                                 pixel.x, pixel.y, scene.width, scene.height));

  const Frame frame = renderWith(reference, scene);
  const std::size_t i = frame.index(pixel.x, pixel.y);
  PixelQuery query;
  query.fixture_file = args.scene.string();
  query.reference_spec = reference.text;
  query.options = reference.reference;
  query.x = pixel.x;
  query.y = pixel.y;
  // The A-buffer's sorted list when ref:abuffer is the reference or among the backends.
  query.abuffer = std::any_of(backends.begin(), backends.end(), [](const BackendSpec& b) {
    return b.kind == BackendSpec::Kind::Reference && b.reference.abuffer;
  });
  Json doc = pixelHistory(scene, query, frame);

  // Each backend renders its own frame (GL in a worker process) and is compared with the
  // reference frame as `compare` would.
  Json out_backends = Json::object();
  bool backend_failed = false;
  if (!backends.empty()) {
    for (std::size_t b = 0; b < backends.size(); ++b) {
      try {
        const Frame other = renderBackend(backends[b], scene, fs::absolute(args.scene));
        checkSameSize(frame, other, args.scene, backends[b].text);
        out_backends[backends[b].text] = backendPixel(
            backends[b].text, frame, other, pairTolerances(frame, other, scene.tolerance, cli), i);
        if (!scene.passes.empty())
          out_backends[backends[b].text]["shadow_texels"] = backendShadowTexels(doc, other);
      } catch (const BackendError& e) {
        backend_failed = true;
        out_backends[backends[b].text] = {{"backend", backends[b].text}, {"error", e.what()}};
      }
    }
  }
  doc["backends"] = out_backends;

  if (args.json) {
    std::cout << doc.dump(2) << '\n';
  } else {
    std::cout << pixelStory(doc);
  }
  return backend_failed ? kExitBackend : kExitPass;
}

}  // namespace rc
