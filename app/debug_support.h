// What `explain` and `reduce` share: scratch folders, and rendering a fixture file with a
// GL backend in a `rastercheck worker` process kept for the command (as `run` does, so a
// driver crash costs one render and each process picks its own GL driver).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "app/backends.h"
#include "fixtures/frame.h"
#include "fixtures/output_folder.h"
#include "fixtures/scene.h"

namespace rc {

// A fresh folder under the system temporary directory, removed with its contents when
// the object goes (unless RASTERCHECK_KEEP_SCRATCH is set, for debugging the tool: then it
// is kept as rastercheck-PREFIX-PID). A killed process's is removed by the next command
// (fixtures/output_folder.h ScratchFolder).
class ScratchDir {
 public:
  explicit ScratchDir(std::string_view prefix);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  ScratchFolder folder_;
  std::filesystem::path path_;
};

// Renders `scene` with `backend`: the reference in this process, GL in a worker process
// (`rastercheck worker`, one per spec, kept for the rest of this process) that reads
// `scene_file` (which must hold the same scene). Throws BackendError.
Frame renderBackend(const BackendSpec& backend, const Scene& scene,
                    const std::filesystem::path& scene_file);

}  // namespace rc
