#include "common/cli.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <utility>
#include <vector>

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

void PrintJson(const nlohmann::json& j) { std::cout << j.dump(2) << std::endl; }

std::string Num(double v, int digits) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

void Info(const std::string& line) { std::cerr << line << std::endl; }

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
}

}  // namespace textile::cli
