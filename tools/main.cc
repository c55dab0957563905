// textile: the command line. Each subcommand lives in tools/cmd_<name>.cc; the process around
// them (parsing, the exit codes of docs/spec/cli.md) is tools/common/app_main.cc.

#include "common/app_main.h"

int main(int argc, char** argv) { return textile::cli::AppMain(argc, argv); }
