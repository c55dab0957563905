#ifndef TEXTILE_FIT_LAW_ERROR_H_
#define TEXTILE_FIT_LAW_ERROR_H_

// How far a fitted moment-curvature law is from the truth, in the project's one standard
// measure (used by tests and the fit-accuracy benchmark for every fitting method):
//
//   e = sqrt( (1/κmax) ∫₀^κmax (M_fit(κ) - M_true(κ))² dκ ) / M_true(κmax)
//
// i.e. the RMS moment error over the observed curvature range, relative to the largest
// observed moment. Constants are compared through the curve because they are not separately
// identifiable (a linear law has any κ0; b2 is unobserved when κ0 > κmax).
//
//   textile::BendingLaw truth = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   double e = textile::MomentCurveError(fitted, truth, 120.0);  // 0.01 = 1 %

#include "textile/sim/law/bending_law.h"

namespace textile {

// @param fit        the law to judge
// @param truth      the reference law
// @param kappa_max  upper end of the curvature range [1/m], > 0 (the largest curvature the
//                   data showed)
// @return           the relative RMS error above (dimensionless; 0.01 = 1 %)
// Throws InputError when kappa_max is not a positive finite number. Exact up to rounding:
// the squared difference is a piecewise quartic (a sextic where a spline law is involved),
// integrated by Gauss-Legendre per piece between the laws' breakpoints.
double MomentCurveError(const BendingLaw& fit, const BendingLaw& truth, double kappa_max);

}  // namespace textile

#endif  // TEXTILE_FIT_LAW_ERROR_H_
