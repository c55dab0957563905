// The bad-input corpus (tests/bad_inputs/, issue 9): every case of every manifest
// tests/bad_inputs/*.cases runs through the real `textile` executable, which must refuse it the
// way docs/spec/cli.md promises:
//   - it exits (no signal, no hang) with the expected code (2 bad input, 3 computation failed);
//   - stderr is exactly one line, starting with "error: " and containing the expected fragment;
//   - stdout is empty (unless the case allows output);
//   - its output folder {out} holds no file afterwards (a pre-filled file must be unchanged).
// The manifest format is described in tests/bad_inputs/README.md. Manifests are read when the
// test runs, so a new line needs no rebuild.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <csignal>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "run_cli.h"

namespace textile::testing {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(TEXTILE_SOURCE_DIR) / "tests" / "bad_inputs";
// A watchdog, not a timing: a refusal takes milliseconds, so a case still running after this
// long is hanging (generous for sanitizer builds on a loaded machine).
constexpr auto kHangAfter = std::chrono::seconds(120);
// What a pre-filled output holds before the run; it must still hold exactly this afterwards.
const std::string kPrefilled = "a good file from an earlier run\n";

struct Case {
  std::string manifest;  // file name, for messages
  int line = 0;
  std::string name;
  int exit_code = 0;
  std::string fragment;
  std::vector<std::string> args;  // after substitution
  std::vector<std::string> prefill;  // names of files put into {out} before the run
  bool stdout_allowed = false;
  std::string xfail;  // reason, when the case is known to fail (a bug to fix elsewhere)
};

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  for (size_t k = s.find(from); k != std::string::npos; k = s.find(from, k + to.size())) {
    s.replace(k, from.size(), to);
  }
  return s;
}

fs::path OutDir(const std::string& case_name) {
  return fs::path(TEXTILE_BINARY_DIR) / "test_scratch" / "bad_inputs" / case_name;
}

// Splits at blanks; "..." groups (and "" is an empty argument); \xHH is the byte HH (for
// arguments that are not valid text). No other shell syntax.
bool SplitArgs(const std::string& text, std::vector<std::string>* args, std::string* why) {
  std::string cur;
  bool in_arg = false, quoted = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\\' && i + 3 < text.size() && text[i + 1] == 'x' &&
        std::isxdigit(static_cast<unsigned char>(text[i + 2])) &&
        std::isxdigit(static_cast<unsigned char>(text[i + 3]))) {
      cur += static_cast<char>(std::stoi(text.substr(i + 2, 2), nullptr, 16));
      in_arg = true;
      i += 3;
    } else if (c == '"') {
      quoted = !quoted;
      in_arg = true;
    } else if ((c == ' ' || c == '\t') && !quoted) {
      if (in_arg) args->push_back(cur);
      cur.clear();
      in_arg = false;
    } else {
      cur += c;
      in_arg = true;
    }
  }
  if (quoted) {
    *why = "unbalanced \"";
    return false;
  }
  if (in_arg) args->push_back(cur);
  return true;
}

// Parses one manifest line; false with *why for a malformed one.
bool ParseCase(const std::string& manifest, int line_no, const std::string& line, Case* c,
               std::string* why) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, '|');) fields.push_back(Trim(f));
  if (fields.size() < 4 || fields.size() > 5) {
    *why = "expected NAME | EXIT | FRAGMENT | ARGS [| FLAGS]";
    return false;
  }
  c->manifest = manifest;
  c->line = line_no;
  c->name = fields[0];
  if (c->name.empty() || c->name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_.") !=
                             std::string::npos) {
    *why = "name: use a-z, 0-9, '-', '_', '.'";
    return false;
  }
  if (fields[1] != "2" && fields[1] != "3") {
    *why = "exit code: 2 (bad input) or 3 (computation failed)";
    return false;
  }
  c->exit_code = std::stoi(fields[1]);
  c->fragment = fields[2];
  if (c->fragment.empty()) {
    *why = "fragment: say what the message must contain";
    return false;
  }
  std::string args = fields[3];
  args = Replace(args, "{files}", (kCorpus / "files").string());
  args = Replace(args, "{src}", TEXTILE_SOURCE_DIR);
  args = Replace(args, "{out}", OutDir(c->name).string());
  if (!SplitArgs(args, &c->args, why) || c->args.empty()) {
    if (why->empty()) *why = "no arguments";
    return false;
  }
  if (fields.size() == 5) {
    std::string flags = fields[4];
    // xfail takes the rest of the field (its reason may hold commas).
    const size_t x = flags.find("xfail=");
    if (x != std::string::npos) {
      c->xfail = Trim(flags.substr(x + 6));
      flags = flags.substr(0, x);
      if (c->xfail.empty()) {
        *why = "xfail= needs a reason";
        return false;
      }
    }
    std::stringstream fl(flags);
    for (std::string f; std::getline(fl, f, ',');) {
      f = Trim(f);
      if (f.empty()) continue;
      if (f == "stdout") {
        c->stdout_allowed = true;
      } else if (f.rfind("prefill=", 0) == 0 && f.size() > 8 && f.find('/') == std::string::npos) {
        c->prefill.push_back(f.substr(8));
      } else {
        *why = "unknown flag '" + f + "' (stdout, prefill=NAME, xfail=REASON)";
        return false;
      }
    }
  }
  return true;
}

