// Writes featureCorpusBytes() to the file named by argv[1]. Built twice, against the
// reference sources compiled at -O0 and at -O2, so that test_determinism can compare
// frames across optimisation levels.
#include <cstdio>
#include <fstream>

#include "tests/reference/test_scenes.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT\n", argv[0]);
    return 2;
  }
  const std::string bytes = rc::test::featureCorpusBytes();
  std::ofstream out(argv[1], std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return out ? 0 : 1;
}
