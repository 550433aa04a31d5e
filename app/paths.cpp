// See paths.h.
#include "app/paths.h"

#include <cstdlib>

namespace rc {

std::filesystem::path defaultCatalogDir() {
  if (const char* env = std::getenv("RASTERCHECK_CATALOG"); env && *env) return env;
  return std::filesystem::path(RC_SOURCE_DIR) / "fixtures" / "scenes";
}

std::filesystem::path defaultExpectationsFile() {
  if (const char* env = std::getenv("RASTERCHECK_EXPECTATIONS"); env && *env) return env;
  return std::filesystem::path(RC_SOURCE_DIR) / "fixtures" / "expectations.json";
}

std::filesystem::path selfExecutable() { return std::filesystem::read_symlink("/proc/self/exe"); }

}  // namespace rc
