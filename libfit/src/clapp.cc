#include "textile/fit/clapp.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>

#include "clapp_stages.h"
#include "cost_functions/clapp_law_cost.h"
#include "deadline.h"
#include "law_parameters.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Panels of the arc-length and moment quadrature along the smooth curve. The integrands
// (speed and x·speed of a degree-5 polar polynomial) are smooth, so 200 panels of 5-point
// Gauss-Legendre are exact to rounding; the method's error is the polynomial's, not ours.
constexpr int kPanels = 200;
constexpr std::array<double, 5> kGaussNodes = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                               0.5384693101056831, 0.9061798459386640};
constexpr std::array<double, 5> kGaussWeights = {0.2369268850561891, 0.4786286704993665,
                                                 0.5688888888888889, 0.4786286704993665,
                                                 0.2369268850561891};

// The smooth curve x = r cos φ(r), y = -r sin φ(r) of one profile.
class PolarCurve {
 public:
  PolarCurve(std::vector<double> coefficients, double r_scale)
      : c_(std::move(coefficients)), r_scale_(r_scale) {}

  struct Point {
    double x, y;   // position [m]
    double speed;  // ds/dr [-]
    double kappa;  // curvature [1/m], positive when turning downwards (clockwise)
  };

  // φ and its first two derivatives with respect to r, by Horner's rule in t = r / r_scale.
  void Phi(double r, double* phi, double* dphi, double* ddphi) const {
    const double t = r / r_scale_;
    double p = 0.0, dp = 0.0, ddp = 0.0;
    for (int k = static_cast<int>(c_.size()) - 1; k >= 0; --k) {
      ddp = ddp * t + 2.0 * dp;
      dp = dp * t + p;
      p = p * t + c_[k];
    }
    *phi = p;
    *dphi = dp / r_scale_;
    *ddphi = ddp / (r_scale_ * r_scale_);
  }

  Point At(double r) const {
    double f, df, ddf;
    Phi(r, &f, &df, &ddf);
    const double c = std::cos(f), s = std::sin(f);
    // Derivatives of (x, y) with respect to the parameter r.
    const double xr = c - r * df * s;
    const double yr = -s - r * df * c;
    const double xrr = -2.0 * df * s - r * ddf * s - r * df * df * c;
    const double yrr = -2.0 * df * c - r * ddf * c + r * df * df * s;
    const double speed = std::hypot(xr, yr);  // = sqrt(1 + r² φ'²)
    // Signed curvature is positive counter-clockwise; a hanging strip turns clockwise.
    const double kappa = -(xr * yrr - yr * xrr) / (speed * speed * speed);
    return {r * c, -r * s, speed, kappa};
  }

  // ∫ ds and ∫ x ds from r = a to r = b [m, m²].
  void Integrate(double a, double b, double* ds, double* xds) const {
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    double s = 0.0, xs = 0.0;
    for (size_t q = 0; q < kGaussNodes.size(); ++q) {
      const Point p = At(mid + half * kGaussNodes[q]);
      s += kGaussWeights[q] * p.speed;
      xs += kGaussWeights[q] * p.x * p.speed;
    }
    *ds = half * s;
    *xds = half * xs;
  }

 private:
  std::vector<double> c_;
  double r_scale_;
};

void CheckDensity(double areal_density) {
  if (!std::isfinite(areal_density) || areal_density <= 0.0) {
    std::ostringstream why;
    why << "Clapp fit: areal density must be a positive number [kg/m²], got " << areal_density;
    throw InputError(why.str());
  }
}

void CheckOptions(const ClappOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("Clapp fit options: " + why);
}

double Sq(double v) { return v * v; }

}  // namespace

bool ClappOptions::Check(std::string* why) const {
  std::string problem;
  if (polynomial_order < 1 || polynomial_order > 9) {
    problem = "polynomial_order must be in [1, 9] (Clapp et al.: 5), got " +
              std::to_string(polynomial_order);
  } else if (points_per_profile < 3) {
    problem = "points_per_profile must be >= 3, got " + std::to_string(points_per_profile);
  } else if (!(tip_exclusion >= 0.0 && tip_exclusion < 0.5)) {
    problem = "tip_exclusion must be in [0, 0.5), got " + std::to_string(tip_exclusion);
  } else if (!(min_radius >= 0.0) || !std::isfinite(min_radius)) {
    problem = "min_radius must be a finite length >= 0 [m], got " + std::to_string(min_radius);
  } else if (loss != ClappLoss::kNone && !(loss_scale > 0.0 && std::isfinite(loss_scale))) {
    problem = "loss_scale must be > 0, got " + std::to_string(loss_scale);
  } else if (num_starts < 1) {
    problem = "num_starts must be >= 1, got " + std::to_string(num_starts);
  } else if (max_iterations < 1) {
    problem = "max_iterations must be >= 1, got " + std::to_string(max_iterations);
  } else if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    problem = "max_seconds must be a finite number >= 0 [s], got " + std::to_string(max_seconds);
  }
  if (why != nullptr) *why = problem;
  return problem.empty();
}

