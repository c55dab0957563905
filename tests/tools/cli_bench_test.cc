// `textile bench` runs textile-bench (bench/), found beside `textile`: the same output, help and
// errors as textile-bench itself; one line and exit 2 when textile-bench is missing. What the
// benchmarks write is tested in cli_law_test.cc (CliBench.*).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "run_cli.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::CountLines;
using testing::ReadAll;
using testing::Scratch;
using testing::Textile;

// Runs `exe args` from the source root, as RunTextile runs textile.
CliResult RunProgram(const fs::path& exe, const std::string& args, const std::string& tag) {
  const fs::path d = Scratch("CliBenchForward." + tag);
  const std::string cmd = std::string("cd '") + TEXTILE_SOURCE_DIR + "' && timeout 120 '" +
                          exe.string() + "' " + args + " > '" + (d / "out").string() + "' 2> '" +
                          (d / "err").string() + "' < /dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadAll(d / "out");
  r.err = ReadAll(d / "err");
  return r;
}

TEST(CliBenchForward, TextileBenchIsBesideTextile) {
  EXPECT_EQ(fs::path(TEXTILE_BENCH_EXE).parent_path(), fs::path(TEXTILE_EXE).parent_path());
}

TEST(CliBenchForward, ListIsTextileBenchs) {
  const CliResult via = Textile("bench --list");
  const CliResult direct = RunProgram(TEXTILE_BENCH_EXE, "--list", "list");
  ASSERT_EQ(direct.exit_code, 0) << direct.err;
  EXPECT_EQ(via.exit_code, 0) << via.err;
  EXPECT_NE(direct.out.find("hinge-curve\t"), std::string::npos) << direct.out;
  EXPECT_EQ(via.out, direct.out);
  EXPECT_EQ(via.err, direct.err);
}

// The help names `textile bench` either way; its first line (the description) is the one
// `textile --help` lists for bench (tools/cmd_bench.cc repeats bench/bench_command.cc's).
TEST(CliBenchForward, HelpIsTextileBenchsAndTextileListsItsDescription) {
  const CliResult direct = RunProgram(TEXTILE_BENCH_EXE, "--help", "help");
  ASSERT_EQ(direct.exit_code, 0) << direct.err;
  for (const char* args : {"bench --help", "bench -h", "--help bench"}) {
    const CliResult via = Textile(args);
    EXPECT_EQ(via.exit_code, 0) << args;
    EXPECT_EQ(via.out, direct.out) << args;
  }
  EXPECT_NE(direct.out.find("Usage: textile bench [OPTIONS] [names...]"), std::string::npos)
      << direct.out;
  const std::string description = direct.out.substr(0, direct.out.find('\n'));
  ASSERT_FALSE(description.empty()) << direct.out;
  const CliResult top = Textile("--help");
  const size_t at = top.out.find("\n  bench ");
  ASSERT_NE(at, std::string::npos) << top.out;
  const std::string line = top.out.substr(at + 1, top.out.find('\n', at + 1) - at - 1);
  EXPECT_EQ(line.substr(line.size() - description.size()), description) << line;
}

// Arguments reach textile-bench as given: an empty one and one after "--" included.
TEST(CliBenchForward, ErrorsAreTextileBenchs) {
  const fs::path out = Scratch("CliBenchForward.ErrorsOut");
  const std::string o = " -o '" + out.string() + "'";
  for (const std::string& args :
       {"no-such-benchmark" + o, "''" + o, "--fast" + o, "-- --list" + o}) {
    const CliResult via = Textile("bench " + args);
    const CliResult direct = RunProgram(TEXTILE_BENCH_EXE, args, "errors");
    EXPECT_EQ(via.exit_code, 2) << args;
    EXPECT_EQ(direct.exit_code, 2) << args;
    EXPECT_EQ(CountLines(via.err), 1) << via.err;
    EXPECT_EQ(via.err, direct.err) << args;
    EXPECT_TRUE(via.out.empty()) << via.out;
  }
}

TEST(CliBenchForward, MissingTextileBenchIsOneLineAndExit2) {
  const fs::path d = Scratch("CliBenchForward.Missing");
  fs::copy_file(TEXTILE_EXE, d / "textile");
  const CliResult r = RunProgram(d / "textile", "bench --list", "missing");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find((d / "textile-bench").string()), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  // The other commands do not need it.
  EXPECT_EQ(RunProgram(d / "textile", "law --help", "missing_law").exit_code, 0);
}

}  // namespace
}  // namespace textile
