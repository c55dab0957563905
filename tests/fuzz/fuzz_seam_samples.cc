// libFuzzer target: the measurements `textile fit-seam` reads, on arbitrary bytes: an ACPM
// result's rays (JSON, when the first non-blank byte is '{') or a `d_mm,factor[,sd]` CSV, the
// two parsers of textile::ReadSeamSamples; then the quadratic fit. Every sample must be what
// the parsers promise; the fit must end in a profile that is usable on [0, d_max] (finite
// coefficients, 0 < B_f ≤ 100) or in an InputError / ComputeError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "textile/fit/seam_fit.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto first = text.find_first_not_of(" \t\r\n");
    const std::vector<textile::SeamSample> samples =
        first != std::string::npos && text[first] == '{'
            ? textile::SeamSamplesFromAcpmJson(textile::ParseJsonText(text, "fuzz"), "fuzz")
            : textile::ParseSeamSamplesCsv(text, "fuzz");
    for (const auto& s : samples) {
      if (!(std::isfinite(s.d_mm) && s.d_mm >= 0.0)) __builtin_trap();
      if (!(std::isfinite(s.factor) && s.factor > 0.0)) __builtin_trap();
      if (!(std::isnan(s.sd) || (std::isfinite(s.sd) && s.sd > 0.0))) __builtin_trap();
    }
    try {
      const textile::SeamFitSummary fit = textile::FitSeamFactor(samples);
      const auto& a = fit.coefficients_mm;
      for (double c : a)
        if (!std::isfinite(c)) __builtin_trap();
      // B_f is promised valid over the written influence range (the data's by default; beyond
      // it S fades to 1 and the polynomial is not used).
      for (int k = 0; k <= 100; ++k) {
        const double d = fit.influence_mm * k / 100.0;
        const double b = (a[0] * d + a[1]) * d + a[2];
        if (!(b > 0.0 && b <= 100.0 * (1.0 + 1e-9))) __builtin_trap();
      }
    } catch (const textile::ComputeError&) {
    }
  } catch (const textile::InputError&) {
  }
  return 0;
}
