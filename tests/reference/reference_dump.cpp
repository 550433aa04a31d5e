// Lists the determinism corpus (corpus.h) as one hash per frame. Built three times:
// against the normal libraries (reference_dump), against the reference AND fixtures
// sources compiled at -O0 (reference_dump_O0), and against the reference compiled at -O2
// with the release fixtures library (reference_dump_O2), so that test_determinism can
// compare frames across optimisation levels, loader and scene logic included.
//   reference_dump [--bench] [--out FILE] [FIXTURE|DIR...]
// --bench adds the benchmark scenes; DIR means every *.json under it. Before/after check
// of an optimisation: run it before and after, then diff the two listings.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/reference/corpus.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  bool bench = false;
  std::string output;
  std::vector<fs::path> fixtures;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--bench") {
      bench = true;
    } else if (arg == "--out" && i + 1 < argc) {
      output = argv[++i];
    } else if (arg.starts_with("-")) {
      std::fprintf(stderr, "usage: %s [--bench] [--out FILE] [FIXTURE|DIR...]\n", argv[0]);
      return 2;
    } else if (fs::is_directory(arg)) {
      for (const fs::path& f : rc::test::fixtureFiles(arg)) fixtures.push_back(f);
    } else {
      fixtures.emplace_back(arg);
    }
  }
  try {
    const std::string listing = rc::test::corpusHashes(fixtures, bench);
    if (output.empty()) {
      std::fwrite(listing.data(), 1, listing.size(), stdout);
      return 0;
    }
    std::ofstream out(output, std::ios::binary);
    out << listing;
    return out ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "reference_dump: %s\n", e.what());
    return 1;
  }
}
