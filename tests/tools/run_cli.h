#ifndef TEXTILE_TESTS_TOOLS_RUN_CLI_H_
#define TEXTILE_TESTS_TOOLS_RUN_CLI_H_

// Runs the real `textile` executable and captures what a user would see.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace textile::testing {

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string ReadAll(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A fresh scratch folder under the build tree, unique per test name.
inline std::filesystem::path Scratch(const std::string& name) {
  const auto d = std::filesystem::path(TEXTILE_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// args: everything after `textile`, already shell-quoted where needed. Runs from the source
// root so that sample paths read as in the README. env: NAME=value settings for the run, or "".
inline CliResult RunTextile(const std::string& args, const std::string& tag = "run",
                            const std::string& env = "") {
  const auto d = std::filesystem::path(TEXTILE_BINARY_DIR) / "test_scratch" / "cli_io";
  std::filesystem::create_directories(d);
  const std::string out = (d / (tag + ".out")).string(), err = (d / (tag + ".err")).string();
  const std::string cmd = std::string("cd '") + TEXTILE_SOURCE_DIR + "' && env " + env +
                          " timeout 120 '" + TEXTILE_EXE + "' " + args + " > '" + out + "' 2> '" +
                          err + "' < /dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadAll(out);
  r.err = ReadAll(err);
  return r;
}

inline int CountLines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// RunTextile with capture files named after the running test, so that tests run in parallel
// by ctest never share them.
inline CliResult Textile(const std::string& args, const std::string& env = "") {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  return RunTextile(args, std::string(test->test_suite_name()) + "." + test->name(), env);
}

// Expects a refusal: exit 2, one line "error: ..." containing `fragment`, nothing on stdout.
inline void ExpectRefused(const CliResult& r, const std::string& fragment, const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << what << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << what << ": " << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << what << ": " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << what << ": '" << fragment << "' not in " << r.err;
  EXPECT_TRUE(r.out.empty()) << what << ": " << r.out;
}

}  // namespace textile::testing

#endif  // TEXTILE_TESTS_TOOLS_RUN_CLI_H_
