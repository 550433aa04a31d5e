// See debug_support.h.
#include "app/debug_support.h"

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/format.h>

#include "app/paths.h"
#include "app/worker_pool.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"

namespace rc {
namespace fs = std::filesystem;

ScratchDir::ScratchDir(std::string_view prefix) : folder_(prefix), path_(folder_.path()) {}

ScratchDir::~ScratchDir() {
  if (const char* keep = std::getenv("RASTERCHECK_KEEP_SCRATCH"); keep && *keep) folder_.keep();
}

Job renderJob(const fs::path& scene_file, const std::string& spec, const fs::path& out_dir) {
  fs::path log = out_dir;
  log += ".log";
  return Job{{selfExecutable().string(), "render", scene_file.string(), "--backend", spec, "--out",
              out_dir.string()},
             log};
}

std::string childFailure(const Job& job, const std::vector<std::string>& also_strip) {
  std::ifstream in(job.log);
  std::string last = lastErrorLine(
      std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  for (const std::string& prefix : also_strip) {
    if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  }
  if (!job.signal_name.empty())
    return fmt::format("crashed ({}){}", job.signal_name, last.empty() ? "" : ": " + last);
  return last.empty() ? fmt::format("exited with code {}", job.exit_code) : last;
}

Frame renderInChild(const fs::path& scene_file, const std::string& spec, const fs::path& out_dir) {
  std::vector<Job> jobs{renderJob(scene_file, spec, out_dir)};
  runJobs(jobs, 1);
  if (jobs[0].exit_code != 0) {
    const std::string why = childFailure(jobs[0]);
    // The child's own message usually names the spec already.
    throw BackendError(why.find(spec) != std::string::npos ? why : spec + ": " + why);
  }
  return readFrameDir(out_dir);
}

Frame renderBackend(const BackendSpec& backend, const Scene& scene, const fs::path& scene_file,
                    const fs::path& out_dir) {
  if (backend.kind == BackendSpec::Kind::Reference) return renderWith(backend, scene);
  return renderInChild(scene_file, backend.text, out_dir);
}

}  // namespace rc
