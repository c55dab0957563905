// libFuzzer target: profile CSV (textile::ParseProfileCsv) on arbitrary bytes. Anything but a
// valid Profile or an InputError is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "textile/fit/profile.h"
#include "textile/sim/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const textile::Profile p = textile::ParseProfileCsv(text, "fuzz");
    if (p.size() < static_cast<size_t>(textile::kMinProfilePoints)) __builtin_trap();
    for (size_t i = 0; i < p.size(); ++i) {
      if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) __builtin_trap();
      if (i && !(p.s[i] > p.s[i - 1])) __builtin_trap();
    }
    textile::ParseProfileCsv(textile::ProfileToCsv(p), "fuzz round trip");
  } catch (const textile::InputError&) {
  }
  return 0;
}
