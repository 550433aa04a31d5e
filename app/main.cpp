// rastercheck: the command. Everything happens in the libraries; see app/cli.cpp.
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "app/cli.h"

int main(int argc, char** argv) {
  const int code = rc::runCli(argc, argv);
  // Every output file is complete and renamed into place by now. Skipping static
  // destructors (image-library thread pools, plugin registries) saves ~10 ms per process;
  // the kernel frees memory faster than destructors do.
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
}
