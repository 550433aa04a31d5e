// libFuzzer target: fixture files (the loader: JSON, inline meshes, generators, files it names).
// Built by the fuzz preset, run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rc::fuzz::loadFixtureBytes(data, size);
  return 0;
}
