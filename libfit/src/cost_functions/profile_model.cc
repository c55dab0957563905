#include "cost_functions/profile_model.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "law_parameters.h"
#include "textile/sim/core/error.h"

namespace textile::internal {
namespace {

constexpr double kMmPerM = 1e3;

// Cubic Hermite interpolation of the curve between samples k and k+1 with unit tangents
// (cos θ, -sin θ): position at local parameter t ∈ [0, 1] and its derivative d/ds.
struct CurvePoint {
  double x, y, dx, dy;
};

CurvePoint Hermite(const ElasticaProfile& e, int k, double t) {
  const double h = e.s[k + 1] - e.s[k];
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2,
               h11 = t3 - t2;
  const double d00 = (6 * t2 - 6 * t) / h, d10 = 3 * t2 - 4 * t + 1, d01 = (-6 * t2 + 6 * t) / h,
               d11 = 3 * t2 - 2 * t;
  const double tx0 = std::cos(e.theta[k]), ty0 = -std::sin(e.theta[k]);
  const double tx1 = std::cos(e.theta[k + 1]), ty1 = -std::sin(e.theta[k + 1]);
  return {h00 * e.x[k] + h10 * h * tx0 + h01 * e.x[k + 1] + h11 * h * tx1,
          h00 * e.y[k] + h10 * h * ty0 + h01 * e.y[k + 1] + h11 * h * ty1,
          d00 * e.x[k] + d10 * tx0 + d01 * e.x[k + 1] + d11 * tx1,
          d00 * e.y[k] + d10 * ty0 + d01 * e.y[k + 1] + d11 * ty1};
}

}  // namespace

FootPoint FindFootPoint(const ElasticaProfile& e, double dx, double dy) {
  const int n = static_cast<int>(e.s.size());
  int best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < n; ++k) {
    const double d2 = (e.x[k] - dx) * (e.x[k] - dx) + (e.y[k] - dy) * (e.y[k] - dy);
    if (d2 < best_d2) best_d2 = d2, best = k;
  }
  int seg = std::min(best, n - 2);
  double t = best == seg ? 0.0 : 1.0;
  for (int it = 0; it < 8; ++it) {
    const CurvePoint q = Hermite(e, seg, t);
    const double h = e.s[seg + 1] - e.s[seg];
    const double f = (q.x - dx) * q.dx + (q.y - dy) * q.dy;  // ½ d|q - d|²/ds
    const double step = -f / (q.dx * q.dx + q.dy * q.dy) / h;  // Gauss-Newton in t
    t += step;
    if (t < 0.0 && seg > 0) --seg, t += 1.0;
    else if (t > 1.0 && seg < n - 2) ++seg, t -= 1.0;
    t = std::clamp(t, 0.0, 1.0);
    if (std::abs(step) < 1e-12) break;
  }
  const CurvePoint q = Hermite(e, seg, t);
  return {seg, t, q.x, q.y, q.dx, q.dy};
}

void CurveResiduals(const ElasticaProfile& e, const std::vector<double>& data_x,
                    const std::vector<double>& data_y, const double* rig,
                    std::vector<double>* residual, std::array<double, 2>* tip) {
  const double c = std::cos(rig[1]), s = std::sin(rig[1]);
  residual->resize(data_x.size());
  for (size_t j = 0; j < data_x.size(); ++j) {
    const double ux = data_x[j], uy = data_y[j] - rig[0];
    const double dx = c * ux + s * uy, dy = -s * ux + c * uy;
    const FootPoint f = FindFootPoint(e, dx, dy);
    const double tn = std::hypot(f.dx, f.dy);
    (*residual)[j] = ((dx - f.x) * (-f.dy / tn) + (dy - f.y) * (f.dx / tn)) * kMmPerM;
  }
  const size_t n = e.s.size();
  const double tx = c * e.x[n - 1] - s * e.y[n - 1], ty = s * e.x[n - 1] + c * e.y[n - 1] + rig[0];
  *tip = {(tx - data_x.back()) * kMmPerM, (ty - data_y.back()) * kMmPerM};
}

