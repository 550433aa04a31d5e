// libFuzzer target: texture images through OpenImageIO (image_io_module.cpp). Built by the fuzz
// preset, run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "fixtures/image_io.h"
#include "tests/fuzz/fuzz_entries.h"

// The decoder lives in the image module (fixtures/image_io.h): loaded before the first
// input, so that libFuzzer counts its coverage from the start.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  (void)rc::image_io::functions();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rc::fuzz::decodeTextureBytes(data, size);
  return 0;
}
