#ifndef TEXTILE_FIT_SRC_SEAM_FIT_STAGES_H_
#define TEXTILE_FIT_SRC_SEAM_FIT_STAGES_H_

// The stages of FitSeamFactor (seam_fit.h), in the order it runs them over one state. Each
// stage reads what the stages before it filled in and throws for its own failure. Not public
// API: declared here so that tests can run a stage on a state they set up.
//
//   internal::SeamFitState state(samples, options);
//   internal::CheckSeamData(&state);         // InputError: too few points, mixed sd, ...
//   internal::SolveSeamQuadratic(&state);    // coefficients, covariance, χ²
//   ...
//   internal::NoteFadeOvershoot(&state);

#include <set>
#include <vector>

#include "textile/fit/seam_fit.h"

namespace textile::internal {

struct SeamFitState {
  SeamFitState(const std::vector<SeamSample>& samples, const SeamFitOptions& options)
      : samples(samples), options(options) {}

  const std::vector<SeamSample>& samples;
  const SeamFitOptions& options;
  std::set<double> distinct;  // the samples' distances d [mm], ascending
  double mean_factor = 0.0;   // mean of the samples' factors [-]
  SeamFitSummary fit;         // filled stage by stage
};

// 1. Options valid, every sample valid, ≥ 3 points at ≥ 3 distinct d, sd on all points or none,
// some factor ≥ 1. Sets distinct, fit.num_points, distinct_distances, dof, weighted, range_mm.
// Throws InputError naming what is wrong.
void CheckSeamData(SeamFitState* state);

// 2. Weighted linear least squares (GSL) of B_f(d): fit.coefficients_mm, covariance (scaled by
// χ²/dof without sd, unknown for 3 points without sd), chi2, chi2_probability. Throws
// ComputeError when GSL fails.
void SolveSeamQuadratic(SeamFitState* state);

// 3. The residuals of the fitted quadratic: fit.rms, rms_relative, max_residual, r2, and
// mean_factor.
void MeasureSeamResiduals(SeamFitState* state);

// 4. Whether the fit is poor (seam_fit.h) and why: fit.poor, fit.poor_reason.
void JudgeSeamFit(SeamFitState* state);

// 5. The seam profile of type "fitted" and its influence range d_max: the largest d fitted
// (at least 1 mm) unless options.influence_mm is given.
void StartSeamProfile(SeamFitState* state);

// 6. An influence range beyond the data: refused (InputError) where B_f rises there by more than
// options.rise_tolerance, else noted ("influence_beyond_data") when given explicitly.
void CheckExtrapolation(SeamFitState* state);

// 7. The profile serves as a seam profile (SeamProfile::Check); else ComputeError.
void CheckSeamProfile(const SeamFitState& state);

// 8. An influence range inside the data: a note ("influence_inside_data") on how far S then
// departs from the points beyond it.
void NoteInfluenceInsideData(SeamFitState* state);

// 9. A fit still rising at d_max: the fade to 1 overshoots; a note ("fade_overshoot") when by
// more than options.rise_tolerance.
void NoteFadeOvershoot(SeamFitState* state);

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_SEAM_FIT_STAGES_H_