ProfileModel::ProfileModel(const Profile& profile, double areal_density, int samples, double tol)
    : data_x_(profile.x), data_y_(profile.y), areal_density_(areal_density), samples_(samples),
      tol_(tol) {
  residual_.resize(data_x_.size());
  gradient_.resize(data_x_.size());
}

bool ProfileModel::Update(const double* p, const double* length, const double* rig,
                          bool jacobians) {
  const std::array<double, 6> params = {p[0], p[1], p[2], length[0], rig[0], rig[1]};
  if (cached_valid_ && params == cached_params_ && (cached_jacobians_ || !jacobians)) return true;
  cached_valid_ = false;
  const double L = length[0];
  if (!(L > 0.0) || !std::isfinite(L)) return false;
  ElasticaOptions options;
  options.rel_tol = tol_;
  options.num_samples = samples_;
  options.sensitivities = jacobians;
  // Continuation: the last point is close. Its log gap, not its angle: a strip of 15 bending
  // lengths or more hangs so nearly vertically that θ(L) rounds to π/2, which is not a guess
  // the solver takes (every later step of a 250 mm fit then failed).
  if (solution_.converged && std::isfinite(solution_.log_tip_gap)) {
    options.log_tip_gap_guess = solution_.log_tip_gap;
  }
  try {
    const BendingLaw law = LawFromParameters(p);
    ElasticaProfile e = SolveHeavyElastica(law, areal_density_, L, options);
    if (!e.converged) {
      if (std::getenv("TEXTILE_DEBUG_FIT")) {
        std::fprintf(stderr, "elastica failed: b1 %.6g b2 %.6g c1 %.6g (KES) rho %g L %.6g sens %d: %s\n",
                     law.b1_kes(), law.b2_kes(), law.c1_kes(), areal_density_, L, jacobians,
                     e.message.c_str());
      }
      return false;
    }
    solution_ = std::move(e);
  } catch (const InputError&) {
    return false;  // parameters outside what the law/elastica accept: a rejected step
  }
  const ElasticaProfile& e = solution_;
  const int n = static_cast<int>(e.s.size());
  const double c = std::cos(rig[1]), s = std::sin(rig[1]);
  rig_offset_ = rig[0];
  rig_rotation_ = rig[1];
  // Measurement frame: q = R(φ) c(s) + (0, offset).
  const auto to_meas = [&](double x, double y, double* qx, double* qy) {
    *qx = c * x - s * y;
    *qy = s * x + c * y + rig[0];
  };

  // d(x, y)/d(p, L) at a sample, in the model frame; chain rule from {b1, b2, c1}.
  const double b1 = std::exp(p[0]), b2 = std::exp(p[1]), k0 = std::exp(p[2]);
  const double c1 = (b2 - b1) / (2.0 * k0);
  // ∂(b1, b2, c1)/∂(p0, p1, p2).
  const double db[3][3] = {{b1, 0.0, 0.0}, {0.0, b2, 0.0}, {-b1 / (2 * k0), b2 / (2 * k0), -c1}};
  const auto model_gradient = [&](int k, double w, std::array<double, 4>* gx,
                                  std::array<double, 4>* gy, std::array<double, 4>* gt) {
    // Linear interpolation of the sample sensitivities between k and k+1 with weight w.
    const int k1 = std::min(k + 1, n - 1);
    double sx[3], sy[3], st[3];
    for (int q = 0; q < 3; ++q) {
      sx[q] = (1 - w) * e.dx_dp(k, q) + w * e.dx_dp(k1, q);
      sy[q] = (1 - w) * e.dy_dp(k, q) + w * e.dy_dp(k1, q);
      st[q] = (1 - w) * e.dtheta_dp(k, q) + w * e.dtheta_dp(k1, q);
    }
    for (int j = 0; j < 3; ++j) {
      (*gx)[j] = sx[0] * db[0][j] + sx[1] * db[1][j] + sx[2] * db[2][j];
      (*gy)[j] = sy[0] * db[0][j] + sy[1] * db[1][j] + sy[2] * db[2][j];
      (*gt)[j] = st[0] * db[0][j] + st[1] * db[1][j] + st[2] * db[2][j];
    }
    // d/dL at fixed s from the scaling law of the elastica: a strip of length L with constants
    // (b1, b2, c1) is, in units of L, the strip of length L0 with (λ³b1, λ³b2, λ⁴c1), λ = L0/L.
    // Differentiating at λ = 1 (docs/methods/fitting.md):
    //   ∂x/∂L = -(1/L) [-x + s cos θ + 3 b1 ∂x/∂b1 + 3 b2 ∂x/∂b2 + 4 c1 ∂x/∂c1], same for y,
    //   ∂θ/∂L = -(1/L) [s κ + 3 b1 ∂θ/∂b1 + 3 b2 ∂θ/∂b2 + 4 c1 ∂θ/∂c1].
    const double x = (1 - w) * e.x[k] + w * e.x[k1], y = (1 - w) * e.y[k] + w * e.y[k1];
    const double th = (1 - w) * e.theta[k] + w * e.theta[k1];
    const double kap = (1 - w) * e.kappa[k] + w * e.kappa[k1];
    const double sa = (1 - w) * e.s[k] + w * e.s[k1];
    (*gx)[3] = -(-x + sa * std::cos(th) + 3 * b1 * sx[0] + 3 * b2 * sx[1] + 4 * c1 * sx[2]) / L;
    (*gy)[3] = -(-y - sa * std::sin(th) + 3 * b1 * sy[0] + 3 * b2 * sy[1] + 4 * c1 * sy[2]) / L;
    (*gt)[3] = -(sa * kap + 3 * b1 * st[0] + 3 * b2 * st[1] + 4 * c1 * st[2]) / L;
  };
  // Gradient of a measurement-frame point q w.r.t. all 6 parameters, from the model-frame one.
  const auto full_gradient = [&](const std::array<double, 4>& gx, const std::array<double, 4>& gy,
                                 double mx, double my, std::array<double, 6>* qx,
                                 std::array<double, 6>* qy) {
    for (int j = 0; j < 4; ++j) {
      (*qx)[j] = c * gx[j] - s * gy[j];
      (*qy)[j] = s * gx[j] + c * gy[j];
    }
    (*qx)[4] = 0.0;
    (*qy)[4] = 1.0;
    (*qx)[5] = -s * mx - c * my;
    (*qy)[5] = c * mx - s * my;
  };

  // Each measured point: its nearest point on the curve (nearest sample, then Newton on the
  // Hermite segment), the normal distance, and its gradient (the foot point is stationary, so
  // only the curve's motion along the normal counts).
  for (int j = 0; j < num_points(); ++j) {
    // Data into the model frame: d' = R(-φ) (d - (0, offset)).
    const double ux = data_x_[j], uy = data_y_[j] - rig[0];
    const double dx = c * ux + s * uy, dy = -s * ux + c * uy;
    const FootPoint f = FindFootPoint(e, dx, dy);
    const int seg = f.seg;
    const double t = f.t;
    const CurvePoint q = {f.x, f.y, f.dx, f.dy};
    const double tn = std::hypot(q.dx, q.dy);
    const double nx = -q.dy / tn, ny = q.dx / tn;  // normal, model frame
    residual_[j] = ((dx - q.x) * nx + (dy - q.y) * ny) * kMmPerM;
    if (jacobians) {
      // r = n(s*)·(d' - q(s*)) in the model frame, d' = R(-φ)(d - (0, offset)). The foot point
      // s* is stationary inside the curve; where it is clamped to an end, d' - q has a
      // tangential part that the turning normal (dn/dθ = tangent) picks up, so keep that term.
      std::array<double, 4> gx, gy, gt;
      model_gradient(seg, t, &gx, &gy, &gt);
      const double tx = q.dx / tn, ty = q.dy / tn;
      const double along = (dx - q.x) * tx + (dy - q.y) * ty;
      for (int i = 0; i < 4; ++i) {
        gradient_[j][i] = (along * gt[i] - nx * gx[i] - ny * gy[i]) * kMmPerM;
      }
      // ∂d'/∂offset = R(-φ)(0, -1); ∂d'/∂φ = dR(-φ)/dφ (d - (0, offset)).
      gradient_[j][4] = (nx * (-s) + ny * (-c)) * kMmPerM;
      gradient_[j][5] = (nx * (-s * ux + c * uy) + ny * (-c * ux - s * uy)) * kMmPerM;
    }
  }

  // The tip: model tip in the measurement frame minus the last measured point.
  double tx, ty;
  to_meas(e.x[n - 1], e.y[n - 1], &tx, &ty);
  tip_residual_ = {(tx - data_x_.back()) * kMmPerM, (ty - data_y_.back()) * kMmPerM};
  if (jacobians) {
    std::array<double, 4> gx, gy, gt;
    model_gradient(n - 2, 1.0, &gx, &gy, &gt);
    // The tip moves with L: d/dL [c(L; L)] = c'(L) + ∂c/∂L at s = L.
    gx[3] += std::cos(e.theta[n - 1]);
    gy[3] += -std::sin(e.theta[n - 1]);
    std::array<double, 6> qx, qy;
    full_gradient(gx, gy, e.x[n - 1], e.y[n - 1], &qx, &qy);
    for (int i = 0; i < 6; ++i) {
      tip_gradient_[0][i] = qx[i] * kMmPerM;
      tip_gradient_[1][i] = qy[i] * kMmPerM;
    }
  }
  cached_params_ = params;
  cached_valid_ = true;
  cached_jacobians_ = jacobians;
  return true;
}

