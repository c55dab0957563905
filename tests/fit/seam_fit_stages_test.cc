// The stages of FitSeamFactor (seam_fit_stages.h), each on a state set up by hand.

#include "seam_fit_stages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

using internal::SeamFitState;

std::string InputErrorOf(SeamFitState* state) {
  try {
    internal::CheckSeamData(state);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SeamFitStages, CheckSeamDataSetsTheShapeOfTheData) {
  const std::vector<SeamSample> samples = {
      {0, 3.0, 0.1}, {10, 2.5, 0.1}, {10, 2.4, 0.1}, {30, 1.8, 0.2}};
  const SeamFitOptions options;
  SeamFitState state(samples, options);
  internal::CheckSeamData(&state);
  EXPECT_EQ(state.fit.num_points, 4);
  EXPECT_EQ(state.fit.distinct_distances, 3);
  EXPECT_EQ(state.fit.dof, 1);
  EXPECT_TRUE(state.fit.weighted);
  EXPECT_EQ(state.fit.range_mm[0], 0.0);
  EXPECT_EQ(state.fit.range_mm[1], 30.0);
}

TEST(SeamFitStages, CheckSeamDataRefusesSdOnSomePointsOnly) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<SeamSample> samples = {{0, 3.0, 0.1}, {10, 2.5, nan}, {20, 2.0, nan}};
  const SeamFitOptions options;
  SeamFitState state(samples, options);
  EXPECT_EQ(InputErrorOf(&state), "sd is given for 1 of 3 points: give it for all or none");
}

TEST(SeamFitStages, CheckSeamDataRefusesEveryFactorBelowOne) {
  const std::vector<SeamSample> samples = {{0, 0.5}, {10, 0.8}, {20, 0.9}};
  const SeamFitOptions options;
  SeamFitState state(samples, options);
  const std::string what = InputErrorOf(&state);
  EXPECT_NE(what.find("every factor is below 1 (0.5 to 0.9)"), std::string::npos) << what;
  EXPECT_NE(what.find("Its inverse is 1.111 to 2"), std::string::npos) << what;
}

// A state as the fit leaves it before JudgeSeamFit, for the verdicts below.
SeamFitSummary Fitted(bool weighted, int dof) {
  SeamFitSummary fit;
  fit.weighted = weighted;
  fit.dof = dof;
  return fit;
}

TEST(SeamFitStages, JudgeSeamFitFlagsAChi2TooLargeForTheStatedSd) {
  const std::vector<SeamSample> none;
  const SeamFitOptions options;  // poor below Q = 1e-3
  SeamFitState state(none, options);
  state.fit = Fitted(true, 2);
  state.fit.chi2 = 30.0;
  state.fit.chi2_probability = 3e-7;
  internal::JudgeSeamFit(&state);
  EXPECT_TRUE(state.fit.poor);
  EXPECT_EQ(state.fit.poor_reason,
            "residuals too large for the stated sd: chi2/dof = 15, Q(chi2, 2) = 3e-07 < 0.001");
  // No degrees of freedom: nothing to judge by.
  state.fit = Fitted(true, 0);
  state.fit.chi2_probability = 0.0;
  internal::JudgeSeamFit(&state);
  EXPECT_FALSE(state.fit.poor);
}

TEST(SeamFitStages, JudgeSeamFitNeedsLowR2AndResidualsThatMatter) {
  const std::vector<SeamSample> none;
  const SeamFitOptions options;  // r² < 0.9 and rms > 5 % of the mean factor
  SeamFitState state(none, options);
  state.mean_factor = 2.0;
  // A flat profile: r² low from round-off, residuals negligible against the factor.
  state.fit = Fitted(false, 3);
  state.fit.r2 = 0.1;
  state.fit.rms = 0.001;
  state.fit.rms_relative = 0.0005;
  internal::JudgeSeamFit(&state);
  EXPECT_FALSE(state.fit.poor);
  // Undefined r² with large residuals: poor, said as "none".
  state.fit.r2 = std::numeric_limits<double>::quiet_NaN();
  state.fit.rms = 0.2;
  state.fit.rms_relative = 0.1;
  internal::JudgeSeamFit(&state);
  EXPECT_TRUE(state.fit.poor);
  EXPECT_EQ(state.fit.poor_reason,
            "the quadratic explains only none of the factor's variance (r2 < 0.9) and its rms "
            "residual 0.2 is 10 % of the mean factor 2 (> 5 %)");
}

