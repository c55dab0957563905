// textile bench: runs textile-bench, the benchmarks of docs/spec/benchmarks.md, installed beside
// textile (bench/). Listed here for `textile --help`; the flags, help and output are
// textile-bench's (bench/bench_command.cc).

#include "common/cli.h"
#include "common/forward_command.h"

namespace textile::cli {
namespace {

void RegisterBench(CLI::App& app) {
  // The same description as bench/bench_command.cc's, for `textile --help`.
  app.add_subcommand("bench", "Run the named benchmarks (all by default): CSV + PNG each");
}

const bool kRegistered = AddCommand(90, RegisterBench) && ForwardCommand("bench", "textile-bench");

}  // namespace
}  // namespace textile::cli
