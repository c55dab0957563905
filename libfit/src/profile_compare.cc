#include "textile/fit/profile_compare.h"

#include <cmath>

#include "cost_functions/profile_model.h"
#include "law_parameters.h"
#include "textile/sim/error.h"

namespace textile {

ProfileComparison CompareWithElastica(const BendingLaw& law, double areal_density,
                                      const Profile& measured, double overhang, double offset,
                                      int curve_samples) {
  CheckProfile(measured);
  if (!(overhang > 0.0) || !std::isfinite(overhang)) {
    throw InputError(measured.source + ": overhang must be a finite length > 0");
  }
  internal::ProfileModel model(measured, areal_density, curve_samples, 1e-10);
  // The model's parametrisation (ln b1, ln b2, ln κ0) holds every law but c1 = 0 with b1 ≠ b2
  // exactly; that one is approximated by κ0 = 1e6 /m, far beyond any textile curvature.
  const auto p = internal::ParametersFromLaw(law);
  const double rig[2] = {offset, 0.0};
  if (!model.Update(p.data(), &overhang, rig, false)) {
    throw ComputeError(measured.source + ": the elastica did not converge for this law");
  }
  ProfileComparison c;
  double s2 = 0.0;
  for (int j = 0; j < model.num_points(); ++j) {
    const double d = model.residual(j) * 1e-3;
    s2 += d * d;
    c.max = std::max(c.max, std::abs(d));
  }
  c.rms = std::sqrt(s2 / model.num_points());
  c.tip_dx = model.tip_residual()[0] * 1e-3;
  c.tip_dy = model.tip_residual()[1] * 1e-3;
  c.clamp_curvature = model.solution().clamp_curvature;
  model.ModelCurve(&c.model_x, &c.model_y);
  return c;
}

}  // namespace textile
