#include "textile/fit/law_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <sstream>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {

double MomentCurveError(const BendingLaw& fit, const BendingLaw& truth, double kappa_max) {
  if (!std::isfinite(kappa_max) || kappa_max <= 0.0) {
    std::ostringstream why;
    why << "moment-curve error: kappa_max must be a positive curvature [1/m], got " << kappa_max;
    throw InputError(why.str());
  }
  // Each Pabst law is a polynomial of degree ≤ 2 on either side of its κ0, so (ΔM)² is a
  // quartic between consecutive break points; 3-point Gauss-Legendre integrates degree 5
  // exactly. A spline is cubic between its knots: a sextic, 4 points (degree 7).
  std::vector<double> breaks = {0.0, kappa_max};
  for (const BendingLaw* law : {&fit, &truth}) {
    for (double k : law->Breakpoints()) {
      if (k < kappa_max) breaks.push_back(k);
    }
  }
  std::sort(breaks.begin(), breaks.end());
  const double a = std::sqrt(0.6);
  const std::array<double, 3> nodes3 = {-a, 0.0, a};
  const std::array<double, 3> weights3 = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const double p = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(1.2));
  const double q4 = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(1.2));
  const double wp = (18.0 + std::sqrt(30.0)) / 36.0, wq = (18.0 - std::sqrt(30.0)) / 36.0;
  const std::array<double, 4> nodes4 = {-q4, -p, p, q4};
  const std::array<double, 4> weights4 = {wq, wp, wp, wq};
  const bool cubic = fit.is_spline() || truth.is_spline();
  const std::span<const double> nodes = cubic ? std::span<const double>(nodes4) : nodes3;
  const std::span<const double> weights = cubic ? std::span<const double>(weights4) : weights3;
  double integral = 0.0;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double mid = 0.5 * (breaks[i] + breaks[i + 1]);
    const double half = 0.5 * (breaks[i + 1] - breaks[i]);
    for (size_t q = 0; q < nodes.size(); ++q) {
      const double k = mid + half * nodes[q];
      const double d = fit.Moment(k) - truth.Moment(k);
      integral += half * weights[q] * d * d;
    }
  }
  return std::sqrt(integral / kappa_max) / truth.Moment(kappa_max);
}

}  // namespace textile
