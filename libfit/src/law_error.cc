#include "textile/fit/law_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <vector>

#include "textile/sim/error.h"

namespace textile {

double MomentCurveError(const BendingLaw& fit, const BendingLaw& truth, double kappa_max) {
  if (!std::isfinite(kappa_max) || kappa_max <= 0.0) {
    std::ostringstream why;
    why << "moment-curve error: kappa_max must be a positive curvature [1/m], got " << kappa_max;
    throw InputError(why.str());
  }
  // Each law is a polynomial of degree ≤ 2 on either side of its κ0, so (ΔM)² is a quartic
  // between consecutive break points; 3-point Gauss-Legendre integrates degree 5 exactly.
  std::vector<double> breaks = {0.0, kappa_max};
  for (double k0 : {fit.kappa0(), truth.kappa0()}) {
    if (k0 > 0.0 && k0 < kappa_max) breaks.push_back(k0);
  }
  std::sort(breaks.begin(), breaks.end());
  const double a = std::sqrt(0.6);
  const std::array<double, 3> nodes = {-a, 0.0, a};
  const std::array<double, 3> weights = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double integral = 0.0;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double mid = 0.5 * (breaks[i] + breaks[i + 1]);
    const double half = 0.5 * (breaks[i + 1] - breaks[i]);
    for (int q = 0; q < 3; ++q) {
      const double k = mid + half * nodes[q];
      const double d = fit.Moment(k) - truth.Moment(k);
      integral += half * weights[q] * d * d;
    }
  }
  return std::sqrt(integral / kappa_max) / truth.Moment(kappa_max);
}

}  // namespace textile