// The falling fit of seam-ok.csv (d 0-30 mm): minimum 1.671 at 42.33 mm, 4.165 at 100 mm.
SeamFitState FallingState(const std::vector<SeamSample>& samples, const SeamFitOptions& options) {
  SeamFitState state(samples, options);
  internal::CheckSeamData(&state);
  internal::SolveSeamQuadratic(&state);
  internal::MeasureSeamResiduals(&state);
  internal::StartSeamProfile(&state);
  return state;
}
const std::vector<SeamSample> kFalling = {{0, 3.0}, {10, 2.5}, {20, 2.0}, {30, 1.8}};

TEST(SeamFitStages, StartSeamProfileTakesTheInfluenceRangeFromTheDataUnlessGiven) {
  SeamFitOptions options;
  SeamFitState from_data = FallingState(kFalling, options);
  EXPECT_TRUE(from_data.fit.influence_from_data);
  EXPECT_EQ(from_data.fit.profile.influence_mm, 30.0);
  EXPECT_EQ(from_data.fit.profile.type, "fitted");
  options.influence_mm = 20.0;
  SeamFitState given = FallingState(kFalling, options);
  EXPECT_FALSE(given.fit.influence_from_data);
  EXPECT_EQ(given.fit.profile.influence_mm, 20.0);
}

TEST(SeamFitStages, CheckExtrapolationRefusesARiseAndNotesAnExplicitReach) {
  SeamFitOptions options;
  options.influence_mm = 100.0;
  SeamFitState rising = FallingState(kFalling, options);
  EXPECT_THROW(internal::CheckExtrapolation(&rising), InputError);
  options.influence_mm = 40.0;  // up to the minimum it only falls
  SeamFitState falling = FallingState(kFalling, options);
  internal::CheckExtrapolation(&falling);
  ASSERT_EQ(falling.fit.notes.size(), 1u);
  EXPECT_EQ(falling.fit.notes[0].code, "influence_beyond_data");
  // Within the data there is nothing to check or say.
  options.influence_mm = 20.0;
  SeamFitState inside = FallingState(kFalling, options);
  internal::CheckExtrapolation(&inside);
  EXPECT_TRUE(inside.fit.notes.empty());
}

TEST(SeamFitStages, NoteInfluenceInsideDataNamesThePointsCutOff) {
  SeamFitOptions options;
  options.influence_mm = 10.0;
  SeamFitState state = FallingState(kFalling, options);
  internal::NoteInfluenceInsideData(&state);
  ASSERT_EQ(state.fit.notes.size(), 1u);
  EXPECT_EQ(state.fit.notes[0].code, "influence_inside_data");
  EXPECT_NE(state.fit.notes[0].text.find("at 2 point(s) beyond it"), std::string::npos)
      << state.fit.notes[0].text;
  const SeamFitOptions defaults;
  SeamFitState whole = FallingState(kFalling, defaults);
  internal::NoteInfluenceInsideData(&whole);
  EXPECT_TRUE(whole.fit.notes.empty());
}

TEST(SeamFitStages, NoteFadeOvershootOnlyForAFitRisingAtDMax) {
  const std::vector<SeamSample> rising = {{0, 3.0}, {20, 2.0}, {40, 1.8}, {60, 2.2}};
  const SeamFitOptions options;
  SeamFitState state = FallingState(rising, options);
  internal::NoteFadeOvershoot(&state);
  ASSERT_EQ(state.fit.notes.size(), 1u);
  EXPECT_EQ(state.fit.notes[0].code, "fade_overshoot");
  SeamFitState falling = FallingState(kFalling, options);
  internal::NoteFadeOvershoot(&falling);
  EXPECT_TRUE(falling.fit.notes.empty());
}

}  // namespace
}  // namespace textile
