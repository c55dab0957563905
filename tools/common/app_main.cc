#include "common/app_main.h"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/blas_kernels.h"
#include "common/cli.h"
#include "common/forward_command.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

// Errors are one line (docs/spec/cli.md), whatever a library put into the message.
std::string OneLine(const char* what) {
  std::string s = what;
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

void PrepareProcess() {
  // A reader that goes away (`textile ... 2>&1 | head -1`) makes writes fail instead of killing
  // the process, so that its staged files are still cleaned up.
  std::signal(SIGPIPE, SIG_IGN);
  // Ctrl-C, kill or a closed terminal: the run's temporary files and private folders go first.
  InstallSignalCleanup();
  ChooseBlasKernels();
}

void BuildApp(CLI::App& app) {
  app.name("textile");
  app.set_version_flag(
      "--version", std::string("textile ") + TEXTILE_VERSION + " (BLAS: " + BlasKernels() + ")");
  app.require_subcommand(1);
  app.footer(
      "\nRun 'textile SUBCOMMAND --help' for the flags and an example of each.\n"
      "Exit codes: 0 ok, 2 bad input or usage, 3 computation failed.");
  RegisterAllCommands(app);
}

// CLI11 calls a missing or unknown command, or an unknown option before it, "A subcommand is
// required", and with --help after an unknown command prints the top-level help and exits 0:
// the reason for refusing argv here instead, or "" when its first argument is a command.
std::string NoCommandReason(CLI::App& app, int argc, char** argv) {
  const std::vector<CLI::App*> commands = app.get_subcommands([](CLI::App*) { return true; });
  const std::string first = argc > 1 ? argv[1] : "";
  if (first == "-h" || first == "--help" || first == "--version" ||
      std::any_of(commands.begin(), commands.end(),
                  [&](CLI::App* command) { return command->check_name(first); }))
    return "";
  std::string names;
  for (const CLI::App* command : commands)
    names += (names.empty() ? "" : ", ") + command->get_name();
  const std::string quoted =
      IsValidUtf8(first) ? "'" + OneLine(first.c_str()) + "'" : "(not valid UTF-8 text)";
  // "--" ends the options, and what follows it is no command to CLI11 either.
  const std::string what = argc == 1 ? "no command given"
                           : first == "--"
                               ? "'--' before the command (it comes first: textile COMMAND ...)"
                           : first.rfind('-', 0) == 0 ? "unknown option " + quoted
                                                      : "unknown command " + quoted;
  return what + " (the commands: " + names + ")";
}

// A report that did not reach stdout (a full disk, a reader gone) is no success; as for the
// files a run could not write, exit 2.
bool StdoutWasWritten() {
  std::cout.flush();
  return std::cout && std::fflush(stdout) == 0 && !std::ferror(stdout);
}

// Parses argv and runs the subcommand; a failure is one line on stderr and its exit code.
int ParseAndRun(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: %s (see 'textile --help')\n", OneLine(e.what()).c_str());
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", OneLine(e.what()).c_str());
    return kExitBadInput;
  } catch (const ComputeError& e) {
    std::fprintf(stderr, "error: %s\n", OneLine(e.what()).c_str());
    return kExitComputeFailed;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
    return kExitComputeFailed;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: internal: %s\n", OneLine(e.what()).c_str());
    return kExitComputeFailed;
  }
  if (!StdoutWasWritten()) {
    std::fprintf(stderr, "error: cannot write the report to stdout\n");
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

int AppMain(int argc, char** argv) {
  // Before anything is set up here: the other executable sets up its own process.
  if (RunForwardedCommand(argc, argv)) return kExitBadInput;
  PrepareProcess();
  CLI::App app{
      "textile: textile bending characterisation.\n"
      "Cantilever profiles -> nonlinear moment-curvature law {b1, b2, c1} -> virtual tests.\n"
      "Internally SI; files and printouts in lab units (KES: gf·cm, 1/cm; g/m²; mm)."};
  BuildApp(app);
  const std::string refused = NoCommandReason(app, argc, argv);
  if (!refused.empty()) {
    std::fprintf(stderr, "error: %s\n", refused.c_str());
    return kExitBadInput;
  }
  return ParseAndRun(app, argc, argv);
}

}  // namespace textile::cli
