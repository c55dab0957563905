#ifndef TEXTILE_FIT_SRC_COST_FUNCTIONS_CLAPP_LAW_COST_H_
#define TEXTILE_FIT_SRC_COST_FUNCTIONS_CLAPP_LAW_COST_H_

// Residual of one (κ, M) pair of Clapp's method against eq. 1 of Pabst et al.:
//
//   r = (M_law(κ; p) - M) / M_scale,   p = (ln b1, ln b2, ln κ0)   (law_parameters.h)
//
// The residual is on M, as in Clapp et al. and Pabst et al. ("a quadratic regression and a
// linear regression are taken from the moment-curvature curves": M regressed on κ). M_scale
// (the largest observed moment) only makes the residuals O(1) for Ceres' tolerances.
//
//   problem.AddResidualBlock(
//       new ceres::AutoDiffCostFunction<ClappLawCost, 1, 3>(new ClappLawCost(k, m, m_max)),
//       nullptr, p.data());

#include "law_parameters.h"

namespace textile::internal {

class ClappLawCost {
 public:
  // kappa [1/m], moment [N], moment_scale [N] > 0.
  ClappLawCost(double kappa, double moment, double moment_scale)
      : kappa_(kappa), moment_(moment), inv_scale_(1.0 / moment_scale) {}

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = (LawMoment(p, T(kappa_)) - moment_) * inv_scale_;
    return true;
  }

 private:
  double kappa_, moment_, inv_scale_;
};

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_COST_FUNCTIONS_CLAPP_LAW_COST_H_
