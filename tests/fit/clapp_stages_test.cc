// The stages of FitClapp (clapp_stages.h), each on (κ, M) pairs set up by hand.

#include "clapp_stages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "law_parameters.h"

namespace textile {
namespace {

using internal::ClappFitState;

// Pairs on M = B κ for κ = 1 .. n [1/m].
std::vector<ClappPoint> LinearPairs(double stiffness, int n) {
  std::vector<ClappPoint> points;
  for (int i = 1; i <= n; ++i) points.push_back({double(i), stiffness * i, 0.0, 0});
  return points;
}

// A state holding only pairs: what the stages after PoolClappPairs read.
struct PairsOnly {
  explicit PairsOnly(std::vector<ClappPoint> points, ClappOptions o = {})
      : options(o), state(profiles, 0.2, options) {
    state.result.points = std::move(points);
  }
  std::vector<Profile> profiles;
  ClappOptions options;
  ClappFitState state;
};

TEST(ClappStages, MeasureClappScalesTakesTheLinearStiffness) {
  PairsOnly s(LinearPairs(2e-5, 10));
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  EXPECT_EQ(s.state.result.kappa_max, 10.0);
  EXPECT_DOUBLE_EQ(s.state.moment_max, 2e-4);
  EXPECT_DOUBLE_EQ(s.state.linear_stiffness, 2e-5);
}

TEST(ClappStages, MeasureClappScalesRefusesAStraightStrip) {
  std::vector<ClappPoint> straight = LinearPairs(2e-5, 10);
  for (ClappPoint& p : straight) p.kappa = 1e-6;  // round-off curvature
  PairsOnly s(straight);
  EXPECT_FALSE(internal::MeasureClappScales(&s.state));
  EXPECT_EQ(s.state.result.message,
            "Clapp fit: the profiles have no curvature along them (straight); no law fitted");
}

TEST(ClappStages, MeasureClappScalesRefusesMomentFallingWithCurvature) {
  PairsOnly s(LinearPairs(-2e-5, 10));
  EXPECT_FALSE(internal::MeasureClappScales(&s.state));
  EXPECT_EQ(s.state.result.message.rfind("Clapp fit: moment and curvature of the polynomial curves "
                                         "do not increase together",
                                         0),
            0u)
      << s.state.result.message;
}

TEST(ClappStages, PlaceClappStartsSpreadsKappa0OverTheData) {
  PairsOnly s(LinearPairs(2e-5, 10));
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  internal::PlaceClappStarts(&s.state);
  ASSERT_EQ(s.state.starts.size(), 6u);
  // κ0 from 0.1 to 2 κ_max; a linear law gives b1 = b2 = B from every start.
  constexpr double kTol = 1e-9;  // least squares on exact pairs, in ln
  EXPECT_NEAR(s.state.starts.front()[2], std::log(1.0), kTol);
  EXPECT_NEAR(s.state.starts.back()[2], std::log(20.0), kTol);
  for (const auto& start : s.state.starts) {
    EXPECT_NEAR(start[0], std::log(2e-5), kTol);
    EXPECT_NEAR(start[1], std::log(2e-5), kTol);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(start[k], s.state.lower[k]);
      EXPECT_LE(start[k], s.state.upper[k]);
    }
  }
  EXPECT_NEAR(s.state.upper[0] - s.state.lower[0], 2.0 * std::log(1e6), kTol);
}

TEST(ClappStages, PlaceClappStartsWithOneStartTakesHalfTheLargestCurvature) {
  ClappOptions o;
  o.num_starts = 1;
  PairsOnly s(LinearPairs(2e-5, 10), o);
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  internal::PlaceClappStarts(&s.state);
  ASSERT_EQ(s.state.starts.size(), 1u);
  EXPECT_NEAR(s.state.starts[0][2], std::log(5.0), 1e-12);
}

TEST(ClappStages, RunClappStartsStopsAtTheTimeCapWithoutALaw) {
  ClappOptions o;
  o.max_seconds = 0.0;
  PairsOnly s(LinearPairs(2e-5, 10), o);
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  internal::PlaceClappStarts(&s.state);
  EXPECT_FALSE(internal::RunClappStarts(&s.state));
  EXPECT_EQ(s.state.result.message,
            "Clapp fit: time cap of 0 s (ClappOptions::max_seconds) reached with 0 of 6 "
            "regression starts run; no law");
  EXPECT_FALSE(s.state.result.law.has_value());
}

TEST(ClappStages, ARegressionOnALawsOwnPairsFindsIt) {
  const BendingLaw truth = BendingLaw::FromSi(1e-5, 2e-5, 1e-6);  // κ0 = 5 /m
  std::vector<ClappPoint> pairs;
  for (int i = 1; i <= 40; ++i) pairs.push_back({0.25 * i, truth.Moment(0.25 * i), 0.0, 0});
  PairsOnly s(pairs);
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  internal::PlaceClappStarts(&s.state);
  ASSERT_TRUE(internal::RunClappStarts(&s.state));
  ASSERT_TRUE(internal::ClappLawFromBest(&s.state));
  internal::MeasureClappMisfit(&s.state);
  const BendingLaw& law = *s.state.result.law;
  constexpr double kRel = 1e-5;  // Ceres' tolerances on exact pairs
  EXPECT_NEAR(law.b1(), truth.b1(), kRel * truth.b1());
  EXPECT_NEAR(law.b2(), truth.b2(), kRel * truth.b2());
  EXPECT_TRUE(s.state.result.b2_observed);  // the pairs reach 10 /m, κ0 = 5 /m
}

TEST(ClappStages, ClappCovarianceIsUnavailableOnABound) {
  PairsOnly s(LinearPairs(2e-5, 10));
  ASSERT_TRUE(internal::MeasureClappScales(&s.state));
  internal::PlaceClappStarts(&s.state);
  s.state.best = {std::log(2e-5), std::log(2e-5), s.state.upper[2]};  // κ0 on its bound
  ASSERT_TRUE(internal::ClappLawFromBest(&s.state));
  internal::MeasureClappMisfit(&s.state);
  internal::ClappCovariance(&s.state);
  EXPECT_FALSE(s.state.result.covariance_available);
  EXPECT_TRUE(std::isnan(s.state.result.sd_b1));
}

TEST(ClappStages, FinishClappSaysWhatTheDataLeaveUndetermined) {
  PairsOnly s(LinearPairs(2e-5, 10));
  s.state.result.law = BendingLaw::FromSi(1e-5, 2e-5, 1e-7);  // κ0 = 50 /m
  s.state.result.kappa_max = 10.0;
  s.state.result.b2_observed = false;
  s.state.result.covariance_available = true;
  internal::FinishClapp(&s.state);
  EXPECT_TRUE(s.state.result.success);
  EXPECT_EQ(s.state.result.message,
            "Clapp fit converged; kappa0 = 0.5 /cm lies beyond the largest observed curvature "
            "0.1 /cm: b2 is not determined by the data");
  s.state.result.b2_observed = true;
  s.state.result.covariance_available = false;
  internal::FinishClapp(&s.state);
  EXPECT_EQ(s.state.result.message,
            "Clapp fit converged; covariance unavailable (the constants are not all determined "
            "by the data)");
}

}  // namespace
}  // namespace textile
