// textile: the command line. Each subcommand lives in tools/cmd_<name>.cc; this file only
// wires them up and maps failures to the exit codes of cli.md.

#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "common/blas_kernels.h"
#include "common/cli.h"
#include "textile/sim/error.h"

namespace {
// Errors are one line (cli.md), whatever a library put into the message.
std::string OneLine(const char* what) {
  std::string s = what;
  for (char& c : s) if (c == '\n' || c == '\r') c = ' ';
  return s;
}
}  // namespace

int main(int argc, char** argv) {
  namespace cli = textile::cli;
  cli::ChooseBlasKernels();
  CLI::App app{
      "textile: textile bending characterisation.\n"
      "Cantilever profiles -> nonlinear moment-curvature law {b1, b2, c1} -> virtual tests.\n"
      "Internally SI; files and printouts in lab units (KES: gf·cm, 1/cm; g/m²; mm)."};
  app.name("textile");
  app.set_version_flag("--version", std::string("textile ") + TEXTILE_VERSION + " (BLAS: " +
                                        cli::BlasKernels() + ")");
  app.require_subcommand(1);
  app.footer("\nRun 'textile SUBCOMMAND --help' for the flags and an example of each.\n"
             "Exit codes: 0 ok, 2 bad input or usage, 3 computation failed.");
  cli::RegisterAllCommands(app);
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
    return cli::kExitBadInput;
  } catch (const textile::InputError& e) {
    std::fprintf(stderr, "error: %s\n", OneLine(e.what()).c_str());
    return cli::kExitBadInput;
  } catch (const textile::ComputeError& e) {
    std::fprintf(stderr, "error: %s\n", OneLine(e.what()).c_str());
    return cli::kExitComputeFailed;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
    return cli::kExitComputeFailed;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: internal: %s\n", OneLine(e.what()).c_str());
    return cli::kExitComputeFailed;
  }
  return cli::kExitOk;
}
