// textile-bench: the benchmarks of docs/spec/benchmarks.md, apart from the `textile` CLI so that
// its studies are not shipped in every build of the tool. `textile-bench ARGS` is
// `textile bench ARGS` (tools/cmd_bench.cc forwards to this executable): the same flags, help,
// output and exit codes, since the one command here is bench/bench_command.cc's.

#include <vector>

#include "common/app_main.h"

int main(int argc, char** argv) {
  std::vector<char*> args = {argv[0], const_cast<char*>("bench")};
  args.insert(args.end(), argv + 1, argv + argc);
  args.push_back(nullptr);
  return textile::cli::AppMain(argc + 1, args.data());
}