std::vector<fs::path> Manifests() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(kCorpus)) {
    if (e.path().extension() == ".cases") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Every case of every manifest; malformed lines go to *errors.
std::vector<Case> LoadCases(std::vector<std::string>* errors) {
  std::vector<Case> cases;
  std::set<std::string> names;
  for (const fs::path& m : Manifests()) {
    std::ifstream in(m);
    int n = 0;
    for (std::string line; std::getline(in, line);) {
      ++n;
      const std::string t = Trim(line);
      if (t.empty() || t[0] == '#') continue;
      Case c;
      std::string why;
      const std::string where = m.filename().string() + ":" + std::to_string(n);
      if (!ParseCase(m.filename().string(), n, t, &c, &why)) {
        errors->push_back(where + ": " + why);
      } else if (!names.insert(c.name).second) {
        errors->push_back(where + ": case name '" + c.name + "' is used twice");
      } else {
        cases.push_back(c);
      }
    }
  }
  return cases;
}

struct RunResult {
  bool hung = false;
  int signal = 0;      // set when the process died of a signal
  int exit_code = -1;  // set when it exited
  std::string out, err;
};

// Runs textile with argv (no shell) from the source root, stdin from /dev/null.
RunResult RunArgs(const std::vector<std::string>& args, const std::string& tag) {
  const fs::path io = fs::path(TEXTILE_BINARY_DIR) / "test_scratch" / "bad_inputs_io";
  fs::create_directories(io);
  const std::string out_path = (io / (tag + ".out")).string();
  const std::string err_path = (io / (tag + ".err")).string();
  std::vector<std::string> argv_s = {TEXTILE_EXE};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t pid = fork();
  if (pid == 0) {
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0 || chdir(TEXTILE_SOURCE_DIR) != 0) _exit(126);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    execv(argv[0], argv.data());
    _exit(127);
  }
  RunResult r;
  if (pid < 0) {
    r.err = std::string("fork failed: ") + std::strerror(errno);
    return r;
  }
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + kHangAfter;
  while (true) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) break;
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      r.hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!r.hung) {
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  }
  r.out = ReadAll(out_path);
  r.err = ReadAll(err_path);
  return r;
}

// Checks one case's run; returns the problems (empty when it behaved).
std::vector<std::string> Problems(const Case& c, const RunResult& r) {
  std::vector<std::string> p;
  if (r.hung) p.push_back("still running after the watchdog (hang?)");
  if (r.signal) p.push_back("died of signal " + std::to_string(r.signal) + " (" + strsignal(r.signal) + ")");
  if (!r.hung && !r.signal && r.exit_code != c.exit_code) {
    p.push_back("exit " + std::to_string(r.exit_code) + ", expected " + std::to_string(c.exit_code));
  }
  const bool one_line = !r.err.empty() && r.err.back() == '\n' && CountLines(r.err) == 1;
  if (!one_line) p.push_back("stderr is not exactly one line");
  if (r.err.rfind("error: ", 0) != 0) p.push_back("stderr does not start with 'error: '");
  if (r.err.find(c.fragment) == std::string::npos) p.push_back("stderr lacks '" + c.fragment + "'");
  if (r.err.find("error: internal") == 0) p.push_back("an internal error (an unexpected exception)");
  if (!c.stdout_allowed && !r.out.empty()) p.push_back("stdout is not empty");
  // The output folder: pre-filled files unchanged, nothing else but (empty) folders.
  const fs::path out = OutDir(c.name);
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(out, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it->is_directory()) continue;
    const std::string rel = fs::relative(it->path(), out).string();
    if (std::find(c.prefill.begin(), c.prefill.end(), rel) == c.prefill.end()) {
      p.push_back("left a file behind: " + rel);
    } else if (ReadAll(it->path()) != kPrefilled) {
      p.push_back("changed the pre-filled " + rel);
    }
  }
  for (const auto& name : c.prefill) {
    if (!fs::exists(out / name)) p.push_back("removed the pre-filled " + name);
  }
  return p;
}

