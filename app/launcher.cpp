// rastercheck as users start it: answers `--version` before any heavy library is loaded,
// and hands every other command to rastercheck-core beside it (execv, same arguments).
// rastercheck-core loads OpenImageIO's ~260 shared libraries only when a command touches
// an image (fixtures/image_io.h), but it still links EGL and the project's libraries; this
// program links only the C and C++ runtimes. It must stay that way: no project library here.
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>

#include "app/version.h"

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "--version") == 0) {
    std::printf("rastercheck %s\n", rc::kVersion);
    return 0;
  }
  // The core is beside the launcher in the build tree; installed, the launcher is in
  // <prefix>/bin and the core in <prefix>/libexec/rastercheck (RC_CORE_FROM_LAUNCHER: the
  // relative path, so that an installed tree can be moved).
  char self[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  std::string core = "rastercheck-core";
  if (n > 0) {
    std::string dir(self, static_cast<std::size_t>(n));
    dir.resize(dir.rfind('/') + 1);
    core = dir + "rastercheck-core";
    if (::access(core.c_str(), X_OK) != 0) core = dir + RC_CORE_FROM_LAUNCHER "/rastercheck-core";
  }
  ::execv(core.c_str(), argv);
  std::fprintf(stderr, "rastercheck: internal error: cannot start %s: %s\n", core.c_str(),
               std::strerror(errno));
  return 3;  // kExitBackend: the tool itself could not run
}
