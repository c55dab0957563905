#include "textile/fit/profile_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "cost_functions/profile_model.h"
#include "law_parameters.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/polyline.h"

namespace textile {

namespace {

// A spline law has no (ln b1, ln b2, ln κ0) for the profile model: its strip is solved as it
// is, turned and lifted into the measurement frame (q = R(φ) c(s) + (0, offset), as the
// model does), and compared as a curve.
ProfileComparison CompareSplineStrip(const BendingLaw& law, double areal_density,
                                     const Profile& measured, double overhang, double offset,
                                     double rotation, int curve_samples) {
  ElasticaOptions options;
  options.rel_tol = 1e-10;
  options.num_samples = std::max(curve_samples, 2);
  const ElasticaProfile strip = SolveHeavyElastica(law, areal_density, overhang, options);
  if (!strip.converged) {
    throw ComputeError(measured.source +
                       ": the elastica did not converge for this law: " + strip.message);
  }
  const double c = std::cos(rotation), s = std::sin(rotation);
  std::vector<double> x(strip.x.size()), y(strip.y.size());
  for (size_t k = 0; k < x.size(); ++k) {
    x[k] = c * strip.x[k] - s * strip.y[k];
    y[k] = s * strip.x[k] + c * strip.y[k];
  }
  ProfileComparison comparison = CompareWithCurve(measured, x, y, offset);
  comparison.clamp_curvature = strip.clamp_curvature;
  return comparison;
}


// The model of `measured` evaluated at the law (with its derivatives when `jacobians`); throws
// as CompareWithElastica.
void SolveModel(internal::ProfileModel* model, const BendingLaw& law, const Profile& measured,
                double overhang, double offset, double rotation, bool jacobians) {
  // The model's parametrisation (ln b1, ln b2, ln κ0) holds every law but c1 = 0 with b1 ≠ b2
  // exactly; that one is approximated by κ0 = 1e6 /m, far beyond any textile curvature.
  const auto p = internal::ParametersFromLaw(law);
  const double rig[2] = {offset, rotation};
  if (!model->Update(p.data(), &overhang, rig, jacobians)) {
    throw ComputeError(measured.source + ": the elastica did not converge for this law");
  }
}

void CheckOverhang(const Profile& measured, double overhang) {
  CheckProfile(measured);
  if (!(overhang > 0.0) || !std::isfinite(overhang)) {
    throw InputError(measured.source + ": overhang must be a finite length > 0");
  }
}

}  // namespace

ProfileComparison CompareWithElastica(const BendingLaw& law, double areal_density,
                                      const Profile& measured, double overhang, double offset,
                                      double rotation, int curve_samples) {
  CheckOverhang(measured, overhang);
  if (law.is_spline())
    return CompareSplineStrip(law, areal_density, measured, overhang, offset, rotation,
                              curve_samples);
  internal::ProfileModel model(measured, areal_density, curve_samples, 1e-10);
  SolveModel(&model, law, measured, overhang, offset, rotation, false);
  ProfileComparison c;
  double s2 = 0.0;
  for (int j = 0; j < model.num_points(); ++j) {
    const double d = model.residual(j) * 1e-3;
    s2 += d * d;
    c.max = std::max(c.max, std::abs(d));
    c.distances.push_back(std::abs(d));
  }
  c.rms = std::sqrt(s2 / model.num_points());
  c.tip_dx = model.tip_residual()[0] * 1e-3;
  c.tip_dy = model.tip_residual()[1] * 1e-3;
  c.clamp_curvature = model.solution().clamp_curvature;
  model.ModelCurve(&c.model_x, &c.model_y);
  return c;
}

CurveSpread ElasticaSpread(const BendingLaw& law, double areal_density, const Profile& measured,
                           double overhang, double offset, double rotation,
                           const Eigen::Matrix3d& covariance, int curve_samples) {
  CheckOverhang(measured, overhang);
  if (!covariance.allFinite()) {
    throw InputError(measured.source + ": the law's covariance has a non-finite entry");
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (law.is_spline()) return {nan, nan, nan};  // its covariance is of knots, not (b1, b2, c1)
  const double b1 = law.b1(), b2 = law.b2(), c1 = law.c1(), k0 = law.kappa0();
  if (!(k0 > internal::kMinKappa0) || !(k0 < internal::kMaxKappa0)) return {nan, nan, nan};
  internal::ProfileModel model(measured, areal_density, curve_samples, 1e-10);
  SolveModel(&model, law, measured, overhang, offset, rotation, true);
  // ∂(ln b1, ln b2, ln κ0)/∂(b1, b2, c1) at the law, κ0 = (b2 − b1) / (2 c1): the model's
  // gradients are in its own parameters, the covariance in the constants.
  Eigen::Matrix3d dp;
  dp << 1.0 / b1, 0.0, 0.0,  //
      0.0, 1.0 / b2, 0.0,    //
      -1.0 / (2.0 * k0 * c1), 1.0 / (2.0 * k0 * c1), -1.0 / c1;
  const auto to_constants = [&](const std::array<double, 6>& g) -> Eigen::RowVector3d {
    // [mm per unit of p] -> [m per unit of (b1, b2, c1)]
    return Eigen::RowVector3d(g[0], g[1], g[2]) * dp * 1e-3;
  };
  CurveSpread spread;
  double s2 = 0.0;
  for (int j = 0; j < model.num_points(); ++j) {
    const Eigen::RowVector3d J = to_constants(model.gradient(j));
    const double var = std::max(0.0, (J * covariance * J.transpose())(0, 0));
    s2 += var;
    spread.max = std::max(spread.max, std::sqrt(var));
  }
  spread.rms = std::sqrt(s2 / model.num_points());
  double tip2 = 0.0;
  for (int c = 0; c < 2; ++c) {
    const Eigen::RowVector3d J = to_constants(model.tip_gradient()[c]);
    tip2 += std::max(0.0, (J * covariance * J.transpose())(0, 0));
  }
  spread.tip = std::sqrt(tip2);
  return spread;
}

namespace {

// Points of the uniform Catmull-Rom spline through (x_k, y_k), `per` samples per segment. The
// end segments use a ghost point on the parabola through the last three points (a straight
// continuation would flatten the ends: 30 µm off a 10 mm circle at 2 mm spacing).
void Densify(const std::vector<double>& x, const std::vector<double>& y, int per,
             std::vector<double>* dx, std::vector<double>* dy) {
  const size_t n = x.size();
  dx->clear();
  dy->clear();
  const auto at = [&](long k, const std::vector<double>& v) {
    if (k < 0) return n > 2 ? 3.0 * (v[0] - v[1]) + v[2] : 2.0 * v[0] - v[1];
    if (k >= static_cast<long>(n))
      return n > 2 ? 3.0 * (v[n - 1] - v[n - 2]) + v[n - 3] : 2.0 * v[n - 1] - v[n - 2];
    return v[static_cast<size_t>(k)];
  };
  for (size_t k = 0; k + 1 < n; ++k) {
    const long i = static_cast<long>(k);
    for (int q = 0; q < per; ++q) {
      const double t = static_cast<double>(q) / per, t2 = t * t, t3 = t2 * t;
      const double w0 = -0.5 * t3 + t2 - 0.5 * t, w1 = 1.5 * t3 - 2.5 * t2 + 1.0,
                   w2 = -1.5 * t3 + 2.0 * t2 + 0.5 * t, w3 = 0.5 * t3 - 0.5 * t2;
      for (int c = 0; c < 2; ++c) {
        const std::vector<double>& v = c == 0 ? x : y;
        const double p = w0 * at(i - 1, v) + w1 * at(i, v) + w2 * at(i + 1, v) + w3 * at(i + 2, v);
        (c == 0 ? dx : dy)->push_back(p);
      }
    }
  }
  dx->push_back(x.back());
  dy->push_back(y.back());
}

}  // namespace

ProfileComparison CompareWithCurve(const Profile& measured, const std::vector<double>& curve_x,
                                   const std::vector<double>& curve_y, double offset) {
  CheckProfile(measured);
  if (curve_x.size() != curve_y.size() || curve_x.size() < 2) {
    throw InputError(measured.source + ": a simulated curve needs at least 2 points");
  }
  for (size_t k = 0; k < curve_x.size(); ++k) {
    if (!std::isfinite(curve_x[k]) || !std::isfinite(curve_y[k])) {
      throw InputError(measured.source + ": the simulated curve has a non-finite point");
    }
  }
  if (!std::isfinite(offset)) throw InputError(measured.source + ": offset must be finite");
  ProfileComparison c;
  Densify(curve_x, curve_y, 8, &c.model_x, &c.model_y);
  for (double& y : c.model_y) y += offset;
  double s2 = 0.0;
  for (size_t j = 0; j < measured.size(); ++j) {
    // Beyond an end of the curve: the distance from that end's tangent line.
    const double dist = DistanceToPolyline(c.model_x, c.model_y, measured.x[j], measured.y[j],
                                           /*extend_ends=*/true);
    s2 += dist * dist;
    c.max = std::max(c.max, dist);
    c.distances.push_back(dist);
  }
  c.rms = std::sqrt(s2 / static_cast<double>(measured.size()));
  c.tip_dx = c.model_x.back() - measured.x.back();
  c.tip_dy = c.model_y.back() - measured.y.back();
  c.clamp_curvature = std::numeric_limits<double>::quiet_NaN();
  return c;
}

}  // namespace textile
