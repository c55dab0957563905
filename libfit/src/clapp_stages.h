#ifndef TEXTILE_FIT_SRC_CLAPP_STAGES_H_
#define TEXTILE_FIT_SRC_CLAPP_STAGES_H_

// The stages of FitClapp (clapp.h), in the order it runs them over one state: the smooth curve
// of each profile, the pooled (κ, M) pairs' scales, the regression's starts and bounds, the
// regression from each start, the law of the best, its covariance and the closing message. A
// stage that returns false has set result.message and the fit ends there, without a law. Not
// public API: declared here so that tests can run a stage on a state they set up.

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "deadline.h"
#include "textile/fit/clapp.h"

namespace textile::internal {

struct ClappFitState {
  ClappFitState(const std::vector<Profile>& profiles, double areal_density,
                const ClappOptions& options)
      : profiles(profiles),
        areal_density(areal_density),
        options(options),
        deadline(options.max_seconds) {}

  const std::vector<Profile>& profiles;
  double areal_density;  // ρ [kg/m²]
  const ClappOptions& options;
  fit_internal::Deadline deadline;  // options.max_seconds, from the state's making
  ClappResult result;               // filled stage by stage
  double moment_max = 0.0;          // largest |M| of the pairs [N]
  double linear_stiffness = 0.0;    // least-squares B of M ≈ B κ [N·m]
  // Starts of the regression and its bounds, p = (ln b1, ln b2, ln κ0).
  std::vector<std::array<double, 3>> starts;
  std::array<double, 3> lower{}, upper{};
  // The converged start of lowest cost (best_cost infinite: none yet).
  std::array<double, 3> best{};
  double best_cost = std::numeric_limits<double>::infinity();
};

// 1. Options, density and profiles given; throws InputError.
void CheckClappInput(const ClappFitState& state);

// 2. Each profile's smooth curve and its (κ, M) pairs, pooled in result.profiles and
// result.points (steps 1-4 of clapp.h). Throws InputError naming a profile that has too few points.
void PoolClappPairs(ClappFitState* state);

// 3. The pairs' scales: result.kappa_max, moment_max, linear_stiffness. False (with the message)
// for a strip that does not bend, or whose moment does not grow with its curvature.
bool MeasureClappScales(ClappFitState* state);

// 4. The regression's starts, κ0 spread geometrically over [0.1, 2] κ_max (0.5 κ_max for one),
// each with the least-squares (b1, b2) for its κ0 (b1 = b2 = linear_stiffness where those are
// not positive), and the bounds of p; the starts lie within the bounds.
void PlaceClappStarts(ClappFitState* state);

// 5. The regression of eq. 1 from each start, keeping the converged one of lowest cost. False
// (with the message) when the time cap is reached or no start converges.
bool RunClappStarts(ClappFitState* state);

// 6. result.law from the best start; false (with the message) when it is no valid law.
bool ClappLawFromBest(ClappFitState* state);

// 7. result.moment_rms and b2_observed (κ0 within the data's curvatures).
void MeasureClappMisfit(ClappFitState* state);

// 8. 1-σ of b1, b2, c1 from the regression's JᵀJ; NaN (covariance_available false) when fewer
// than four pairs, a parameter on its bound or JᵀJ near singular.
void ClappCovariance(ClappFitState* state);

// 9. result.success and the message of a fit that succeeded: what the data leave undetermined.
void FinishClapp(ClappFitState* state);

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_CLAPP_STAGES_H_
