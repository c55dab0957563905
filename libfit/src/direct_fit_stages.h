#ifndef TEXTILE_FIT_SRC_DIRECT_FIT_STAGES_H_
#define TEXTILE_FIT_SRC_DIRECT_FIT_STAGES_H_

// The decisions inside one solve of the direct fit (direct_fit.cc, FitDirectFrom), as stages a
// test can run without a Ceres problem. FitDirectFrom runs, over its state:
//   build the problem (models, residuals, overhang bounds) -> BoundLaw (LogStiffnessBounds) ->
//   prior and rig -> solve -> solve again with the prior rescaled (RescaledPriorWeight) ->
//   convergence and the final state -> per-profile statistics -> RefuseMixedStrips ->
//   PinnedBoundMessage -> CovarianceFromJacobian -> ObserveConstants -> summary.
// Not public API.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "textile/fit/direct_fit.h"
#include "textile/fit/profile.h"
#include "textile/sim/law/bending_law.h"

namespace textile::internal {

// Bounds of ln b1 and ln b2 for a start of stiffness b_centre [N·m]: within a factor 100 of it
// and inside the textile range that material files accept. None when the two do not overlap
// (the profiles' shape asks for a stiffness no textile has).
std::optional<std::array<double, 2>> LogStiffnessBounds(double b_centre);

// The prior's weight for a first solve whose points' rms is rms_mm [mm], when it differs from
// current_weight by more than a factor 1.25 (else none: the first solve stands).
std::optional<double> RescaledPriorWeight(double rms_mm, double current_weight);

// Throws InputError when several profiles fit one law badly (fit.rms above outlier_profile_rms)
// while each alone fits at least 3× better: profiles of different strips. rms_alone(p) is the
// rms of a fit of p alone [m] (infinite when it fails); called only when the joint fit is bad.
// The message names the profile that fits worst together (fit.profiles[i].rms).
void RefuseMixedStrips(const std::vector<Profile>& profiles, const DirectFitSummary& fit,
                       double outlier_profile_rms,
                       const std::function<double(const Profile&)>& rms_alone);

// Why a law p = (ln b1, ln b2, ln κ0) on (within 1e-6 of) a bound of ln b1 or ln b2 is no fit;
// empty when neither is.
std::string PinnedBoundMessage(const std::array<double, 3>& law_p,
                               const std::array<double, 2>& lower,
                               const std::array<double, 2>& upper);

// Covariance of (b1, b2, c1) and their 1-σ from the Jacobian of the residuals [mm] over the free
// parameters, the law's first (ln b1, ln b2, ln κ0): (JᵀJ)⁺ sigma2 [mm²] by SVD, propagated to
// the constants. A constant whose direction lies mostly in J's null space gets an sd of NaN.
// Sets fit->covariance, b1_sd, b2_sd, c1_sd.
void CovarianceFromJacobian(const Eigen::MatrixXd& free_jacobian, double sigma2,
                            const BendingLaw& law, double log_kappa0, DirectFitSummary* fit);

// Which constants the data determine (docs/spec/cantilever.md), from fit->kappa_max and the sds:
// sets b1_observed, b2_observed, c1_observed and the observability sentence. When κ0 lies
// beyond kappa_max, b2 is not observed: its sd becomes NaN and *law takes as b2 the slope at
// kappa_max (where that is positive).
void ObserveConstants(BendingLaw* law, DirectFitSummary* fit);

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_DIRECT_FIT_STAGES_H_
