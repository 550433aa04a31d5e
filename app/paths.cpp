// See paths.h.
#include "app/paths.h"

#include <cstdlib>
#include <system_error>

namespace rc {
namespace fs = std::filesystem;
namespace {

// The installed data folder (share/rastercheck) when this program runs from an installed
// tree: RC_DATA_FROM_CORE is its path relative to the folder of rastercheck-core there
// (cmake/Install.cmake). Empty when it is not there (the build tree).
fs::path installedData() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path data = (self.parent_path() / RC_DATA_FROM_CORE).lexically_normal();
  return fs::is_directory(data / "fixtures", ec) ? data : fs::path();
}

// fixtures/<name> of the installed data folder, else of the source tree this was built from.
fs::path fixturesFile(const char* name) {
  static const fs::path installed = installedData();
  const fs::path root = installed.empty() ? fs::path(RC_SOURCE_DIR) : installed;
  return root / "fixtures" / name;
}

}  // namespace

fs::path defaultCatalogDir() {
  if (const char* env = std::getenv("RASTERCHECK_CATALOG"); env && *env) return env;
  return fixturesFile("scenes");
}

fs::path defaultExpectationsFile() {
  if (const char* env = std::getenv("RASTERCHECK_EXPECTATIONS"); env && *env) return env;
  return fixturesFile("expectations.json");
}

fs::path selfExecutable() { return fs::read_symlink("/proc/self/exe"); }

}  // namespace rc
