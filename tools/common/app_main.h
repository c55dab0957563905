#ifndef TEXTILE_TOOLS_COMMON_APP_MAIN_H_
#define TEXTILE_TOOLS_COMMON_APP_MAIN_H_

// The whole of a `textile` process, shared by the executables that register subcommands
// (`textile`: tools/main.cc; `textile-bench`: bench/main.cc):
//   int main(int argc, char** argv) { return textile::cli::AppMain(argc, argv); }
// Hands a forwarded subcommand to its executable (common/forward_command.h); otherwise sets up
// the process (SIGPIPE, signal cleanup of staged files, BLAS kernels), builds the `textile` app
// from the subcommands registered in this executable (AddCommand), parses argv, runs the chosen
// subcommand and maps failures to one line on stderr and the exit codes of docs/spec/cli.md.

namespace textile::cli {

int AppMain(int argc, char** argv);

}  // namespace textile::cli

#endif  // TEXTILE_TOOLS_COMMON_APP_MAIN_H_
