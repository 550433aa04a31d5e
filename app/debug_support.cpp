// See debug_support.h.
#include "app/debug_support.h"

#include <cstdlib>

#include "app/worker_pool.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;

ScratchDir::ScratchDir(std::string_view prefix) : folder_(prefix), path_(folder_.path()) {}

ScratchDir::~ScratchDir() {
  if (const char* keep = std::getenv("RASTERCHECK_KEEP_SCRATCH"); keep && *keep) folder_.keep();
}

namespace {

// The GL renders of one command (`reduce` tries dozens of candidates, `explain` renders
// each backend once): one `rastercheck worker` per spec, started on first use and kept
// until the process exits, so the driver is loaded and its context created once, and
// frames come back through a pipe instead of frame.exr (a child `render` per candidate
// cost ~0.8 s of start-up, image encoding and decoding for a 48x36 scene). A crash or
// exit of the worker costs that render, as a child's did; the next render starts a new one.
class GlWorkers {
 public:
  Frame render(const fs::path& scene_file, const std::string& spec) {
    RenderRequest request{fs::absolute(scene_file), spec};
    request.pass_frames = true;  // explain compares the driver's shadow maps
    RenderOutcome outcome = std::move(pool_.renderAll({request}).front());
    if (!outcome.ok) {
      // The worker's message usually names the spec already.
      throw BackendError(outcome.error.find(spec) != std::string::npos
                             ? outcome.error
                             : spec + ": " + outcome.error);
    }
    return std::move(outcome.frame);
  }

 private:
  ScratchDir logs_{"workers"};
  WorkerPool pool_{WorkerPool::Options{.log_dir = logs_.path()}};
};

}  // namespace

Frame renderBackend(const BackendSpec& backend, const Scene& scene, const fs::path& scene_file) {
  if (backend.kind == BackendSpec::Kind::Reference) return renderWith(backend, scene);
  static GlWorkers workers;
  return workers.render(scene_file, backend.text);
}

}  // namespace rc
