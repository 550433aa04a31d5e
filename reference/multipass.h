// Multi-pass scenes in the reference (docs/reference.md "Multi-pass scenes"): every pass
// before the frame pass rendered as its own single-pass scene (fixtures' passScene()), its
// target kept as a texture (colour) or a shadow map (depth) with the range another
// conforming implementation's contents may take, and bound into the passes that sample it.
#pragma once

#include <cstdint>
#include <vector>

#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "reference/reference_renderer.h"

namespace rc::ref {

struct PassOutputs {
  std::vector<Frame> frames;  // the passes before the frame pass, in order
  Scene frame_scene;          // the frame pass as a single-pass scene, its inputs bound
};
// `render` draws one single-pass scene (the reference's own renderer, with its channels).
PassOutputs renderPasses(const Scene& scene, const ReferenceOptions& options);

// The range a conforming implementation's stored depth may take at each texel of a depth
// target the reference drew as `frame` (its channels; docs/tolerances.md "Shadow maps"),
// written into map.lo and map.hi (texel rows bottom-up, as map.depth). `optional_cover`
// (ReferenceOptions::optional_cover of the pass, or null): pixels where any depth may be.
void shadowMapRange(const Frame& frame, double clear_depth, ShadowMapData& map,
                    const std::vector<std::uint8_t>* optional_cover = nullptr);

}  // namespace rc::ref
