#include "common/cli.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace textile::cli {

CLI::App* AddSubcommand(CLI::App& app, const std::string& name, const std::string& description,
                        const std::string& example) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->footer("\nExample:\n  " + example + "\n");
  return sub;
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

}  // namespace textile::cli