double ClappProfileFit::Phi(double r) const {
  double p = 0.0;
  const double t = r / r_scale;
  for (auto it = coefficients.rbegin(); it != coefficients.rend(); ++it) p = p * t + *it;
  return p;
}

namespace {

// Step 1: the digitised points in polar coordinates about the edge, φ the angle below
// horizontal; points nearer the edge than options.min_radius are left out.
struct PolarPoints {
  std::vector<double> r, phi;  // #n distances [m] and angles [rad]
};

PolarPoints PolarPointsAboutEdge(const Profile& profile, const ClappOptions& options) {
  const int order = options.polynomial_order;
  PolarPoints polar;
  for (size_t i = 0; i < profile.size(); ++i) {
    const double ri = std::hypot(profile.x[i], profile.y[i]);
    if (ri > 0.0 && ri >= options.min_radius) {
      polar.r.push_back(ri);
      polar.phi.push_back(std::atan2(-profile.y[i], profile.x[i]));
    }
  }
  const int n = static_cast<int>(polar.r.size());
  if (n < order + 1) {
    throw InputError(profile.source + ": only " + std::to_string(n) +
                     " points away from the edge; Clapp's polynomial of order " +
                     std::to_string(order) + " needs at least " + std::to_string(order + 1));
  }
  return polar;
}

// Step 2: the least-squares polynomial φ(r) from the edge to the tip, the last digitised
// point, with its residuals. Throws InputError for a tip at the edge or too few distinct r.
ClappProfileFit FitPolarPolynomial(const Profile& profile, const PolarPoints& polar,
                                   const ClappOptions& options) {
  const int order = options.polynomial_order;
  const std::vector<double>& r = polar.r;
  const std::vector<double>& phi = polar.phi;
  const int n = static_cast<int>(r.size());
  const double r_tip = std::hypot(profile.x.back(), profile.y.back());
  if (!(r_tip > 0.0)) throw InputError(profile.source + ": the tip lies at the edge");

  // In t = r / r_tip ∈ (0, ~1]: the scaled Vandermonde matrix is well conditioned (~1e4 for
  // order 5) and QR never forms the normal equations.
  Eigen::MatrixXd vandermonde(n, order + 1);
  Eigen::VectorXd rhs(n);
  for (int i = 0; i < n; ++i) {
    const double t = r[i] / r_tip;
    const double w = options.weighting == ClappWeighting::kRadius ? t : 1.0;
    double power = 1.0;
    for (int k = 0; k <= order; ++k, power *= t) vandermonde(i, k) = w * power;
    rhs(i) = w * phi[i];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(vandermonde);
  if (qr.rank() < order + 1) {
    throw InputError(profile.source + ": the points span too few distinct distances from the " +
                     "edge for a polynomial of order " + std::to_string(order));
  }
  const Eigen::VectorXd coefficients = qr.solve(rhs);

  ClappProfileFit fit;
  fit.source = profile.source;
  fit.coefficients.assign(coefficients.data(), coefficients.data() + coefficients.size());
  fit.r_scale = r_tip;
  fit.points_used = n;
  fit.data_length = profile.s.back();
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) sum_sq += Sq(r[i] * (phi[i] - fit.Phi(r[i])));
  fit.residual_rms = std::sqrt(sum_sq / n);
  return fit;
}

// Step 3: arc length and first moment of the curve, cumulative at the ends of kPanels panels.
struct CurvePanels {
  std::vector<double> r, s, xs;  // #kPanels + 1: r [m], ∫ ds [m], ∫ x ds [m²] from the edge
};

CurvePanels IntegrateCurve(const PolarCurve& curve, double r_tip) {
  CurvePanels panels{std::vector<double>(kPanels + 1), std::vector<double>(kPanels + 1, 0.0),
                     std::vector<double>(kPanels + 1, 0.0)};
  for (int k = 0; k <= kPanels; ++k) panels.r[k] = r_tip * k / kPanels;
  for (int k = 0; k < kPanels; ++k) {
    double ds, dxs;
    curve.Integrate(panels.r[k], panels.r[k + 1], &ds, &dxs);
    panels.s[k + 1] = panels.s[k] + ds;
    panels.xs[k + 1] = panels.xs[k] + dxs;
  }
  return panels;
}

// Step 4: (κ, m) at evenly spaced arc lengths; m(s) = ρ g [∫_s^L x ds' - x(s) (L - s)].
void PairsAlongCurve(const PolarCurve& curve, const CurvePanels& panels, double areal_density,
                     const ClappOptions& options, std::vector<ClappPoint>* points) {
  const std::vector<double>& panel_r = panels.r;
  const std::vector<double>& panel_s = panels.s;
  const std::vector<double>& panel_xs = panels.xs;
  const double length = panel_s.back(), first_moment = panel_xs.back();
  const double weight = areal_density * units::kGravity;  // per unit area [N/m²]
  const int count = options.points_per_profile;
  const double s_end = (1.0 - options.tip_exclusion) * length;
  if (points != nullptr) points->clear();
  for (int j = 0; j < count; ++j) {
    const double s_target = s_end * j / (count - 1);
    const int k =
        std::clamp(static_cast<int>(std::upper_bound(panel_s.begin(), panel_s.end(), s_target) -
                                    panel_s.begin()) -
                       1,
                   0, kPanels - 1);
    // Newton on s(r) = s_target inside panel k (s is increasing, ds/dr = speed ≥ 1).
    const double a = panel_r[k], b = panel_r[k + 1];
    double rj = a + (b - a) * (s_target - panel_s[k]) / (panel_s[k + 1] - panel_s[k]);
    double ds = 0.0, dxs = 0.0;
    for (int it = 0; it < 50; ++it) {
      curve.Integrate(a, rj, &ds, &dxs);
      const double f = panel_s[k] + ds - s_target;
      if (std::abs(f) <= 1e-14 * length) break;
      rj = std::clamp(rj - f / curve.At(rj).speed, a, b);
    }
    curve.Integrate(a, rj, &ds, &dxs);
    const double s_j = panel_s[k] + ds, xs_j = panel_xs[k] + dxs;
    const PolarCurve::Point p = curve.At(rj);
    const double moment = weight * ((first_moment - xs_j) - p.x * (length - s_j));
    if (points != nullptr) points->push_back({p.kappa, moment, s_j, 0});
  }
}

}  // namespace

