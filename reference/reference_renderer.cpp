// The reference renderer's entry points: the input checks only the reference makes, then one
// Renderer (renderer_internal.h) per frame, sample or traced pixel. See reference_renderer.h and
// docs/reference.md.
#include "reference/reference_renderer.h"

#include <cstdint>
#include <string>

#include "fixtures/errors.h"
#include "reference/multipass.h"
#include "reference/renderer_internal.h"

namespace rc {
namespace {

using namespace rc::ref;

constexpr int kMaxImageSide = 16384;
constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 26;

// ---- input validation -------------------------------------------------------------------

// The scene's own consistency is fixtures' validateForRendering(), shared with the GL
// backend; what is checked here is what only the reference limits: its options and the
// image size it allocates.
void validate(const Scene& scene, const ReferenceOptions& options) {
  validateForRendering(scene);
  const std::string label = sceneLabel(scene);
  auto fail = [&](const std::string& what) { throw InputError(label + ": " + what); };
  if (options.subpixel_bits < 0 || options.subpixel_bits > kMaxSubpixelBits)
    fail("reference subpixel bits " + std::to_string(options.subpixel_bits) + " out of range [0, " +
         std::to_string(kMaxSubpixelBits) + "]");
  if (scene.width > kMaxImageSide || scene.height > kMaxImageSide ||
      std::int64_t{scene.width} * scene.height > kMaxImagePixels)
    fail("image " + std::to_string(scene.width) + "x" + std::to_string(scene.height) +
         " outside what the reference renders (1..16384 a side, at most 2^26 pixels)");
}

}  // namespace

Frame renderReference(const Scene& scene, const ReferenceOptions& options) {
  validate(scene, options);
  if (!scene.passes.empty()) {
    PassOutputs passes = renderPasses(scene, options);
    Frame frame = renderReference(passes.frame_scene, options);
    frame.passes = std::move(passes.frames);
    return frame;
  }
  Frame frame =
      scene.state.samples > 1
          ? renderMultisample(scene, options)
          : Renderer(scene, options, PixelRect{0, 0, scene.width, scene.height}, nullptr).run();
  frame.drawn = drawFacts(scene);  // what a comparison of this frame needs
  return frame;
}

std::vector<FragmentTrace> tracePixel(const Scene& scene, const ReferenceOptions& options, int x,
                                      int y_image) {
  validate(scene, options);
  if (x < 0 || x >= scene.width || y_image < 0 || y_image >= scene.height)
    throw InputError(sceneLabel(scene) + ": pixel " + std::to_string(x) + "," +
                     std::to_string(y_image) + " is outside the " + std::to_string(scene.width) +
                     "x" + std::to_string(scene.height) + " image");
  const int y = scene.height - 1 - y_image;  // GL window row
  std::vector<FragmentTrace> trace;
  if (!scene.passes.empty()) {  // the frame pass, its targets drawn first
    const PassOutputs passes = renderPasses(scene, options);
    Renderer renderer(passes.frame_scene, options, PixelRect{x, y, x + 1, y + 1}, &trace);
    renderer.run();
    return trace;
  }
  Renderer renderer(scene, options, PixelRect{x, y, x + 1, y + 1}, &trace);
  renderer.run();
  return trace;
}

std::vector<SortedFragment> abufferPixel(const Scene& scene, ReferenceOptions options, int x,
                                         int y_image) {
  options.abuffer = true;
  validate(scene, options);
  if (x < 0 || x >= scene.width || y_image < 0 || y_image >= scene.height)
    throw InputError(sceneLabel(scene) + ": pixel " + std::to_string(x) + "," +
                     std::to_string(y_image) + " is outside the " + std::to_string(scene.width) +
                     "x" + std::to_string(scene.height) + " image");
  const int y = scene.height - 1 - y_image;
  std::vector<FragmentTrace> trace;
  std::vector<SortedFragment> sorted;
  Renderer renderer(scene, options, PixelRect{x, y, x + 1, y + 1}, &trace, SampleShift{}, &sorted);
  renderer.run();
  return sorted;
}

}  // namespace rc
