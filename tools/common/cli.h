#ifndef TEXTILE_TOOLS_COMMON_CLI_H_
#define TEXTILE_TOOLS_COMMON_CLI_H_

// What every subcommand shares: registration, the --json flag, printing, exit codes.
// Conventions (docs/spec/cli.md): human-readable text on stdout, or one JSON object with --json;
// errors are one line "error: ..." on stderr with exit 2 (bad input, usage) or 3 (a
// computation failed). Subcommands throw InputError / ComputeError; main() maps them.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/monte_carlo.h"
#include <optional>
#include <string>

namespace textile::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitComputeFailed = 3;

// Adds a subcommand with a one-line description and an example for --help.
CLI::App* AddSubcommand(CLI::App& app, const std::string& name, const std::string& description,
                        const std::string& example);

// Prints one JSON object on stdout (pretty, newline-terminated); text that is not valid UTF-8
// is printed with U+FFFD in place of the bad bytes rather than failing.
void PrintJson(const nlohmann::json& j);

// Compact number for people: 6 significant digits, no trailing zeros (textile::NumberText).
std::string Num(double v, int digits = 6);

// True if s is valid UTF-8 (JSON output needs it; names and notes from flags are checked).
bool IsValidUtf8(const std::string& s);

// The parameters of `--sensitivity-params LIST` (drape, acpm): comma-separated names as the
// material file spells them; none when the list is empty (every parameter). InputError for a
// list without --sensitivity or with an empty name.
std::vector<std::string> SensitivityParameterList(bool sensitivity, const std::string& list);

// The flags of sensitivities and their Monte Carlo check (drape, acpm): --sensitivity,
// --sensitivity-params LIST, --monte-carlo N, --monte-carlo-seed S. `quantity` names the result
// ("the DC", "the crossing length L"), `scope` where it applies, `names` example parameters.
struct SensitivityArgs {
  bool sensitivity = false;
  std::string params;
  int monte_carlo = 0;
  std::optional<unsigned> monte_carlo_seed;
  // --sensitivity's parameters (SensitivityParameterList); --monte-carlo implies --sensitivity.
  // InputError, naming the flag, for --monte-carlo under 2 or --monte-carlo-seed without it.
  std::vector<std::string> Parameters() const;
  unsigned Seed() const { return monte_carlo_seed.value_or(1); }
};
void AddSensitivityFlags(CLI::App* sub, SensitivityArgs* a, const std::string& quantity,
                         const std::string& scope, const std::string& names);
// Prints the Monte Carlo line: "<quantity> Monte Carlo: sigma ... over N samples (...)".
void PrintMonteCarlo(const std::string& quantity, const std::string& unit, double scale,
                     const MonteCarloSpread& spread);
// Prints a quantity's σ line and its influence table (largest change first) on stdout:
// "<quantity> sigma: ..." then one line a parameter; `scale` turns Q into the printed `unit`
// (1e3 and "mm" for metres; "" for none).
void PrintInfluences(const std::string& quantity, const std::string& unit, double scale,
                     double sigma, const std::string& sigma_note,
                     const std::vector<ParameterInfluence>& rows);
// "<title> (not in the sigma):" and `rows` as PrintInfluences prints them (the quantity's
// values times `scale`, in `unit`); nothing when there are none.
void PrintInfluencesBesideSigma(const std::string& title, const std::string& unit, double scale,
                                const std::vector<ParameterInfluence>& rows);

// Progress/info line on stderr (never on stdout, which may carry JSON).
void Info(const std::string& line);

// Progress line on stderr ("Progress for anything over about a second goes to stderr",
// docs/spec/cli.md), printed only when stderr is a terminal or when `always` is set (a --progress
// flag), as git does: a script or a test reading stderr sees nothing there but the one `error: ...`
// line of a failed run. Warnings and notes the user must see go through Info.
void Progress(const std::string& line, bool always = false);
// Whether Progress prints: stderr is a terminal, or `always`.
bool ShowProgress(bool always = false);

// Subcommands register themselves, one file each (tools/cmd_<name>.cc), with a namespace-scope
//   const bool kRegistered = AddCommand(40, RegisterFit);
// `order` sorts them in --help (the pipeline order: law 10, synth-profile 20, calibrate 25,
// extract 30, render-photo 35, fit 40, fit-seam 45, acpm 50, drape 60, render-shadow 62,
// drape-measure 65, validate 70, export 80, bench 90).
using CommandRegistrar = void (*)(CLI::App& app);
bool AddCommand(int order, CommandRegistrar registrar);
// Adds every registered subcommand to app, in order, and makes every option and argument of
// theirs that takes a number or a text refuse an empty value (RefuseEmptyValues).
void RegisterAllCommands(CLI::App& app);

// CLI11 2.1 reads an empty value of a number option as 0, and of a number list as no value
// (`textile law --kappa ""` printed the default curvatures); an empty output path read as "not
// asked for" (`--png ""` exited 0 without the picture), an empty input path failed with
// "error: : cannot open ...". This adds a check to every option and positional argument of app
// and its subcommands whose type is a number or a text, or a list of them, so that such a value
// is a usage error naming the flag (exit 2). No option of textile takes an empty text on
// purpose: an output not wanted is left out, a name not given gets its default. A text that is
// not valid UTF-8 is refused the same way: names and paths are stored in JSON results, which a
// run would otherwise fail to write after its work ("error: internal").
// A whole number beyond the 64-bit range is refused too (CLI11 kept strtoll's saturated value).
void RefuseEmptyValues(CLI::App& app);

}  // namespace textile::cli

#endif  // TEXTILE_TOOLS_COMMON_CLI_H_
