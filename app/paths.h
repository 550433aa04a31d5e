// Where the installed tool finds its catalog and itself (for child processes).
#pragma once

#include <filesystem>

namespace rc {

// fixtures/scenes of the source tree this binary was built from, unless
// RASTERCHECK_CATALOG names another folder.
std::filesystem::path defaultCatalogDir();

// The known driver differences run applies by default: fixtures/expectations.json of the
// source tree, unless RASTERCHECK_EXPECTATIONS names another file.
std::filesystem::path defaultExpectationsFile();

// The running executable (/proc/self/exe), used to start one child process per render.
std::filesystem::path selfExecutable();

}  // namespace rc