void ProfileModel::ModelCurve(std::vector<double>* x, std::vector<double>* y) const {
  x->clear();
  y->clear();
  const double c = std::cos(rig_rotation_), s = std::sin(rig_rotation_);
  for (size_t k = 0; k < solution_.s.size(); ++k) {
    x->push_back(c * solution_.x[k] - s * solution_.y[k]);
    y->push_back(s * solution_.x[k] + c * solution_.y[k] + rig_offset_);
  }
}

namespace {
void CopyJacobians(const std::array<double, 6>& g, double** jacobians, int row, int rows) {
  if (!jacobians) return;
  if (jacobians[0]) for (int i = 0; i < 3; ++i) jacobians[0][row * 3 + i] = g[i];
  if (jacobians[1]) jacobians[1][row] = g[3];
  if (jacobians[2]) for (int i = 0; i < 2; ++i) jacobians[2][row * 2 + i] = g[4 + i];
  (void)rows;
}
}  // namespace

bool PointResidual::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  if (!model_->Update(parameters[0], parameters[1], parameters[2], jacobians != nullptr)) {
    return false;
  }
  residuals[0] = model_->residual(j_);
  CopyJacobians(model_->gradient(j_), jacobians, 0, 1);
  return true;
}

bool TipResidual::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  if (!model_->Update(parameters[0], parameters[1], parameters[2], jacobians != nullptr)) {
    return false;
  }
  residuals[0] = model_->tip_residual()[0];
  residuals[1] = model_->tip_residual()[1];
  CopyJacobians(model_->tip_gradient()[0], jacobians, 0, 2);
  CopyJacobians(model_->tip_gradient()[1], jacobians, 1, 2);
  return true;
}

}  // namespace textile::internal
