#include "elastica/elastica_stages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace textile::sim_internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(ElasticaSamples, UniformSamplesEndExactlyAtTheTip) {
  ElasticaOptions options;
  options.num_samples = 3;
  const ElasticaSamples s = SampleArcLengths(0.3, options);
  ASSERT_EQ(s.arc.size(), 3u);
  EXPECT_EQ(s.arc[0], 0.0);
  EXPECT_EQ(s.arc[2], 0.3);
  // t runs from the tip: exact fractions, ascending.
  EXPECT_EQ(s.targets[0], 0.0);
  EXPECT_EQ(s.targets[1], 0.5);
  EXPECT_EQ(s.targets[2], 1.0);
}

TEST(ElasticaSamples, RequestedArcLengthsAreKeptAndReversedIntoT) {
  ElasticaOptions options;
  options.arc_lengths = {0.0, 0.05, 0.1};
  const ElasticaSamples s = SampleArcLengths(0.2, options);
  EXPECT_EQ(s.arc, options.arc_lengths);
  ASSERT_EQ(s.targets.size(), 3u);
  EXPECT_EQ(s.targets[0], 0.5);   // s = 0.1
  EXPECT_DOUBLE_EQ(s.targets[1], 0.75);  // s = 0.05, (L - s)/L rounded
  EXPECT_EQ(s.targets[2], 1.0);   // s = 0, the edge
}

TEST(ShootingUpdate, UndershotWithoutUpperBoundDoublesTheUnknown) {
  ShootingState st;
  st.z = 0.8;
  UpdateShooting({.reached_clamp = false}, false, 1e-6, &st);
  EXPECT_EQ(st.lo, 0.8);
  EXPECT_EQ(st.hi, kInf);
  EXPECT_EQ(st.z, 1.8);  // max(2z, z + 1)
  EXPECT_FALSE(st.done);
  EXPECT_EQ(st.phase, ShootingPhase::kCoarse);
}

TEST(ShootingUpdate, NewtonStepOutsideTheBracketBisects) {
  ShootingState st;
  st.z = 1.0;
  st.lo = 0.5;
  // Overshoot (residual > 0) with a Newton step to z = 1 - 1/0.1 = -9, below lo.
  UpdateShooting({.reached_clamp = true, .residual = 1.0, .slope = 0.1}, false, 1e-6, &st);
  EXPECT_EQ(st.hi, 1.0);
  EXPECT_EQ(st.z, 0.75);
  EXPECT_EQ(st.phase, ShootingPhase::kCoarse);
}

TEST(ShootingUpdate, SettledNewtonGoesToTheFinePassOnlyWithSensitivities) {
  const ShotOutcome small{.reached_clamp = true, .residual = 1e-6, .slope = 1.0};
  ShootingState plain{.z = 1.0};
  UpdateShooting(small, false, 1e-6, &plain);
  EXPECT_EQ(plain.phase, ShootingPhase::kFinal);
  EXPECT_DOUBLE_EQ(plain.z, 1.0 - 1e-6);
  ShootingState sens{.z = 1.0};
  UpdateShooting(small, true, 1e-6, &sens);
  EXPECT_EQ(sens.phase, ShootingPhase::kFine);
}

TEST(ShootingUpdate, FinalPassAcceptsASmallStepAsTheCorrection) {
  ShootingState st{.z = 1.0, .phase = ShootingPhase::kFinal};
  UpdateShooting({.reached_clamp = true, .residual = 1e-8, .slope = 1.0}, false, 1e-6, &st);
  EXPECT_TRUE(st.done);
  EXPECT_EQ(st.z, 1.0);
  // z - r/slope - z: exact to the rounding of z (an ulp of 1).
  EXPECT_NEAR(st.correction, -1e-8, 1e-15);
}

TEST(ShootingUpdate, FinalPassWithALargeStepGoesBackToCoarse) {
  ShootingState st{.z = 1.0, .phase = ShootingPhase::kFinal};
  UpdateShooting({.reached_clamp = true, .residual = 0.1, .slope = 1.0}, false, 1e-6, &st);
  EXPECT_FALSE(st.done);
  EXPECT_EQ(st.phase, ShootingPhase::kCoarse);
  EXPECT_DOUBLE_EQ(st.z, 0.9);
}

TEST(ShootingUpdate, CollapsedBracketIsTakenAsTheRoot) {
  ShootingState st{.z = 1.0, .lo = 1.0};
  // No Newton step (slope 0): would bisect, but [lo, hi] is at rounding already.
  UpdateShooting({.reached_clamp = true, .residual = 1e-3, .slope = 0.0}, false, 1e-6, &st);
  EXPECT_EQ(st.phase, ShootingPhase::kFinal);
  EXPECT_EQ(st.z, 1.0);
}

}  // namespace
}  // namespace textile::sim_internal
