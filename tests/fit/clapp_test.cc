#include "textile/fit/clapp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <vector>

#include "textile/fit/law_error.h"
#include "textile/fit/synthetic_profile.h"
#include "textile/sim/error.h"
#include "textile/sim/units.h"

namespace textile {
namespace {

constexpr double kRho = 0.2;  // 200 g/m² [kg/m²]

// A profile of the curve x = r cos φ(r), y = -r sin φ(r) at n points r ∈ (0, r_max]; s is the
// chord length (Clapp's method never reads s except for the data length it reports).
Profile PolarProfile(const std::function<double(double)>& phi, double r_max, int n) {
  Profile p;
  p.source = "polar test curve";
  double s = 0.0, x_prev = 0.0, y_prev = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double r = r_max * i / n;
    const double x = r * std::cos(phi(r)), y = -r * std::sin(phi(r));
    s += std::hypot(x - x_prev, y - y_prev);
    p.s.push_back(s);
    p.x.push_back(x);
    p.y.push_back(y);
    x_prev = x;
    y_prev = y;
  }
  return p;
}

TEST(ClappPolynomial, RecoversExactPolarPolynomial) {
  // A fifth-order φ(t), t = r / R, shaped like a hanging strip (0 -> 0.77 rad).
  const std::vector<double> c = {0.0, 0.3, 0.4, 0.1, -0.05, 0.02};
  const double r_max = 0.05;
  const auto phi = [&](double r) {
    double v = 0.0;
    for (int k = 5; k >= 0; --k) v = v * (r / r_max) + c[k];
    return v;
  };
  std::vector<ClappPoint> points;
  const ClappProfileFit fit = FitClappProfile(PolarProfile(phi, r_max, 60), kRho, {}, &points);
  // QR on a Vandermonde matrix of condition ~1e4 in t ∈ (0, 1]: rounding only.
  const double kCoefficientTol = 1e-11;
  ASSERT_EQ(fit.coefficients.size(), c.size());
  for (size_t k = 0; k < c.size(); ++k) EXPECT_NEAR(fit.coefficients[k], c[k], kCoefficientTol);
  EXPECT_DOUBLE_EQ(fit.r_scale, r_max);
  EXPECT_EQ(fit.points_used, 60);
  EXPECT_LT(fit.residual_rms, 1e-14);
  // κ(0) = 2 φ'(0) for a polar curve through the origin (φ ≈ κ r / 2).
  EXPECT_NEAR(fit.kappa_at_edge, 2.0 * c[1] / r_max, 1e-9);
  EXPECT_EQ(points.size(), 50u);
}

TEST(ClappPolynomial, StraightInclinedStripHasLeverArmMoment) {
  // φ = α: a straight strip, κ = 0 and m(s) = ρ g cos α (L - s)² / 2.
  const double alpha = 0.6, length = 0.04;
  std::vector<ClappPoint> points;
  const ClappProfileFit fit =
      FitClappProfile(PolarProfile([&](double) { return alpha; }, length, 30), kRho, {}, &points);
  const double kTol = 1e-12;  // quadrature and QR rounding, relative
  EXPECT_NEAR(fit.curve_length, length, kTol * length);
  const double m0 = kRho * units::kGravity * std::cos(alpha) * length * length / 2.0;
  for (const ClappPoint& p : points) {
    EXPECT_NEAR(p.kappa, 0.0, 1e-9);
    EXPECT_NEAR(p.moment, kRho * units::kGravity * std::cos(alpha) * std::pow(length - p.s, 2) / 2,
                kTol * m0);
  }
  EXPECT_NEAR(points.front().s, 0.0, 1e-15);
  EXPECT_NEAR(points.back().s, length, kTol * length);
}

TEST(ClappPolynomial, CircularArcGivesItsCurvatureAndMoment) {
  // A circle of radius a tangent to the platform at the edge: r = 2a sin φ. Along it
  // x = a sin(s/a) and m(s) = ρ g [a² (cos(s/a) - cos(L/a)) - a sin(s/a) (L - s)].
  // φ(r) = asin(r / 2a) is not a polynomial: up to r = a the order-5 fit leaves ~1e-5 rad.
  const double a = 0.05, r_max = 0.05;
  std::vector<ClappPoint> points;
  const ClappProfileFit fit = FitClappProfile(
      PolarProfile([&](double r) { return std::asin(r / (2 * a)); }, r_max, 100), kRho, {},
      &points);
  const double length = 2.0 * a * std::asin(r_max / (2 * a));
  const double kLengthTol = 5e-6;     // relative; the polynomial's angle error, measured 1.2e-6
  const double kCurvatureTol = 5e-3;  // relative; order-5 fit of asin, measured 1.9e-3 at the ends
  const double kMomentTol = 1e-5;     // relative to m(0); measured 2.2e-6
  EXPECT_NEAR(fit.curve_length, length, kLengthTol * length);
  const double w = kRho * units::kGravity;
  const auto moment = [&](double s) {
    return w * (a * a * (std::cos(s / a) - std::cos(length / a)) - a * std::sin(s / a) * (length - s));
  };
  for (const ClappPoint& p : points) {
    EXPECT_NEAR(p.kappa, 1.0 / a, kCurvatureTol / a) << "at s = " << p.s;
    EXPECT_NEAR(p.moment, moment(p.s), kMomentTol * moment(0.0)) << "at s = " << p.s;
  }
}

}  // namespace
}  // namespace textile
