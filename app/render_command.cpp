// `rastercheck render SCENE --backend SPEC --out DIR`: one fixture, one backend, one
// frame directory (written all-or-nothing).
#include <iostream>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/commands.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/resource_estimate.h"

namespace rc {

int renderCommand(const RenderArgs& args) {
  // Parse the SPEC before loading so that a typo costs nothing and exits 2.
  const BackendSpec backend = parseBackendSpec(args.backend);
  const Scene scene = loadScene(args.scene);
  checkResources(scene, rendererKind(backend), ResourceLimits::current());
  const Frame frame = renderWith(backend, scene);
  writeFrameDir(frame, args.out);
  std::cout << fmt::format("{}: {} -> {}\n", scene.name, backend.text, args.out.string());
  return kExitPass;
}

}  // namespace rc
