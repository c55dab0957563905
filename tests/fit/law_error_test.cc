#include "textile/fit/law_error.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// Quadrature is exact for piecewise quartics, so results agree with closed forms to rounding.
constexpr double kRoundingTol = 1e-12;

TEST(MomentCurveError, ZeroForIdenticalLaws) {
  const auto law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  EXPECT_EQ(MomentCurveError(law, law, 150.0), 0.0);
}

TEST(MomentCurveError, ScaledLinearLawHasClosedForm) {
  // M_fit = (1 + ε) B κ vs M = B κ: RMS of ε B κ over [0, K] is ε B K / √3, over B K.
  const double eps = 0.03;
  const auto truth = BendingLaw::FromKes(0.1, 0.1, 0.0);
  const auto fit = truth.Scaled(1.0 + eps);
  EXPECT_NEAR(MomentCurveError(fit, truth, 120.0), eps / std::sqrt(3.0), kRoundingTol);
}

// The error measure by a fine midpoint rule (error O(h²) ~ 1e-9 at 2e5 cells, worse at the
// kinks), to check the piecewise Gauss-Legendre against.
double MidpointError(const BendingLaw& fit, const BendingLaw& truth, double kappa_max) {
  const int cells = 200000;
  double sum = 0.0;
  for (int i = 0; i < cells; ++i) {
    const double k = kappa_max * (i + 0.5) / cells;
    const double d = fit.Moment(k) - truth.Moment(k);
    sum += d * d;
  }
  return std::sqrt(sum / cells) / truth.Moment(kappa_max);
}
constexpr double kMidpointTol = 1e-7;

TEST(MomentCurveError, MatchesDenseSamplingAcrossKinks) {
  // Both laws have κ0 inside [0, κmax].
  const auto truth = BendingLaw::FromKes(0.1, 0.0892, -0.0092);  // κ0 = 0.587 /cm
  const auto fit = BendingLaw::FromKes(0.11, 0.085, -0.02);      // κ0 = 0.625 /cm
  const double kappa_max = 150.0;                                // 1.5 /cm
  const double expected = MidpointError(fit, truth, kappa_max);
  EXPECT_NEAR(MomentCurveError(fit, truth, kappa_max), expected, kMidpointTol * expected);
}

TEST(MomentCurveError, SplineLawsSplitAtTheirKnots) {
  // A spline against a Pabst law: (ΔM)² is a sextic between the knots and κ0, integrated by
  // 4-point Gauss-Legendre (exact to degree 7); checked against the fine midpoint rule.
  const auto truth = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const auto fit =
      BendingLaw::FromSplineKes({0.0, 0.3, 0.7, 1.2, 2.0}, {0.0, 0.028, 0.062, 0.11, 0.18});
  EXPECT_EQ(MomentCurveError(fit, fit, 150.0), 0.0);
  const double kappa_max = 150.0;
  const double expected = MidpointError(fit, truth, kappa_max);
  EXPECT_NEAR(MomentCurveError(fit, truth, kappa_max), expected, kMidpointTol * expected);
  // Symmetric but for the normalisation by the reference's M(κmax).
  const double rms = expected * truth.Moment(kappa_max);
  EXPECT_NEAR(MomentCurveError(truth, fit, kappa_max) * fit.Moment(kappa_max), rms,
              kMidpointTol * rms);
}

TEST(MomentCurveError, RejectsNonPositiveRange) {
  const auto law = BendingLaw::FromKes(0.1, 0.1, 0.0);
  for (double bad : {0.0, -1.0, std::nan("")}) {
    try {
      MomentCurveError(law, law, bad);
      ADD_FAILURE() << "no exception for kappa_max = " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("kappa_max"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace textile