ClappProfileFit FitClappProfile(const Profile& profile, double areal_density,
                                const ClappOptions& options, std::vector<ClappPoint>* points) {
  CheckOptions(options);
  CheckDensity(areal_density);
  CheckProfile(profile);
  const PolarPoints polar = PolarPointsAboutEdge(profile, options);
  ClappProfileFit fit = FitPolarPolynomial(profile, polar, options);
  const PolarCurve curve(fit.coefficients, fit.r_scale);
  const CurvePanels panels = IntegrateCurve(curve, fit.r_scale);
  fit.curve_length = panels.s.back();
  fit.kappa_at_edge = curve.At(0.0).kappa;
  PairsAlongCurve(curve, panels, areal_density, options, points);
  return fit;
}

namespace internal {
namespace {

ceres::Solver::Options ClappSolverOptions(const ClappOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = 1e-12;
  solver_options.gradient_tolerance = 1e-14;
  solver_options.parameter_tolerance = 1e-12;
  solver_options.logging_type = ceres::SILENT;
  return solver_options;
}

// The regression of eq. 1 on the pooled pairs from p (in place), within the state's bounds.
ceres::Solver::Summary SolveClappStart(const ClappFitState& state,
                                       const ceres::Solver::Options& solver_options,
                                       std::array<double, 3>* p) {
  const ClappOptions& options = state.options;
  ceres::Problem problem;
  for (const ClappPoint& pt : state.result.points) {
    ceres::LossFunction* loss = nullptr;
    if (options.loss == ClappLoss::kHuber) loss = new ceres::HuberLoss(options.loss_scale);
    if (options.loss == ClappLoss::kCauchy) loss = new ceres::CauchyLoss(options.loss_scale);
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ClappLawCost, 1, 3>(
                                 new ClappLawCost(pt.kappa, pt.moment, state.moment_max)),
                             loss, p->data());
  }
  for (int k = 0; k < 3; ++k) {
    problem.SetParameterLowerBound(p->data(), k, state.lower[k]);
    problem.SetParameterUpperBound(p->data(), k, state.upper[k]);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

// Past the cap nothing is trusted, not even a converged start: the others might fit better.
bool TimeCapReached(ClappFitState* state, size_t starts_run) {
  std::ostringstream why;
  why << "Clapp fit: time cap of " << state->options.max_seconds << " s (ClappOptions::max_seconds)"
      << " reached with " << starts_run << " of " << state->starts.size()
      << " regression starts run; no law";
  state->result.message = why.str();
  return false;
}

}  // namespace

void CheckClappInput(const ClappFitState& state) {
  CheckOptions(state.options);
  CheckDensity(state.areal_density);
  if (state.profiles.empty()) throw InputError("Clapp fit: no profiles given");
}

void PoolClappPairs(ClappFitState* state) {
  ClappResult& result = state->result;
  for (size_t i = 0; i < state->profiles.size(); ++i) {
    std::vector<ClappPoint> pts;
    result.profiles.push_back(
        FitClappProfile(state->profiles[i], state->areal_density, state->options, &pts));
    for (ClappPoint& p : pts) {
      p.profile = static_cast<int>(i);
      result.points.push_back(p);
    }
  }
}

bool MeasureClappScales(ClappFitState* state) {
  ClappResult& result = state->result;
  // Scales of the data; a strip that does not bend carries no information about the law.
  double moment_max = 0.0, sum_km = 0.0, sum_kk = 0.0;
  for (const ClappPoint& p : result.points) {
    result.kappa_max = std::max(result.kappa_max, std::abs(p.kappa));
    moment_max = std::max(moment_max, std::abs(p.moment));
    sum_km += p.kappa * p.moment;
    sum_kk += p.kappa * p.kappa;
  }
  const double linear_stiffness = sum_kk > 0.0 ? sum_km / sum_kk : 0.0;  // M ≈ B κ [N·m]
  state->moment_max = moment_max;
  state->linear_stiffness = linear_stiffness;
  // A straight strip's curvature is round-off (6e-14 /cm for a vertical one), not zero: below
  // 1e-4 /m (a radius of 10 km) a strip does not bend.
  constexpr double kNoCurvature = 1e-4;  // [1/m]
  if (!(moment_max > 0.0) || !(result.kappa_max > kNoCurvature)) {
    result.message =
        "Clapp fit: the profiles have no curvature along them (straight); no law fitted";
    return false;
  }
  if (!(linear_stiffness > 0.0) || !std::isfinite(linear_stiffness)) {
    result.message =
        "Clapp fit: moment and curvature of the polynomial curves do not increase together "
        "(the polynomial does not follow the strip; noisy points near the edge? see "
        "ClappOptions::min_radius); no law fitted";
    return false;
  }
  return true;
}

void PlaceClappStarts(ClappFitState* state) {
  const ClappResult& result = state->result;
  const int num_starts = state->options.num_starts;
  // 5. Regression of eq. 1 on the pooled pairs. Starts: κ0 spread geometrically over
  // [0.1, 2] κ_max; for fixed κ0, M is linear in (b1, b2):
  //   κ ≤ κ0: M = b1 (κ - κ²/(2κ0)) + b2 κ²/(2κ0);  κ > κ0: M = b1 κ0/2 + b2 (κ - κ0/2),
  // so each start takes the least-squares (b1, b2) for its κ0, or b1 = b2 = B (the linear
  // fit) when those are not positive.
  const int num_points = static_cast<int>(result.points.size());
  state->starts.clear();
  for (int i = 0; i < num_starts; ++i) {
    const double fraction =
        num_starts == 1 ? 0.5 : 0.1 * std::pow(20.0, double(i) / (num_starts - 1));
    const double k0 = fraction * result.kappa_max;
    Eigen::MatrixXd basis(num_points, 2);
    Eigen::VectorXd moments(num_points);
    for (int j = 0; j < num_points; ++j) {
      const double k = std::abs(result.points[j].kappa);
      const double sign = result.points[j].kappa < 0.0 ? -1.0 : 1.0;
      if (k <= k0) {
        basis(j, 0) = sign * (k - k * k / (2.0 * k0));
        basis(j, 1) = sign * k * k / (2.0 * k0);
      } else {
        basis(j, 0) = sign * 0.5 * k0;
        basis(j, 1) = sign * (k - 0.5 * k0);
      }
      moments(j) = result.points[j].moment;
    }
    Eigen::Vector2d b = basis.colPivHouseholderQr().solve(moments);
    if (!(b(0) > 0.0 && b(1) > 0.0 && b.allFinite())) b.setConstant(state->linear_stiffness);
    state->starts.push_back({std::log(b(0)), std::log(b(1)), std::log(k0)});
  }
  // Bounds: κ0 where a law differs from its limits (law_parameters.h); b1, b2 within 1e6 of
  // the linear fit either way, far outside any plausible answer but keeping exp() finite.
  const double log_b = std::log(state->linear_stiffness), log_range = std::log(1e6);
  state->lower = {log_b - log_range, log_b - log_range, std::log(kMinKappa0)};
  state->upper = {log_b + log_range, log_b + log_range, std::log(kMaxKappa0)};
  for (auto& start : state->starts) {
    for (int k = 0; k < 3; ++k) start[k] = std::clamp(start[k], state->lower[k], state->upper[k]);
  }
}

bool RunClappStarts(ClappFitState* state) {
  ceres::Solver::Options solver_options = ClappSolverOptions(state->options);
  std::string last_failure;
  for (size_t i = 0; i < state->starts.size(); ++i) {
    const double left = state->deadline.Remaining();
    if (left <= 0.0) return TimeCapReached(state, i);
    std::array<double, 3> p = state->starts[i];
    solver_options.max_solver_time_in_seconds = left;
    const ceres::Solver::Summary summary = SolveClappStart(*state, solver_options, &p);
    if (state->deadline.Remaining() <= 0.0) return TimeCapReached(state, i + 1);
    const bool finite = std::all_of(p.begin(), p.end(), [](double v) { return std::isfinite(v); });
    // A start that runs out of iterations is not trusted (max_iterations is generous for
    // three parameters); another start usually converges.
    if (summary.termination_type != ceres::CONVERGENCE || !finite) {
      last_failure = summary.message;
      continue;
    }
    if (summary.final_cost < state->best_cost) {
      state->best_cost = summary.final_cost;
      state->best = p;
    }
  }
  if (!std::isfinite(state->best_cost)) {
    state->result.message =
        "Clapp fit: the regression of eq. 1 failed from every start (" + last_failure + ")";
    return false;
  }
  return true;
}

bool ClappLawFromBest(ClappFitState* state) {
  try {
    state->result.law = LawFromParameters(state->best.data());
  } catch (const InputError& e) {
    state->result.message = std::string("Clapp fit: the regression gave no valid law: ") + e.what();
    return false;
  }
  return true;
}

void MeasureClappMisfit(ClappFitState* state) {
  ClappResult& result = state->result;
  const BendingLaw& law = *result.law;
  double sum_sq = 0.0;
  for (const ClappPoint& pt : result.points) sum_sq += Sq(law.Moment(pt.kappa) - pt.moment);
  result.moment_rms = std::sqrt(sum_sq / static_cast<int>(result.points.size()));
  result.b2_observed = law.kappa0() < result.kappa_max;
}

void ClappCovariance(ClappFitState* state) {
  ClappResult& result = state->result;
  const BendingLaw& law = *result.law;
  const std::array<double, 3>& best = state->best;
  const int num_points = static_cast<int>(result.points.size());
  // Covariance of p from (JᵀJ)⁻¹ scaled by the residual variance (the pairs carry no
  // individual uncertainties), then first-order propagation to {b1, b2, c1}. Three
  // parameters: J comes from the same functor on Jets, and a near-singular JᵀJ (a constant
  // the data do not determine) or a parameter on its bound means "unavailable".
  result.sd_b1 = result.sd_b2 = result.sd_c1 = kNaN;
  using Jet = ceres::Jet<double, 3>;
  const Jet p_jet[3] = {Jet(best[0], 0), Jet(best[1], 1), Jet(best[2], 2)};
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  for (const ClappPoint& pt : result.points) {
    Jet residual;
    ClappLawCost(pt.kappa, pt.moment, state->moment_max)(p_jet, &residual);
    jtj += residual.v * residual.v.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(jtj);
  const Eigen::Vector3d& lambda = eigen.eigenvalues();  // ascending
  bool on_bound = false;
  for (int k = 0; k < 3; ++k) {
    on_bound = on_bound || best[k] <= state->lower[k] + 1e-9 || best[k] >= state->upper[k] - 1e-9;
  }
  // Reciprocal condition of JᵀJ: below 1e-12 the standard deviations would exceed the
  // values by orders of magnitude and mean nothing.
  constexpr double kMinReciprocalCondition = 1e-12;
  if (num_points > 3 && !on_bound && lambda(0) > kMinReciprocalCondition * lambda(2)) {
    const double variance =
        Sq(result.moment_rms / state->moment_max) * num_points / (num_points - 3);
    const Eigen::Matrix3d cov_p = variance * eigen.eigenvectors() *
                                  lambda.cwiseInverse().asDiagonal() *
                                  eigen.eigenvectors().transpose();
    const double b1 = law.b1(), b2 = law.b2(), k0 = std::exp(best[2]);
    const Eigen::Vector3d grad_b1(b1, 0.0, 0.0), grad_b2(0.0, b2, 0.0);
    // c1 = (e^{p1} - e^{p0}) / (2 e^{p2}).
    const Eigen::Vector3d grad_c1(-b1 / (2.0 * k0), b2 / (2.0 * k0), -(b2 - b1) / (2.0 * k0));
    result.sd_b1 = std::sqrt(grad_b1.dot(cov_p * grad_b1));
    result.sd_b2 = std::sqrt(grad_b2.dot(cov_p * grad_b2));
    result.sd_c1 = std::sqrt(grad_c1.dot(cov_p * grad_c1));
    result.covariance_available =
        std::isfinite(result.sd_b1) && std::isfinite(result.sd_b2) && std::isfinite(result.sd_c1);
  }
  if (!result.covariance_available) result.sd_b1 = result.sd_b2 = result.sd_c1 = kNaN;
}

void FinishClapp(ClappFitState* state) {
  ClappResult& result = state->result;
  const BendingLaw& law = *result.law;
  result.success = true;
  std::ostringstream note;
  note << "Clapp fit converged";
  if (!result.b2_observed) {
    note << "; kappa0 = " << units::SiCurvatureToKes(law.kappa0())
         << " /cm lies beyond the largest observed curvature "
         << units::SiCurvatureToKes(result.kappa_max) << " /cm: b2 is not determined by the data";
  }
  if (!result.covariance_available) {
    note << "; covariance unavailable (the constants are not all determined by the data)";
  }
  result.message = note.str();
}

}  // namespace internal

ClappResult FitClapp(const std::vector<Profile>& profiles, double areal_density,
                     const ClappOptions& options) {
  internal::ClappFitState state(profiles, areal_density, options);
  internal::CheckClappInput(state);
  internal::PoolClappPairs(&state);
  if (!internal::MeasureClappScales(&state)) return state.result;
  internal::PlaceClappStarts(&state);
  if (!internal::RunClappStarts(&state) || !internal::ClappLawFromBest(&state)) return state.result;
  internal::MeasureClappMisfit(&state);
  internal::ClappCovariance(&state);
  internal::FinishClapp(&state);
  return state.result;
}

std::string ClappResult::BriefReport() const {
  std::ostringstream out;
  out << std::setprecision(4);
  out << "Clapp et al. 1990: " << profiles.size() << " profile(s), " << points.size()
      << " (kappa, M) pairs, kappa up to " << units::SiCurvatureToKes(kappa_max) << " /cm\n";
  for (const ClappProfileFit& p : profiles) {
    out << "  " << p.source << ": order-" << (p.coefficients.size() - 1) << " polynomial on "
        << p.points_used << " points, RMS " << units::MToMm(p.residual_rms) << " mm, length "
        << units::MToMm(p.curve_length) << " mm (data " << units::MToMm(p.data_length) << " mm)\n";
  }
  if (!success || !law) {
    out << "  no law: " << message;
    return out.str();
  }
  const auto pm = [&](double value, double sd) {
    std::ostringstream s;
    s << std::setprecision(4) << value;
    if (covariance_available) s << " ± " << std::setprecision(2) << sd;
    return s.str();
  };
  out << "  law (KES): b1 = " << pm(law->b1_kes(), units::SiStiffnessToKes(sd_b1))
      << " gf·cm, b2 = " << pm(law->b2_kes(), units::SiStiffnessToKes(sd_b2))
      << " gf·cm, c1 = " << pm(law->c1_kes(), units::SiQuadraticToKes(sd_c1)) << " gf·cm²"
      << (covariance_available ? " (1-σ)" : " (1-σ unavailable)") << "\n";
  out << "  kappa0 = " << units::SiCurvatureToKes(law->kappa0()) << " /cm"
      << (b2_observed ? "" : " (beyond the data: b2 not determined)") << ", moment RMS "
      << units::SiMomentToKes(moment_rms) << " gf·cm/cm\n";
  out << "  " << message;
  return out.str();
}

}  // namespace textile
