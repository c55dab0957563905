#ifndef TEXTILE_FIT_SRC_COST_FUNCTIONS_PROFILE_MODEL_H_
#define TEXTILE_FIT_SRC_COST_FUNCTIONS_PROFILE_MODEL_H_

// One measured profile against the heavy elastica, for Ceres. The elastica is solved once per
// parameter point and shared by the profile's residual blocks (one block per measured point,
// so that a robust loss acts per point, plus one for the tip).
//
// Parameter blocks: law p[3] = (ln b1, ln b2, ln κ0), overhang L[1] [m], rig r[2] = (vertical
// offset [m], rotation [rad]). Residuals are in mm (well scaled for the solver).

#include <ceres/ceres.h>

#include <array>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/sim/elastica/elastica.h"

namespace textile::internal {

// The nearest point of an elastica curve to d = (dx, dy) (model frame): the nearest sample,
// then Gauss-Newton on the cubic Hermite segment through it; (x, y) and d/ds there [m].
struct FootPoint {
  int seg = 0;
  double t = 0.0;  // in [0, 1] along the segment
  double x = 0.0, y = 0.0, dx = 0.0, dy = 0.0;
};
FootPoint FindFootPoint(const ElasticaProfile& e, double dx, double dy);

// The residuals ProfileModel computes, without derivatives, for any solved curve: the signed
// normal distance [mm] of each data point (measurement frame [m]) under the rig (offset [m],
// rotation [rad]), and the tip (model minus measured, x and y [mm]).
void CurveResiduals(const ElasticaProfile& e, const std::vector<double>& data_x,
                    const std::vector<double>& data_y, const double* rig,
                    std::vector<double>* residual, std::array<double, 2>* tip);

class ProfileModel {
 public:
  // profile: the data [m]; areal_density [kg/m²]; samples: elastica samples along the curve.
  ProfileModel(const Profile& profile, double areal_density, int samples, double tol);

  // Evaluates all residuals at (p, L, r); with jacobians, also their derivatives. Cached: a
  // second call with the same parameters is free. False if the elastica fails there.
  bool Update(const double* p, const double* length, const double* rig, bool jacobians);

  int num_points() const { return static_cast<int>(data_x_.size()); }
  // Normal distance of point j to the model curve [mm] and its gradient w.r.t. p, L, r.
  double residual(int j) const { return residual_[j]; }
  const std::array<double, 6>& gradient(int j) const { return gradient_[j]; }
  // Tip: model tip minus measured tip [mm], and its 2×6 gradient.
  const std::array<double, 2>& tip_residual() const { return tip_residual_; }
  const std::array<std::array<double, 6>, 2>& tip_gradient() const { return tip_gradient_; }
  // Solution at the last update (for reports and plots).
  const ElasticaProfile& solution() const { return solution_; }
  // Model curve in the measurement frame at the last update, dense [m].
  void ModelCurve(std::vector<double>* x, std::vector<double>* y) const;

 private:
  std::vector<double> data_x_, data_y_;
  double areal_density_;
  int samples_;
  double tol_;

  std::array<double, 6> cached_params_{};
  bool cached_valid_ = false, cached_jacobians_ = false;
  ElasticaProfile solution_;
  double rig_offset_ = 0.0, rig_rotation_ = 0.0;

  std::vector<double> residual_;
  std::vector<std::array<double, 6>> gradient_;
  std::array<double, 2> tip_residual_{};
  std::array<std::array<double, 6>, 2> tip_gradient_{};
};

// Residual of measured point j: Ceres block with one residual.
class PointResidual : public ceres::SizedCostFunction<1, 3, 1, 2> {
 public:
  PointResidual(ProfileModel* model, int j) : model_(model), j_(j) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  ProfileModel* model_;
  int j_;
};

// Residual of the tip position: two residuals (x, y) [mm].
class TipResidual : public ceres::SizedCostFunction<2, 3, 1, 2> {
 public:
  explicit TipResidual(ProfileModel* model) : model_(model) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  ProfileModel* model_;
};

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_COST_FUNCTIONS_PROFILE_MODEL_H_