TEST(BadInputs, ManifestsAreWellFormed) {
  ASSERT_TRUE(fs::is_directory(kCorpus)) << kCorpus;
  EXPECT_FALSE(Manifests().empty()) << "no tests/bad_inputs/*.cases";
  std::vector<std::string> errors;
  const std::vector<Case> cases = LoadCases(&errors);
  for (const auto& e : errors) ADD_FAILURE() << e;
  EXPECT_GT(cases.size(), 0u);
}

// Every subcommand of docs/spec/cli.md that exists has cases: `textile --help` lists them.
TEST(BadInputs, EverySubcommandHasCases) {
  const RunResult help = RunArgs({"--help"}, "help");
  ASSERT_EQ(help.exit_code, 0) << help.err;
  std::vector<std::string> errors;
  std::set<std::string> covered;
  for (const Case& c : LoadCases(&errors)) covered.insert(c.args.front());
  for (const char* sub : {"law", "calibrate", "extract", "render-photo", "fit", "fit-seam", "acpm",
                          "drape", "drape-measure", "render-shadow", "validate", "synth-profile",
                          "bench"}) {
    // A subcommand is listed in --help as "  NAME  description".
    if (help.out.find("  " + std::string(sub) + " ") == std::string::npos) continue;
    EXPECT_TRUE(covered.count(sub)) << "textile " << sub << " has no case in tests/bad_inputs/";
  }
}

// One test per manifest (BadInputs/Manifest.EveryCaseIsRefusedCleanly/fit, ...), so that ctest
// runs them in parallel and each has its own timeout. The list of manifests is read when the
// test binary starts (a new manifest needs a rebuild to get its test; new lines do not).
std::vector<std::string> ManifestStems() {
  std::vector<std::string> stems;
  std::error_code ec;
  if (!fs::is_directory(kCorpus, ec)) return stems;
  for (const fs::path& m : Manifests()) stems.push_back(m.stem().string());
  return stems;
}

class Manifest : public ::testing::TestWithParam<std::string> {};

TEST_P(Manifest, EveryCaseIsRefusedCleanly) {
  std::vector<std::string> errors;
  std::vector<Case> cases;
  for (const Case& c : LoadCases(&errors)) {
    if (c.manifest == GetParam() + ".cases") cases.push_back(c);
  }
  ASSERT_TRUE(errors.empty()) << errors.front();
  ASSERT_FALSE(cases.empty()) << GetParam() << ".cases has no case";
  int xfailed = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.manifest + ":" + std::to_string(c.line) + " " + c.name);
    const fs::path out = OutDir(c.name);
    fs::remove_all(out);
    fs::create_directories(out);
    for (const auto& name : c.prefill) std::ofstream(out / name, std::ios::binary) << kPrefilled;
    const RunResult r = RunArgs(c.args, c.name);
    const std::vector<std::string> problems = Problems(c, r);
    std::string report;
    for (const auto& p : problems) report += "\n  - " + p;
    report += "\n  stderr: " + r.err.substr(0, 400);
    if (c.xfail.empty()) {
      EXPECT_TRUE(problems.empty()) << c.name << ":" << report;
    } else if (problems.empty()) {
      ADD_FAILURE() << c.name << " is marked xfail (" << c.xfail
                    << ") but now behaves: remove the mark";
    } else {
      ++xfailed;
      std::printf("[ xfail    ] %s: %s%s\n", c.name.c_str(), c.xfail.c_str(), report.c_str());
    }
    if (problems.empty()) fs::remove_all(out);
  }
  std::printf("[ corpus   ] %s: %zu cases, %d known failures (xfail)\n", GetParam().c_str(),
              cases.size(), xfailed);
}

INSTANTIATE_TEST_SUITE_P(BadInputs, Manifest, ::testing::ValuesIn(ManifestStems()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(Manifest);

}  // namespace
}  // namespace textile::testing
