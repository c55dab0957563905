#include "textile/fit/law_error.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/error.h"

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

TEST(MomentCurveError, MatchesDenseSamplingAcrossKinks) {
  // Both laws have κ0 inside [0, κmax]; a fine midpoint rule (error O(h²) ~ 1e-9 at 2e5
  // cells, worse at the kinks) checks the piecewise Gauss-Legendre.
  const auto truth = BendingLaw::FromKes(0.1, 0.0892, -0.0092);  // κ0 = 0.587 /cm
  const auto fit = BendingLaw::FromKes(0.11, 0.085, -0.02);      // κ0 = 0.625 /cm
  const double kappa_max = 150.0;                                // 1.5 /cm
  const int cells = 200000;
  double sum = 0.0;
  for (int i = 0; i < cells; ++i) {
    const double k = kappa_max * (i + 0.5) / cells;
    const double d = fit.Moment(k) - truth.Moment(k);
    sum += d * d;
  }
  const double expected = std::sqrt(sum / cells) / truth.Moment(kappa_max);
  const double kMidpointTol = 1e-7;
  EXPECT_NEAR(MomentCurveError(fit, truth, kappa_max), expected, kMidpointTol * expected);
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
