#include "textile/sim/core/number_text.h"

#include <cmath>
#include <cstdio>

namespace textile {

std::string NumberText(double value, int significant) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant, value);
  return buffer;
}

}  // namespace textile
