// Where the tool finds its catalog and itself (for child processes), built or installed.
#pragma once

#include <filesystem>

namespace rc {

// The catalog: RASTERCHECK_CATALOG when set, else share/rastercheck/fixtures/scenes of the
// installed tree this program runs from, else fixtures/scenes of the source tree it was
// built from (a build tree).
std::filesystem::path defaultCatalogDir();

// The known driver differences run applies by default: RASTERCHECK_EXPECTATIONS when set,
// else fixtures/expectations.json, installed or in the source tree as for the catalog.
std::filesystem::path defaultExpectationsFile();

// The running executable (/proc/self/exe), used to start one child process per render.
std::filesystem::path selfExecutable();

}  // namespace rc
