// rastercheck: the command. Everything happens in the libraries; see app/cli.cpp.
#include "app/cli.h"

int main(int argc, char** argv) { return rc::runCli(argc, argv); }
