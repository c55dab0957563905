#ifndef TEXTILE_FIT_SRC_LAW_PARAMETERS_H_
#define TEXTILE_FIT_SRC_LAW_PARAMETERS_H_

// The parametrisation every fit of the bending law uses: p = (ln b1, ln b2, ln κ0) with b in
// N·m and κ0 in 1/m, and c1 = (b2 - b1) / (2 κ0). Any real p is a valid law (b1, b2 > 0,
// κ0 > 0), so positivity and κ0 ≥ 0 hold by construction, not by clamping after the fact
// (issue: "κ0 ≥ 0 by parametrisation"). b1 = b2 is the linear law for any κ0; κ0 → ∞ is
// the linear law M = b1 κ. Templated for Ceres' Jets.

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "textile/sim/law/bending_law.h"

namespace textile::internal {

// κ0 is kept in [kMinKappa0, kMaxKappa0] [1/m] when converting a law into parameters: a
// law with κ0 = 0 or ∞ is the same law as one with κ0 at these bounds for all practical
// curvatures (1e-4 /cm .. 1e4 /cm).
inline constexpr double kMinKappa0 = 1e-2, kMaxKappa0 = 1e6;

// Moment per unit width M(κ) [N] of eq. 1 (odd extension) from parameters p.
template <typename T>
T LawMoment(const T* p, const T& kappa) {
  using std::abs;
  using std::exp;
  const T b1 = exp(p[0]), b2 = exp(p[1]), k0 = exp(p[2]);
  const T c1 = (b2 - b1) / (2.0 * k0);
  const T k = abs(kappa);
  T m;
  if (k <= k0) {
    m = (b1 + c1 * k) * k;
  } else {
    // M0 + b2 κ with M0 = (b1 - b2) κ0 + c1 κ0² = -(b2 - b1) κ0 / 2.
    m = 0.5 * (b1 - b2) * k0 + b2 * k;
  }
  return kappa < T(0.0) ? -m : m;
}

inline BendingLaw LawFromParameters(const double* p) {
  const double b1 = std::exp(p[0]), b2 = std::exp(p[1]), k0 = std::exp(p[2]);
  return BendingLaw::FromSi(b1, b2, (b2 - b1) / (2.0 * k0));
}

// A Pabst law only (a spline has no κ0 = (b2 - b1)/(2 c1): callers route splines elsewhere).
inline std::array<double, 3> ParametersFromLaw(const BendingLaw& law) {
  assert(!law.is_spline());
  const double k0 = std::clamp(law.kappa0(), kMinKappa0, kMaxKappa0);
  return {std::log(law.b1()), std::log(law.b2()), std::log(k0)};
}

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_LAW_PARAMETERS_H_
