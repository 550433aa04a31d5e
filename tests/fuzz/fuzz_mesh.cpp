// libFuzzer target: mesh files through Assimp (mesh_import.cpp). Built by the fuzz preset, run by
// scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rc::fuzz::importMeshBytes(data, size);
  return 0;
}
