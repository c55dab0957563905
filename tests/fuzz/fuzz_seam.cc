// libFuzzer target: seam JSON (textile::ParseSeamJson) on arbitrary bytes. Anything but a
// SeamProfile or an InputError is a bug (a crash, another exception, a sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/law/seam.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const textile::SeamProfile p = textile::ParseSeamJson(text, "fuzz");
    // A seam that parsed keeps its promises (seam.h): it passes Check, S(d) >= 1 and finite
    // inside, across and beyond the influence band, the area factor is a whole number >= 1,
    // and it survives a round trip through the file format unchanged.
    std::string why;
    if (!p.Check(&why)) __builtin_trap();
    const double d_end = p.influence_mm + p.fade_mm;
    for (const double d : {0.0, 0.5 * p.influence_mm, p.influence_mm, p.influence_mm + 0.5 * p.fade_mm,
                           d_end, 2.0 * d_end}) {
      const double s = p.Multiplier(d), a = p.AreaFactor(d);
      if (!std::isfinite(s) || s < 1.0) __builtin_trap();
      if (!std::isfinite(a) || a < 1.0 || a != std::floor(a)) __builtin_trap();
    }
    if (p.Multiplier(2.0 * d_end) != 1.0) __builtin_trap();
    const textile::SeamProfile q =
        textile::ParseSeamJson(textile::SeamProfileToJson(p).dump(), "fuzz round trip");
    if (q.layers != p.layers || q.coefficients_mm != p.coefficients_mm) __builtin_trap();
  } catch (const textile::InputError&) {
  }
  return 0;
}
