// libFuzzer target: mesh files through mesh import with its Assimp side in this process
// (fuzz_entries.h, importMeshBytesInProcess, says what that covers and why). Built by the
// fuzz preset, run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>

#include <assimp/ai_assert.h>

#include "fixtures/errors.h"
#include "fixtures/mesh_import.h"
#include "fixtures/mesh_import_assimp.h"
#include "fixtures/texture_io.h"
#include "tests/fuzz/fuzz_entries.h"

// Assimp 5.2 aborts on a failed internal assertion (aiAssertViolation; it has no handler
// to set): a PLY file made TriangulateProcess abort ("numOut != pMesh->mNumFaces",
// tests/fuzz/regressions/mesh/triangulate-assert-abort-in-assimp). In rastercheck the
// child contains that abort (an InputError: "the mesh importer crashed (signal 6...)");
// in this process it would stop fuzzing at once. This definition interposes Assimp's
// (the library calls it through its PLT) and throws instead, which Importer::ReadFile
// turns into a failed import: the target goes on, and our code after Assimp still runs.
namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line) {
  throw std::runtime_error(std::string("Assimp assertion failed: ") + expression + " (" + file +
                           ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace rc::fuzz {

void importMeshBytesInProcess(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::string_view extension = kMeshExtensions[data[0] % std::size(kMeshExtensions)];
  // Skipped here, still imported through the child by the regression replay and the CLI:
  // ASE (Assimp's reader segfaults on malformed files) and X (its reader allocates what a
  // count in the file says, 4 GiB at a time; the child's address-space limit turns that
  // into a refusal, but in this process libFuzzer's malloc limit calls it a finding, and
  // under ASan a failed `new` cannot throw). docs/reliability.md, "Fuzzing".
  if (extension == "ase" || extension == "x") return;
  const std::filesystem::path file = scratchFile("mesh." + std::string(extension));
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    mesh_import_detail::checkBeforeAssimp(file);
    std::string stream;
    writeMeshImport(file.string(), /*materials=*/true,
                    [&](const char* bytes, std::size_t n) { stream.append(bytes, n); });
    TextureCache textures;
    (void)mesh_import_detail::modelFromStream(file, stream, &textures);
  } catch (const InputError& e) {
    checkRefusalMessage(e.what());
  }
}

}  // namespace rc::fuzz

// RC_FUZZ_MESH_THROUGH_CHILD=1 runs an input the way rastercheck does, through the
// importer child: scripts/fuzz.sh replays a finding so to tell a problem inside Assimp that
// the child contains (a one-line refusal: no finding for rastercheck) from one in our code.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool through_child = std::getenv("RC_FUZZ_MESH_THROUGH_CHILD") != nullptr;
  if (through_child) {
    rc::fuzz::importMeshBytes(data, size);
  } else {
    rc::fuzz::importMeshBytesInProcess(data, size);
  }
  return 0;
}
