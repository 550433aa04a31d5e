// libFuzzer target: texture images through OpenImageIO (texture_io.cpp). Built by the fuzz preset,
// run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rc::fuzz::decodeTextureBytes(data, size);
  return 0;
}
