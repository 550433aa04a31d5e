// Where the installed tool finds its catalog and itself (for child processes).
#pragma once

#include <filesystem>

namespace rc {

// fixtures/scenes of the source tree this binary was built from, unless
// RASTERCHECK_CATALOG names another folder.
std::filesystem::path defaultCatalogDir();

// The running executable (/proc/self/exe), used to start one child process per render.
std::filesystem::path selfExecutable();

}  // namespace rc
