#ifndef TEXTILE_FIT_PROFILE_COMPARE_H_
#define TEXTILE_FIT_PROFILE_COMPARE_H_

// Measured profile against a simulated one: how far apart, in mm, as a technician would judge
// (docs/spec/cantilever.md, "Closing the loop"). Used by fit reports (for every method alike, so
// Clapp and the direct fit are graded the same way) and by validation.
//
//   textile::ProfileComparison c = textile::CompareWithElastica(law, 0.2, measured, 0.06, 0.0);
//   // c.rms, c.max [m]: normal distances of the measured points to the simulated curve

#include <vector>

#include <Eigen/Core>

#include "textile/fit/profile.h"
#include "textile/sim/law/bending_law.h"

namespace textile {

struct ProfileComparison {
  double rms = 0.0;       // RMS normal distance of the measured points to the curve [m]
  double max = 0.0;       // largest normal distance [m]
  double tip_dx = 0.0;    // simulated minus measured tip, x [m]
  double tip_dy = 0.0;    // simulated minus measured tip, y [m]
  double clamp_curvature = 0.0;  // κ(0) of the simulated strip [1/m]
  std::vector<double> model_x, model_y;  // the simulated curve, measurement frame [m]
  std::vector<double> distances;  // each measured point's distance, as rms and max count it [m]
};

// Simulates the strip (law [SI], areal density [kg/m²], overhang [m]) and compares it with
// the measured profile, the simulation lifted by `offset` [m] (the mid-line's height at the
// edge) and turned by `rotation` [rad] about the edge (a fitted rig tilt). Throws ComputeError if
// the elastica fails, InputError for bad arguments. A spline law's strip is compared as a curve
// of curve_samples points (CompareWithCurve below; clamp_curvature is then the strip's).
ProfileComparison CompareWithElastica(const BendingLaw& law, double areal_density,
                                      const Profile& measured, double overhang, double offset,
                                      double rotation = 0.0, int curve_samples = 201);

// The same comparison against a simulated curve given as points (x_k, y_k) [m] in the
// profile's frame before the offset, from the edge to the free end (at least 2), e.g. the shell
// model's centre line: the points are joined by a Catmull-Rom spline (a polyline through
// 2 mm-spaced points would miss the curve by up to h²/8R, 0.05 mm at R = 10 mm) and the
// distances are those of CompareWithElastica (normal distance; beyond an end, the distance from
// the end's tangent line). clamp_curvature is NaN. Throws InputError for bad arguments.
ProfileComparison CompareWithCurve(const Profile& measured, const std::vector<double>& curve_x,
                                   const std::vector<double>& curve_y, double offset);

// How far the simulated curve of CompareWithElastica moves when the law moves within a
// covariance of {b1, b2, c1} [SI] (DirectFitSummary::covariance), the overhang, offset and
// rotation held. Linear propagation through the elastica's variational equations (the direct
// fit's own analytic derivatives, docs/methods/fitting.md): J_j = ∂(normal distance of point j)/∂(b1,
// b2, c1), and the curve's normal displacement at point j has variance σ_j² = J_j C J_jᵀ; the
// tip's 2×2 covariance is J_tip C J_tipᵀ. Each figure bounds how far the comparison's own
// figure can move when the curve moves by it (rms: triangle inequality; max; tip distance).
struct CurveSpread {
  double rms = 0.0;  // √(mean σ_j²) over the measured points [m]
  double max = 0.0;  // max σ_j [m]
  double tip = 0.0;  // √trace of the tip's covariance [m]
};

// The spread of CompareWithElastica(law, areal_density, measured, overhang, offset, rotation)
// under `covariance` (3×3, symmetric positive semi-definite, SI). NaN figures for a law the
// fit's parametrisation (ln b1, ln b2, ln κ0) does not reach smoothly: κ0 = 0 (b1 = b2) or ∞
// (c1 = 0). Throws as CompareWithElastica; InputError for a non-finite covariance.
CurveSpread ElasticaSpread(const BendingLaw& law, double areal_density, const Profile& measured,
                           double overhang, double offset, double rotation,
                           const Eigen::Matrix3d& covariance, int curve_samples = 201);

}  // namespace textile

#endif  // TEXTILE_FIT_PROFILE_COMPARE_H_
