// The command-line front end: declares every subcommand and option with its help text
// (CLI11), calls the command, and maps errors to one line and an exit code.
#pragma once

namespace rc {
int runCli(int argc, char** argv);
}
