#include "common/cli.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile::cli {

CLI::App* AddSubcommand(CLI::App& app, const std::string& name, const std::string& description,
                        const std::string& example) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->footer("\nExample:\n  " + example + "\n");
  return sub;
}

bool IsValidUtf8(const std::string& s) {
  try {
    (void)nlohmann::json(s).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

// Bytes that are not UTF-8 (a path or name given as such) become U+FFFD instead of an exception
// at the very end of a run whose outputs are already written.
void PrintJson(const nlohmann::json& j) {
  std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
}

std::string Num(double v, int digits) { return NumberText(v, digits); }

void Info(const std::string& line) { std::cerr << line << std::endl; }

bool ShowProgress(bool always) { return always || ::isatty(STDERR_FILENO) == 1; }

void Progress(const std::string& line, bool always) {
  if (ShowProgress(always)) std::cerr << line << std::endl;
}

namespace {
// CLI11's name of an option's value type without its validators' notes ("FLOAT:POSITIVE")
// and list brackets: FLOAT, INT, UINT, TEXT, ...
std::string BaseTypeName(const CLI::Option& option) {
  std::string t = option.get_type_name();
  t = t.substr(0, t.find(':'));
  std::erase_if(t, [](char c) { return c == '[' || c == ']'; });
  return t;
}
}  // namespace

void RefuseEmptyValues(CLI::App& app) {
  static const CLI::Validator kNotEmptyNumber(
      [](std::string& value) {
        return value.empty() ? std::string("an empty value is not a number") : std::string();
      },
      "", "NOT_EMPTY");
  // CLI11 2.1 reads a whole number with strtoll/strtoull and keeps their saturated result for a
  // 64-bit target: `synth-profile --seed 99999999999999999999` ran with 2^63 - 1.
  const auto in_range = [](bool is_signed) {
    return CLI::Validator(
        [is_signed](std::string& value) {
          errno = 0;
          if (is_signed) {
            (void)std::strtoll(value.c_str(), nullptr, 0);
          } else {
            (void)std::strtoull(value.c_str(), nullptr, 0);
          }
          return errno == ERANGE ? value + " is out of range" : std::string();
        },
        "", "IN_RANGE");
  };
  static const CLI::Validator kIntInRange = in_range(true), kUintInRange = in_range(false);
  static const CLI::Validator kNotEmptyText(
      [](std::string& value) {
        if (value.empty()) return std::string("an empty value is not allowed");
        // Names and paths end up in the JSON results, which must be UTF-8.
        if (!IsValidUtf8(value)) return std::string("not valid UTF-8 text");
        return std::string();
      },
      "", "NOT_EMPTY");
  for (CLI::Option* option : app.get_options()) {
    const std::string type = BaseTypeName(*option);  // empty for flags
    if (type == "FLOAT" || type == "INT" || type == "UINT" || type == "NUMBER") {
      option->check(kNotEmptyNumber);
      if (type == "INT") option->check(kIntInRange);
      if (type == "UINT") option->check(kUintInRange);
    } else if (type == "TEXT") {
      option->check(kNotEmptyText);
    }
  }
  for (CLI::App* sub : app.get_subcommands({})) RefuseEmptyValues(*sub);
}

namespace {
std::vector<std::pair<int, CommandRegistrar>>& Commands() {
  static std::vector<std::pair<int, CommandRegistrar>> commands;
  return commands;
}
}  // namespace

bool AddCommand(int order, CommandRegistrar registrar) {
  Commands().emplace_back(order, registrar);
  return true;
}

void RegisterAllCommands(CLI::App& app) {
  auto commands = Commands();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [order, registrar] : commands) registrar(app);
  RefuseEmptyValues(app);
}

std::vector<std::string> SensitivityParameterList(bool sensitivity, const std::string& list) {
  if (list.empty()) return {};
  if (!sensitivity) throw InputError("--sensitivity-params: needs --sensitivity");
  std::vector<std::string> names;
  for (size_t from = 0; from <= list.size();) {
    const size_t comma = std::min(list.find(',', from), list.size());
    if (comma == from) throw InputError("--sensitivity-params: '" + list + "' has an empty name");
    names.push_back(list.substr(from, comma - from));
    from = comma + 1;
  }
  return names;
}

std::vector<std::string> SensitivityArgs::Parameters() const {
  if (monte_carlo < 0 || monte_carlo == 1)
    throw InputError("--monte-carlo: must be at least 2 samples, got " + std::to_string(monte_carlo));
  if (monte_carlo_seed && monte_carlo == 0)
    throw InputError("--monte-carlo-seed: needs --monte-carlo");
  return SensitivityParameterList(sensitivity || monte_carlo > 0, params);
}

void AddSensitivityFlags(CLI::App* sub, SensitivityArgs* a, const std::string& quantity,
                         const std::string& scope, const std::string& names) {
  sub->add_flag("--sensitivity", a->sensitivity,
                "Each material parameter's influence on " + quantity +
                    " (its derivative per ln p, and its change over the parameter's "
                    "uncertainty) and its sigma from the fit's covariance; " + scope +
                    " (docs/methods/sensitivity.md)");
  sub->add_option("--sensitivity-params", a->params,
                  "--sensitivity: only these parameters, comma-separated as the material file "
                  "names them (" + names + ")");
  sub->add_option("--monte-carlo", a->monte_carlo,
                  "Check the sigma: simulate N materials drawn from the fit's covariance of b1, "
                  "b2, c1 and compare their spread with the linear sigma (implies "
                  "--sensitivity; needs a fitted material)");
  sub->add_option("--monte-carlo-seed", a->monte_carlo_seed,
                  "--monte-carlo: the draws' seed (default 1)");
}

void PrintMonteCarlo(const std::string& quantity, const std::string& unit, double scale,
                     const MonteCarloSpread& s) {
  const std::string in = unit.empty() ? "" : " " + unit;
  std::cout << quantity << " Monte Carlo: sigma "
            << (std::isfinite(s.sigma) ? Num(scale * s.sigma, 2) + in : std::string("none"))
            << ", mean " << Num(scale * s.mean, 4) << in << " over " << s.samples << " samples in "
            << Num(s.seconds, 3) << " s (" << s.note << ")\n";
}

namespace {

// "  name = value unit (default): dQ/dln p; change over source", Q's values times `scale` with
// their unit `in` (" mm" or empty).
void PrintInfluenceRow(const ParameterInfluence& s, double scale, const std::string& in) {
  std::cout << "  " << s.parameter << " = " << Num(s.value, 4)
            << (s.unit == "-" ? std::string() : " " + s.unit)
            << (s.defaulted ? " (default)" : "") << ": " << Num(scale * s.d_q_d_ln_p, 3) << in
            << "; " << Num(scale * s.change, 2) << in << " over " << s.uncertainty_source << "\n";
}

}  // namespace

void PrintInfluences(const std::string& quantity, const std::string& unit, double scale,
                     double sigma, const std::string& sigma_note,
                     const std::vector<ParameterInfluence>& rows) {
  const std::string in = unit.empty() ? "" : " " + unit;
  std::cout << quantity << " sigma: "
            << (std::isfinite(sigma) ? Num(scale * sigma, 2) + in : std::string("none")) << " ("
            << sigma_note << ")\n"
            << "influence (d" << quantity << "/dln p" << in
            << "; change over the uncertainty):\n";
  for (const ParameterInfluence& s : rows) PrintInfluenceRow(s, scale, in);
}

void PrintInfluencesBesideSigma(const std::string& title, const std::string& unit, double scale,
                                const std::vector<ParameterInfluence>& rows) {
  if (rows.empty()) return;
  std::cout << title << " (not in the sigma):\n";
  for (const ParameterInfluence& s : rows)
    PrintInfluenceRow(s, scale, unit.empty() ? "" : " " + unit);
}

}  // namespace textile::cli
