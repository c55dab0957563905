#ifndef TEXTILE_TOOLS_COMMON_FORWARD_COMMAND_H_
#define TEXTILE_TOOLS_COMMON_FORWARD_COMMAND_H_

// A subcommand served by another executable installed beside this one: `textile bench ARGS`
// runs `textile-bench ARGS` (tools/cmd_bench.cc), so that the benchmarks are not linked into the
// CLI. The subcommand still registers itself (AddCommand) to be listed in `textile --help`; its
// arguments are never parsed here, the other executable answers them (help and errors included).
//   const bool kRegistered =
//       AddCommand(90, RegisterBench) && ForwardCommand("bench", "textile-bench");

#include <string>

namespace textile::cli {

// `textile COMMAND ARGS...` is to exec EXECUTABLE (a file name, looked up in the folder of the
// running executable) with ARGS.
bool ForwardCommand(const std::string& command, const std::string& executable);

// If argv[1] is a forwarded command, replaces this process with its executable and the arguments
// after argv[1] (`--help COMMAND ...` becomes `--help ...`). Returns false if argv[1] is no
// forwarded command; if the executable cannot be
// run (missing, not executable), prints one line "error: ..." on stderr and returns true: the
// caller exits with kExitBadInput.
bool RunForwardedCommand(int argc, char** argv);

}  // namespace textile::cli

#endif  // TEXTILE_TOOLS_COMMON_FORWARD_COMMAND_H_
