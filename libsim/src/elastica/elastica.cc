#include "textile/sim/elastica/elastica.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <span>
#include <sstream>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "elastica_stages.h"

// How the solver works (details and accuracy figures in docs/methods/cantilever-facts.md).
//
// The independent variable is t = (L - s)/L ∈ [0, 1], running from the free tip (t = 0) to the
// edge (t = 1), and every quantity is scaled to be O(1): m̃ = m/(ρgL²), X̃, Ỹ = integrals of
// cos θ, sin θ from the tip, divided by L. Then
//
//   dθ/dt = -L κ(m),  dm̃/dt = t cos θ,  dX̃/dt = cos θ,  dỸ/dt = sin θ,  θ(0) = θ_L, m̃(0) = 0,
//
// and the shooting condition is θ(t = 1) = 0; x(s) = L (X̃(1) - X̃(t)), y(s) = -L (Ỹ(1) - Ỹ(t)).
//
// Near-vertical strips (docs/spec/cantilever.md, "two traps"): for a strip many bending lengths
// long the tip hangs with φ = π/2 - θ ≈ φ_L exp((2/3)(s'/ℓ)^{3/2}) (Airy growth), so φ_L underflows
// and θ_L = π/2 in double precision. There the state is (ψ = log φ, μ̃ = m̃/φ) instead, which obeys
//
//   dψ/dt = R μ̃,  dμ̃/dt = t sin(φ)/φ - R μ̃²,  R = ρgL³ κ(m)/m,
//
// finite and well scaled however small φ is (for a linear law R = ρgL³/B). The shooting unknown
// z maps to the tip continuously and C1: θ_L = z for z ≤ θ_s = π/2 - φ_s, and
// φ_L = φ_s exp(-(z - θ_s)/φ_s) beyond, with the log form used whenever z > θ_s.
//
// The residual is increasing in z (a strip that starts steeper at the tip bends less: a
// comparison argument on the ODE), negative exactly for z below the root, so a bracket is kept
// and Newton steps (slope from the variational equation in z) that leave it are replaced by
// bisection. Trials whose angle drops below -1 rad are stopped early: they are certainly below
// the root, and integrating them further would wander into curled-back states. As θ_L < π/2 for
// every trial, the curled-back equilibria (θ > π/2 somewhere) are never found.
//
// The law's kinks: B(κ) has a corner at each of the law's breakpoints (M is C1, not C2): κ0 of
// a Pabst law, every knot of a spline law. m grows monotonically from the tip, so each moment
// M(κ_k) is crossed at most once, in ascending order. Each is an integration event: the step
// that crosses it is redone to end exactly there (cubic Hermite guess, then Newton on m̃), so
// each rk8pd step sees a smooth right-hand side.

namespace textile {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Shooting unknown z -> tip: θ_L = z below kSwitchAngle, φ_L = kSwitchGap exp(-(z - ...)/...)
// above. 0.5 rad keeps both forms far from their precision limits (θ near 0 in the log form,
// φ near 0 in the direct form).
constexpr double kSwitchGap = 0.5;
constexpr double kSwitchAngle = kHalfPi - kSwitchGap;
// A trial whose angle falls below this is certainly below the root (and its continuation would
// curl); stop integrating it.
constexpr double kAbortAngle = -1.0;
// Per shot cap on accepted steps; a strip 300 bending lengths long needs ~10⁴.
constexpr int kMaxStepsPerShot = 400000;
// Steps between readings of the wall clock for ElasticaOptions::max_seconds (a step costs about
// a microsecond, a reading tens of nanoseconds).
constexpr int kClockStride = 1024;
// Moments [N] below this are treated as 0 when forming κ(m)/m (its limit 1/B(0) is then exact
// to far below double precision: the relative correction is c1 m / b1²).
constexpr double kTinyMoment = 1e-200;

constexpr int kPrimary = 4;        // (θ or ψ, m̃ or μ̃, X̃, Ỹ)
constexpr int kMaxDirections = 4;  // z, b1, b2, c1
constexpr int kMaxDim = kPrimary * (1 + kMaxDirections);

// What the right-hand sides need; no allocation happens in them.
struct Strip {
  const BendingLaw* law = nullptr;
  double length = 0.0;        // L [m]
  double moment_scale = 0.0;  // ρ g L² [N]
  double load = 0.0;          // ρ g L³ [N·m]
  double stiffness0 = 0.0;    // B(0) [N·m]
  int num_directions = 1;     // variational directions: z, then optionally b1, b2, c1
  std::array<double, 3> param_scale{};  // the p-directions are s_p ∂/∂p, O(1) in size
  const StripVariation* variation = nullptr;  // null: a uniform strip
};

// Stiffness multiplier S and scaled weight from the tip w = W(u)/L at t = u/L (1 and t for a
// uniform strip). With them dm̃/dt = w cos θ and κ = M⁻¹(m/S).
inline void Variation(const Strip& p, double t, double* multiplier, double* weight) {
  *multiplier = 1.0;
  *weight = t;
  if (p.variation == nullptr) return;
  const double u = t * p.length;
  if (p.variation->stiffness_multiplier) *multiplier = p.variation->stiffness_multiplier(u);
  if (p.variation->weight_from_tip) *weight = p.variation->weight_from_tip(u) / p.length;
}

// ∂M/∂p divided by κ, per branch, finite as κ -> 0 (used by the log form).
std::array<double, 3> MomentGradientOverKappa(const BendingLaw& law, double kappa) {
  const double k0 = law.kappa0();
  if (k0 > 0.0 && kappa <= k0) return {1.0, 0.0, kappa};
  if (k0 == 0.0) return {0.0, 1.0, 0.0};
  const double q = k0 / kappa;  // kappa > k0 > 0 here
  return {q, 1.0 - q, k0 * q};
}

// Direct form, state (θ, m̃, X̃, Ỹ) followed by their derivatives along each direction.
int DirectRhs(double t, const double y[], double f[], void* params) {
  const Strip& p = *static_cast<const Strip*>(params);
  double sm, w;
  Variation(p, t, &sm, &w);
  const double theta = y[0];
  const double kappa = p.law->Curvature(p.moment_scale * y[1] / sm);
  const double c = std::cos(theta), s = std::sin(theta);
  f[0] = -p.length * kappa;
  f[1] = w * c;
  f[2] = c;
  f[3] = s;
  // Variational equations: δθ' = -(A δm̃ + L s_p ∂κ/∂p), δm̃' = -t sin θ δθ, with
  // A = ρgL³/(S B(κ)) = L ∂κ/∂m̃ and ∂κ/∂p|m = -∂M/∂p / B (S M(κ) = m: S cancels).
  const double b = p.law->Stiffness(kappa);
  const double a = p.load / (sm * b);
  std::array<double, 3> grad{};
  if (p.num_directions > 1) grad = p.law->MomentGradient(kappa);
  for (int k = 0; k < p.num_directions; ++k) {
    const double* d = y + kPrimary * (k + 1);
    double* fd = f + kPrimary * (k + 1);
    const double forcing = k == 0 ? 0.0 : -p.param_scale[k - 1] * p.length / b * grad[k - 1];
    fd[0] = -(a * d[1] + forcing);
    fd[1] = -w * s * d[0];
    fd[2] = -s * d[0];
    fd[3] = c * d[0];
  }
  return GSL_SUCCESS;
}

// sin(φ)/φ and cos φ - sin(φ)/φ without cancellation for small φ (Taylor series to φ⁸,
// truncation < 1e-17 relative below 0.1), given sin φ and cos φ.
inline void Sinc(double phi, double sin_phi, double cos_phi, double* sinc,
                 double* cos_minus_sinc) {
  if (phi < 0.1) {
    const double q = phi * phi;
    *sinc = 1.0 - q / 6.0 * (1.0 - q / 20.0 * (1.0 - q / 42.0 * (1.0 - q / 72.0)));
    *cos_minus_sinc = -q / 3.0 * (1.0 - q / 10.0 * (1.0 - q / 28.0 * (1.0 - q / 54.0)));
  } else {
    *sinc = sin_phi / phi;
    *cos_minus_sinc = cos_phi - *sinc;
  }
}

// Log form, state (ψ = log(π/2 - θ), μ̃ = m̃/φ, X̃, Ỹ) and derivatives along each direction.
int LogRhs(double t, const double y[], double f[], void* params) {
  const Strip& p = *static_cast<const Strip*>(params);
  double sm, w;
  Variation(p, t, &sm, &w);
  const double psi = y[0], mu = y[1];
  const double phi = std::exp(psi);  // may underflow to 0: nothing below divides by it
  const double m = p.moment_scale * mu * phi;
  double kappa, ratio;  // κ [1/m] and κ/m [1/(N·m)]
  if (m > kTinyMoment) {
    kappa = p.law->Curvature(m / sm);
    ratio = kappa / m;
  } else {
    ratio = 1.0 / (sm * p.stiffness0);
    kappa = m * ratio;
  }
  const double r = p.load * ratio;
  const double sphi = std::sin(phi), cphi = std::cos(phi);
  double sinc, cos_minus_sinc;
  Sinc(phi, sphi, cphi, &sinc, &cos_minus_sinc);
  const double dpsi = r * mu;  // = L κ / φ
  f[0] = dpsi;
  f[1] = w * sinc - dpsi * mu;
  f[2] = sphi;  // cos θ
  f[3] = cphi;  // sin θ
  // Variational equations of (ψ, μ̃): with δm̃ = φ (δμ̃ + μ̃ δψ),
  //   δψ' = A (δμ̃ + μ̃ δψ) + P ψ' - ψ' δψ,   P = -(s_p/B) (∂M/∂p)/κ,
  //   δμ̃' = t (cos φ - sinc φ) δψ - ψ' δμ̃ - μ̃ δψ'.
  const double b = p.law->Stiffness(kappa);
  const double a = p.load / (sm * b);
  std::array<double, 3> grad_over_kappa{};
  if (p.num_directions > 1) grad_over_kappa = MomentGradientOverKappa(*p.law, kappa);
  for (int k = 0; k < p.num_directions; ++k) {
    const double* d = y + kPrimary * (k + 1);
    double* fd = f + kPrimary * (k + 1);
    const double forcing = k == 0 ? 0.0 : -p.param_scale[k - 1] / b * grad_over_kappa[k - 1];
    const double dd0 = a * (d[1] + mu * d[0]) + forcing * dpsi - dpsi * d[0];
    fd[0] = dd0;
    fd[1] = w * cos_minus_sinc * d[0] - dpsi * d[1] - mu * dd0;
    fd[2] = cphi * phi * d[0];
    fd[3] = -sphi * phi * d[0];
  }
  return GSL_SUCCESS;
}

// State accessors, for either form.
double Angle(bool log_form, const double* y) {
  return log_form ? kHalfPi - std::exp(y[0]) : y[0];
}
double ScaledMoment(bool log_form, const double* y) {
  return log_form ? y[1] * std::exp(y[0]) : y[1];
}
double ScaledMomentRate(bool log_form, double t, const double* y) {
  return t * (log_form ? std::sin(std::exp(y[0])) : std::cos(y[0]));
}

struct GslDeleter {
  void operator()(gsl_odeiv2_step* p) const { gsl_odeiv2_step_free(p); }
  void operator()(gsl_odeiv2_evolve* p) const { gsl_odeiv2_evolve_free(p); }
  void operator()(gsl_odeiv2_control* p) const { gsl_odeiv2_control_free(p); }
};

// GSL's stepper, step-size control and evolution for one state dimension, reused across shots.
// The absolute tolerance is scaled per component to its expected size (index 0: direct form,
// 1: log form), so that small deflections keep their relative accuracy.
struct Integrator {
  using Control = std::unique_ptr<gsl_odeiv2_control, GslDeleter>;
  // The tolerances are set per shot (gsl_odeiv2_control_init keeps the scales).
  Integrator(int dim, const double* direct_scale, const double* log_scale)
      : dim(dim),
        step(gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, dim)),
        evolve(gsl_odeiv2_evolve_alloc(dim)),
        control{Control(gsl_odeiv2_control_scaled_new(1e-10, 1e-10, 1.0, 0.0, direct_scale, dim)),
                Control(gsl_odeiv2_control_scaled_new(1e-10, 1e-10, 1.0, 0.0, log_scale, dim))} {}
  int dim;
  std::unique_ptr<gsl_odeiv2_step, GslDeleter> step;
  std::unique_ptr<gsl_odeiv2_evolve, GslDeleter> evolve;
  Control control[2];
};

struct ShotResult {
  enum class Kind { kReachedClamp, kUndershot, kFailed };
  Kind kind = Kind::kFailed;
  double residual = kNaN;  // increasing in z, 0 at the solution
  double slope = kNaN;     // d residual / dz
  double kink_t = kNaN;    // where m = M(κ0), if crossed
  std::string failure;
};

// Integrates the strip from the tip for a given shooting unknown, optionally recording the state
// at given t (ascending). Owns the GSL objects; the state lives in fixed arrays.
class Shooter {
 public:
  // angle_scale: expected size of θ (small loads: the tip angle), for the error control.
  // variation: null or non-empty; it must outlive the shooter.
  Shooter(const BendingLaw& law, double areal_density, double length, double angle_scale,
          const StripVariation* variation) {
    strip_.law = &law;
    strip_.variation = variation;
    if (variation != nullptr) {
      for (double u : variation->breakpoints) {
        if (u > 0.0 && u < length) breaks_t_.push_back(u / length);
      }
      std::sort(breaks_t_.begin(), breaks_t_.end());
    }
    strip_.length = length;
    strip_.moment_scale = areal_density * units::kGravity * length * length;
    strip_.load = strip_.moment_scale * length;
    strip_.stiffness0 = law.Stiffness(0.0);
    // s_p: b1 and b2 relative to themselves; c1 against B(0) over a typical curvature.
    const double bending_length = std::cbrt(strip_.stiffness0 / (areal_density * units::kGravity));
    const double ratio = bending_length / length;
    strip_.param_scale = {law.b1(), law.b2(),
                          strip_.stiffness0 * bending_length * std::max(1.0, ratio * ratio)};
    // A Pabst law's one breakpoint is κ0, whose moment the law keeps; a spline's are its knots.
    for (double k : law.Breakpoints()) {
      const double m = law.is_spline() ? law.Moment(k) : law.moment_at_kappa0();
      kink_moments_.push_back(m / strip_.moment_scale);
    }

    // Expected sizes of the components, θ-like ones scaled by the deflection (small loads).
    const double a = std::min(1.0, angle_scale), a2 = a * a;
    const std::array<double, kPrimary> direct_primary{a, 1.0, 1.0, a};
    const std::array<double, kPrimary> direct_z{1.0, a, a, 1.0};
    const std::array<double, kPrimary> direct_p{a, a2, a2, a};
    std::array<double, kMaxDim> direct_scale{}, log_scale{};
    for (int i = 0; i < kPrimary; ++i) {
      direct_scale[i] = direct_primary[i];
      direct_scale[kPrimary + i] = direct_z[i];
      for (int k = 2; k <= kMaxDirections; ++k) direct_scale[kPrimary * k + i] = direct_p[i];
    }
    log_scale.fill(1.0);
    cheap_ = std::make_unique<Integrator>(2 * kPrimary, direct_scale.data(), log_scale.data());
    full_ = std::make_unique<Integrator>(kMaxDim, direct_scale.data(), log_scale.data());
  }

  // Shots stop with kFailed once max_seconds have passed since start (ElasticaOptions).
  void SetTimeCap(std::chrono::steady_clock::time_point start, double max_seconds) {
    start_ = start;
    max_seconds_ = max_seconds;
  }

  const Strip& strip() const { return strip_; }
  const std::array<double, kMaxDim>& final_state() const { return y_; }
  int total_steps() const { return total_steps_; }

  // tol: error tolerance of this shot. num_directions: 1 (z only) or 4 (z, b1, b2, c1).
  // record: dim × targets.size(), may be null when targets is empty.
  ShotResult Shoot(double z, double tol, int num_directions, std::span<const double> targets,
                   Eigen::MatrixXd* record) {
    ShotResult result;
    log_form_ = z > kSwitchAngle;
    strip_.num_directions = num_directions;
    Integrator& integ = num_directions == 1 ? *cheap_ : *full_;
    dim_ = integ.dim;
    sys_ = {log_form_ ? LogRhs : DirectRhs, nullptr, static_cast<size_t>(dim_), &strip_};
    integ_ = &integ;
    gsl_odeiv2_evolve_reset(integ.evolve.get());
    gsl_odeiv2_step_reset(integ.step.get());
    gsl_odeiv2_control_init(integ.control[log_form_ ? 1 : 0].get(), tol, tol, 1.0, 0.0);

    y_.fill(0.0);
    if (log_form_) {
      y_[0] = std::log(kSwitchGap) - (z - kSwitchAngle) / kSwitchGap;
      y_[kPrimary] = -1.0 / kSwitchGap;
    } else {
      y_[0] = z;
      y_[kPrimary] = 1.0;
    }
    t_ = 0.0;
    // Start from the first step of the previous shot (the tip region changes little between
    // shots), else small: the controller grows it by up to 4.9× per step.
    h_ = std::isnan(first_step_) ? 1e-3 : first_step_;
    first_step_ = kNaN;
    // With a varying stiffness m/S may cross M(κ0) more than once: no events then.
    next_kink_ = strip_.variation != nullptr ? kink_moments_.size() : 0;
    kink_t_ = kNaN;
    steps_ = 0;

    for (size_t i = 0; i < targets.size(); ++i) {
      if (!Advance(targets[i], &result)) return result;
      record->col(static_cast<Eigen::Index>(i)) =
          Eigen::Map<const Eigen::VectorXd>(y_.data(), dim_);
    }
    if (!Advance(1.0, &result)) return result;

    result.kind = ShotResult::Kind::kReachedClamp;
    result.kink_t = kink_t_;
    if (log_form_) {
      result.residual = std::log(kHalfPi) - y_[0];
      result.slope = -y_[kPrimary];
    } else {
      result.residual = y_[0];
      result.slope = y_[kPrimary];
    }
    return result;
  }

  bool log_form() const { return log_form_; }

 private:
  // Integrates to t_target (≤ 1), handling the kink event and the early stop.
  bool Advance(double t_target, ShotResult* result) {
    gsl_odeiv2_evolve* evolve = integ_->evolve.get();
    gsl_odeiv2_control* control = integ_->control[log_form_ ? 1 : 0].get();
    gsl_odeiv2_step* step = integ_->step.get();
    std::array<double, kMaxDim> y_prev;
    while (t_ < t_target) {
      if (++steps_ > kMaxStepsPerShot) {
        result->kind = ShotResult::Kind::kFailed;
        result->failure = "more than " + std::to_string(kMaxStepsPerShot) +
                          " integration steps in one shot (strip too long or too soft?)";
        return false;
      }
      // The wall clock at the first step of every shot, then every kClockStride steps.
      if (steps_ % kClockStride == 1) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        if (elapsed >= max_seconds_) {
          result->kind = ShotResult::Kind::kFailed;
          std::ostringstream why;
          why << "time cap: the solve ran for " << elapsed << " s, max_seconds = " << max_seconds_
              << " s (stopped at s/L = " << 1.0 - t_ << ")";
          result->failure = why.str();
          return false;
        }
      }
      std::copy_n(y_.begin(), dim_, y_prev.begin());
      const double t_prev = t_, h_prev = h_;
      // Stop at the next breakpoint of a strip variation, if it comes first.
      double t_stop = t_target;
      const auto next_break = std::upper_bound(breaks_t_.begin(), breaks_t_.end(), t_);
      if (next_break != breaks_t_.end() && *next_break < t_target) t_stop = *next_break;
      const int status =
          gsl_odeiv2_evolve_apply(evolve, control, step, &sys_, &t_, t_stop, &h_, y_.data());
      if (status != GSL_SUCCESS || !std::all_of(y_.begin(), y_.begin() + dim_,
                                                [](double v) { return std::isfinite(v); })) {
        result->kind = ShotResult::Kind::kFailed;
        std::ostringstream why;
        why << "integration failed at s/L = " << 1.0 - t_prev << " (" << gsl_strerror(status)
            << (status == GSL_SUCCESS ? ", non-finite state" : "") << ")";
        result->failure = why.str();
        return false;
      }
      ++total_steps_;
      if (std::isnan(first_step_)) first_step_ = t_ - t_prev;
      while (next_kink_ < kink_moments_.size()) {
        const double kink = kink_moments_[next_kink_];
        const double g_prev = ScaledMoment(log_form_, y_prev.data()) - kink;
        const double g = ScaledMoment(log_form_, y_.data()) - kink;
        if (g < 0.0) break;  // not reached yet
        ++next_kink_;
        if (g_prev < 0.0) {
          // Crossed in this step: redo it to end there (before any later kink).
          LocateKink(kink, t_prev, y_prev, g_prev, t_, g, h_prev);
          if (next_kink_ == kink_moments_.size()) kink_t_ = t_;  // the last: κ0
          break;
        }
      }
      if (Angle(log_form_, y_.data()) < kAbortAngle) {
        result->kind = ShotResult::Kind::kUndershot;
        return false;
      }
    }
    return true;
  }

  // The last step [t_prev, t_next] crossed m̃ = kink; redo it so that it ends there.
  void LocateKink(double kink, double t_prev, const std::array<double, kMaxDim>& y_prev,
                  double g_prev, double t_next, double g_next, double h_prev) {
    gsl_odeiv2_evolve* evolve = integ_->evolve.get();
    gsl_odeiv2_control* control = integ_->control[log_form_ ? 1 : 0].get();
    gsl_odeiv2_step* step = integ_->step.get();
    // Cubic Hermite through the step ends (m̃' = t cos θ is known), solved by bisection.
    const double width = t_next - t_prev;
    const double d0 = width * ScaledMomentRate(log_form_, t_prev, y_prev.data());
    const double d1 = width * ScaledMomentRate(log_form_, t_next, y_.data());
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 60; ++it) {
      const double tau = 0.5 * (lo + hi), tau2 = tau * tau, tau3 = tau2 * tau;
      const double p = (2 * tau3 - 3 * tau2 + 1) * g_prev + (tau3 - 2 * tau2 + tau) * d0 +
                       (-2 * tau3 + 3 * tau2) * g_next + (tau3 - tau2) * d1;
      (p < 0.0 ? lo : hi) = tau;
    }
    double t_kink = t_prev + 0.5 * (lo + hi) * width;
    // Redo the step to the guess, then Newton on m̃(t) - m̃(κ0) (the Hermite guess is already
    // O(h⁴) accurate; a miss ε only costs O(ε³) since M is C1 at κ0).
    for (int it = 0; it < 3; ++it) {
      std::copy_n(y_prev.begin(), dim_, y_.begin());
      t_ = t_prev;
      gsl_odeiv2_evolve_reset(evolve);
      gsl_odeiv2_step_reset(step);
      double h = t_kink - t_prev;
      while (t_ < t_kink && h > 0.0) {
        if (gsl_odeiv2_evolve_apply(evolve, control, step, &sys_, &t_, t_kink, &h, y_.data()) !=
            GSL_SUCCESS)
          break;
        ++total_steps_;
      }
      const double g = ScaledMoment(log_form_, y_.data()) - kink;
      const double rate = ScaledMomentRate(log_form_, t_, y_.data());
      if (std::abs(g) <= 1e-14 * kink || !(rate > 0.0)) break;
      const double next = std::clamp(t_kink - g / rate, t_prev, t_next);
      if (std::abs(next - t_kink) <= 1e-15) break;
      t_kink = next;
    }
    h_ = h_prev;
  }

  Strip strip_;
  std::vector<double> breaks_t_;  // breakpoints of the variation in t, ascending, in (0, 1)
  std::vector<double> kink_moments_;  // M(κ_k)/(ρgL²) at the law's breakpoints, ascending
  std::unique_ptr<Integrator> cheap_, full_;

  // Current shot.
  Integrator* integ_ = nullptr;
  gsl_odeiv2_system sys_{};
  int dim_ = 0;
  bool log_form_ = false;
  std::array<double, kMaxDim> y_{};
  double t_ = 0.0, h_ = 0.0;
  size_t next_kink_ = 0;  // the first of kink_moments_ not crossed yet
  double kink_t_ = kNaN;
  int steps_ = 0;
  int total_steps_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double max_seconds_ = std::numeric_limits<double>::infinity();
  double first_step_ = kNaN;  // first accepted step of the last shot
};

// Shooting unknown of a tip angle guess.
// The same from g = log(π/2 − θ), exact where π/2 − θ underflows in θ itself.
double UnknownOfLogTipGap(double g) {
  if (g >= std::log(kSwitchGap)) return kHalfPi - std::exp(g);
  return kSwitchAngle + kSwitchGap * (std::log(kSwitchGap) - g);
}

double UnknownOfTipAngle(double theta) {
  if (theta <= kSwitchAngle) return theta;
  return UnknownOfLogTipGap(std::log(kHalfPi - theta));
}

// Starting guess from the linear law with B(0), α = ρgL³/B: π/2 - θ_L ≈ (π/2) exp(-g(α)) with
// g = α/(3π) (so θ_L ≈ α/6, the small-load tip slope) up to α = 4π², where it meets the Airy
// growth of a hanging strip, g = (2/3)(L/ℓ)^{3/2} = (2/3)√α. Within ~10 % of θ_L at the
// standard 41.5° crossing and within ~1.5 in log(π/2 - θ_L) for long strips.
double InitialUnknown(const Strip& strip) {
  const double alpha = strip.load / strip.stiffness0;
  const double g = alpha <= 4.0 * std::numbers::pi * std::numbers::pi
                       ? alpha / (3.0 * std::numbers::pi)
                       : (2.0 / 3.0) * std::sqrt(alpha);
  const double log_gap = std::log(kHalfPi) - g;
  if (log_gap >= std::log(kSwitchGap)) return -std::expm1(-g) * kHalfPi;  // θ_L itself
  return kSwitchAngle + kSwitchGap * (std::log(kSwitchGap) - log_gap);
}

std::string Describe(double v, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

}  // namespace

bool ElasticaOptions::Check(std::string* why) const {
  std::ostringstream s;
  if (!(rel_tol >= 1e-14 && rel_tol <= 1e-3)) {
    s << "rel_tol must be in [1e-14, 1e-3], got " << rel_tol;
  } else if (arc_lengths.empty() && num_samples < 2) {
    s << "num_samples must be >= 2 (the edge and the tip), got " << num_samples;
  } else if (max_shooting_iterations < 2) {
    s << "max_shooting_iterations must be >= 2, got " << max_shooting_iterations;
  } else if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    s << "max_seconds must be a finite number >= 0, got " << max_seconds;
  } else if (!std::isnan(tip_angle_guess) &&
             !(tip_angle_guess >= 0.0 && tip_angle_guess < kHalfPi)) {
    s << "tip_angle_guess must be NaN or in [0, pi/2) rad, got " << tip_angle_guess;
  } else if (!std::isnan(log_tip_gap_guess) &&
             !(std::isfinite(log_tip_gap_guess) && log_tip_gap_guess < std::log(kHalfPi))) {
    s << "log_tip_gap_guess must be NaN or finite and below log(pi/2), got " << log_tip_gap_guess;
  } else if (!std::all_of(variation.breakpoints.begin(), variation.breakpoints.end(),
                          [](double u) { return std::isfinite(u); })) {
    s << "variation.breakpoints must be finite";
  } else {
    for (size_t i = 0; i < arc_lengths.size(); ++i) {
      if (!std::isfinite(arc_lengths[i]) || arc_lengths[i] < 0.0) {
        s << "arc_lengths[" << i << "] must be finite and >= 0, got " << arc_lengths[i];
        break;
      }
      if (i > 0 && arc_lengths[i] < arc_lengths[i - 1]) {
        s << "arc_lengths must be ascending, but [" << i << "] = " << arc_lengths[i] << " < ["
          << i - 1 << "] = " << arc_lengths[i - 1];
        break;
      }
    }
  }
  if (why != nullptr) *why = s.str();
  return s.str().empty();
}

std::string ElasticaProfile::BriefReport() const {
  std::ostringstream s;
  s.precision(6);
  s << "Heavy elastica, L = " << units::MToMm(length) << " mm, rho = "
    << units::SiToGsm(areal_density) << " g/m²: ";
  if (!converged) {
    s << "FAILED: " << message;
  } else {
    s << "tip (" << units::MToMm(tip_x) << ", " << units::MToMm(tip_y) << ") mm, theta(L) = "
      << tip_angle * 180.0 / std::numbers::pi << " deg, kappa(0) = "
      << units::SiCurvatureToKes(clamp_curvature) << " /cm";
    if (!std::isnan(kink_arc_length))
      s << ", kink kappa0 at s = " << units::MToMm(kink_arc_length) << " mm";
    s << "; " << shooting_iterations << " integrations, " << integration_steps << " steps";
  }
  return s.str();
}

namespace sim_internal {

ElasticaSamples SampleArcLengths(double length, const ElasticaOptions& options) {
  ElasticaSamples samples;
  samples.arc = options.arc_lengths;
  if (samples.arc.empty()) {
    const int n = options.num_samples;
    samples.arc.resize(n);
    for (int j = 0; j < n; ++j) samples.arc[j] = length * j / (n - 1.0);
    samples.arc.back() = length;
  }
  const int n = static_cast<int>(samples.arc.size());
  samples.targets.resize(n);
  for (int j = 0; j < n; ++j) {
    // Uniform samples get exact t; requested ones (L - s)/L.
    samples.targets[n - 1 - j] = options.arc_lengths.empty()
                                     ? (n - 1.0 - j) / (n - 1.0)
                                     : (length - samples.arc[j]) / length;
  }
  return samples;
}

void UpdateShooting(const ShotOutcome& shot, bool sensitivities, double accept_step,
                    ShootingState* state) {
  ShootingState& st = *state;
  const double z = st.z;
  if (!shot.reached_clamp || shot.residual < 0.0) {
    st.lo = std::max(st.lo, z);
  } else if (shot.residual > 0.0) {
    st.hi = std::min(st.hi, z);
  }
  double next = kNaN;
  if (shot.reached_clamp && shot.slope > 0.0 && std::isfinite(shot.slope)) {
    next = z - shot.residual / shot.slope;
  }
  const double scale = std::max(std::abs(z), std::numeric_limits<double>::min());
  const double step = next - z;  // NaN when there is no Newton step
  if (st.phase == ShootingPhase::kFinal && std::abs(step) <= accept_step * scale) {
    st.correction = step;
    st.done = true;
    return;
  }
  if (std::abs(step) <= kCloseStep * scale) {
    st.z = next;
    st.phase = st.phase == ShootingPhase::kCoarse && sensitivities ? ShootingPhase::kFine
                                                                   : ShootingPhase::kFinal;
    return;
  }
  st.phase = ShootingPhase::kCoarse;
  if (!(next > st.lo && next < st.hi)) {
    next = std::isinf(st.hi) ? std::max(2.0 * z, z + 1.0) : 0.5 * (st.lo + st.hi);
  }
  const double rounding = 4.0 * std::numeric_limits<double>::epsilon() * st.hi;
  if (std::isfinite(st.hi) && st.hi - st.lo <= rounding) {
    // The bracket has collapsed to rounding without Newton settling (should not happen: the
    // residual is smooth); take it as the root.
    next = 0.5 * (st.lo + st.hi);
    st.phase = ShootingPhase::kFinal;
  }
  st.z = next;
}

}  // namespace sim_internal

namespace {

using sim_internal::ElasticaSamples;
using sim_internal::ShootingPhase;
using sim_internal::ShootingState;

// Refuses bad options, density, length, and what the law cannot give (InputError).
void CheckElasticaInputs(const BendingLaw& law, double areal_density, double length,
                         const ElasticaOptions& options) {
  if (std::string why; !options.Check(&why)) throw InputError("elastica options: " + why);
  if (!(std::isfinite(areal_density) && areal_density > 0.0))
    throw InputError("areal density must be a finite number > 0 kg/m², got " +
                     Describe(areal_density));
  if (!(std::isfinite(length) && length > 0.0))
    throw InputError("overhang length must be a finite number > 0 m, got " + Describe(length));
  if (options.sensitivities && law.is_spline())
    throw InputError(
        "elastica sensitivities are derivatives by the Pabst constants {b1, b2, c1}: a spline law "
        "has none");
  if (!options.arc_lengths.empty() && options.arc_lengths.back() > length)
    throw InputError("arc length " + Describe(options.arc_lengths.back(), 10) +
                     " m lies beyond the overhang length " + Describe(length, 10) + " m");
}

// The first trial: the caller's guess when it gives a usable one, else InitialUnknown.
double FirstUnknown(const ElasticaOptions& options, const Strip& strip) {
  double z = !std::isnan(options.log_tip_gap_guess) ? UnknownOfLogTipGap(options.log_tip_gap_guess)
             : !std::isnan(options.tip_angle_guess)  ? UnknownOfTipAngle(options.tip_angle_guess)
                                                     : InitialUnknown(strip);
  if (!(z > 0.0 && std::isfinite(z))) z = InitialUnknown(strip);
  return z;
}

// What the shooting leaves for the assembly of the profile.
struct ShootingRun {
  ShootingState state;
  ShotResult last_shot;    // of the final pass
  Eigen::MatrixXd record;  // the final pass's states at the sample targets, dim × n
};

// Shoots until the final pass is accepted (true), or fails with profile->message set (false).
// Counts profile->shooting_iterations.
bool RunShooting(Shooter& shooter, const ElasticaOptions& options,
                 const std::vector<double>& targets, ShootingRun* run, ElasticaProfile* profile) {
  const int final_directions = options.sensitivities ? kMaxDirections : 1;
  const double coarse_tol = std::max(options.rel_tol, 1e-7);  // a third of the steps
  // The final pass's Newton step is applied linearly through the z-derivatives of the samples,
  // leaving an error O(step²) in the positions (and O(step) in the sensitivities).
  const double accept_step = options.sensitivities ? std::max(1e-9, 100.0 * options.rel_tol)
                                                   : std::max(1e-6, 100.0 * options.rel_tol);
  ShootingState& state = run->state;
  while (!state.done) {
    if (profile->shooting_iterations >= options.max_shooting_iterations) {
      std::ostringstream why;
      why << "shooting did not converge in " << options.max_shooting_iterations
          << " integrations (tip angle bracket [" << Describe(state.lo, 10) << ", "
          << Describe(state.hi, 10) << "] in the shooting unknown)";
      profile->message = why.str();
      return false;
    }
    ++profile->shooting_iterations;
    ShotResult& shot = run->last_shot;
    if (state.phase == ShootingPhase::kFinal) {
      run->record.resize(kPrimary * (1 + final_directions), static_cast<int>(targets.size()));
      shot = shooter.Shoot(state.z, options.rel_tol, final_directions, targets, &run->record);
    } else {
      const double tol = state.phase == ShootingPhase::kCoarse ? coarse_tol : options.rel_tol;
      shot = shooter.Shoot(state.z, tol, 1, {}, nullptr);
    }
    if (shot.kind == ShotResult::Kind::kFailed) {
      profile->message = shot.failure;
      return false;
    }
    const sim_internal::ShotOutcome outcome{shot.kind == ShotResult::Kind::kReachedClamp,
                                            shot.residual, shot.slope};
    sim_internal::UpdateShooting(outcome, options.sensitivities, accept_step, &state);
  }
  return true;
}

// The state at the edge after the final pass, with the last Newton correction applied
// linearly (also to the recorded states) through their z-derivatives.
std::array<double, kMaxDim> CorrectedEdge(const Shooter& shooter, ShootingRun* run) {
  const double correction = run->state.correction;
  std::array<double, kMaxDim> edge = shooter.final_state();
  for (int i = 0; i < kPrimary; ++i) {
    edge[i] += edge[kPrimary + i] * correction;
    run->record.row(i) += run->record.row(kPrimary + i) * correction;
  }
  return edge;
}

// Samples, tip and clamp of the profile from the corrected final pass.
void AssembleShape(const BendingLaw& law, const ElasticaOptions& options, const Shooter& shooter,
                   const ElasticaSamples& samples, const ShootingRun& run,
                   const std::array<double, kMaxDim>& edge, ElasticaProfile* profile) {
  const double length = profile->length;
  const std::vector<double>& arc = samples.arc;
  const int n = static_cast<int>(arc.size());
  const bool log_form = shooter.log_form();
  const Strip& strip = shooter.strip();
  // S at distance u from the tip (1 for a uniform strip): κ = M⁻¹(m / S).
  auto multiplier = [&options](double u) {
    return options.variation.stiffness_multiplier ? options.variation.stiffness_multiplier(u) : 1.0;
  };
  const double tip_x_scaled = edge[2], tip_y_scaled = edge[3];

  profile->s = arc;
  profile->x.resize(n);
  profile->y.resize(n);
  profile->theta.resize(n);
  profile->kappa.resize(n);
  profile->moment.resize(n);
  for (int j = 0; j < n; ++j) {
    const double* y = run.record.col(n - 1 - j).data();
    profile->theta[j] = Angle(log_form, y);
    profile->moment[j] = strip.moment_scale * ScaledMoment(log_form, y);
    profile->kappa[j] = law.Curvature(profile->moment[j] / multiplier(length - arc[j]));
    profile->x[j] = length * (tip_x_scaled - y[2]);
    profile->y[j] = -length * (tip_y_scaled - y[3]);
  }
  // The tip, from the initial state (exact map of z).
  const double z_final = run.state.z + run.state.correction;
  if (log_form) {
    profile->log_tip_gap = std::log(kSwitchGap) - (z_final - kSwitchAngle) / kSwitchGap;
    profile->tip_angle = kHalfPi - std::exp(profile->log_tip_gap);
  } else {
    profile->tip_angle = z_final;
    profile->log_tip_gap = std::log(kHalfPi - z_final);
  }
  profile->tip_x = length * tip_x_scaled;
  profile->tip_y = -length * tip_y_scaled;
  profile->clamp_moment = strip.moment_scale * ScaledMoment(log_form, edge.data());
  profile->clamp_curvature = law.Curvature(profile->clamp_moment / multiplier(length));
  if (!std::isnan(run.last_shot.kink_t))
    profile->kink_arc_length = length * (1.0 - run.last_shot.kink_t);
}

// d(x, y, θ)/d(b1, b2, c1) at the samples, from the final pass's variational states.
void AssembleSensitivities(const Shooter& shooter, const ShootingRun& run,
                           const std::array<double, kMaxDim>& edge, ElasticaProfile* profile) {
  const double length = profile->length;
  const int n = static_cast<int>(profile->s.size());
  const bool log_form = shooter.log_form();
  const Strip& strip = shooter.strip();
  // Eliminate the tip through the shooting condition: dz/dp = -(∂r/∂p)/(∂r/∂z), where the
  // residual r is θ(edge) or log(π/2) - ψ(edge); both are linear in the state's first
  // component, so the ratio of that component's derivatives does it.
  std::array<double, 3> dz_dp;
  for (int k = 0; k < 3; ++k) dz_dp[k] = -edge[kPrimary * (k + 2)] / edge[kPrimary];
  profile->dx_dp.resize(n, 3);
  profile->dy_dp.resize(n, 3);
  profile->dtheta_dp.resize(n, 3);
  // Total derivative of primary component i along p-direction k at a state.
  auto total = [&](const double* y, int k, int i) {
    return y[kPrimary * (k + 2) + i] + y[kPrimary + i] * dz_dp[k];
  };
  for (int j = 0; j < n; ++j) {
    const double* y = run.record.col(n - 1 - j).data();
    const double phi = log_form ? std::exp(y[0]) : 0.0;
    for (int k = 0; k < 3; ++k) {
      const double inv_scale = 1.0 / strip.param_scale[k];
      const double d_angle = log_form ? -phi * total(y, k, 0) : total(y, k, 0);
      profile->dtheta_dp(j, k) = d_angle * inv_scale;
      profile->dx_dp(j, k) = length * (total(edge.data(), k, 2) - total(y, k, 2)) * inv_scale;
      profile->dy_dp(j, k) = -length * (total(edge.data(), k, 3) - total(y, k, 3)) * inv_scale;
    }
  }
}

}  // namespace

// Stages: check the inputs, choose the samples, shoot (safeguarded Newton on the tip unknown),
// then assemble the shape and, if asked, the sensitivities.
ElasticaProfile SolveHeavyElastica(const BendingLaw& law, double areal_density, double length,
                                   const ElasticaOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckElasticaInputs(law, areal_density, length, options);

  ElasticaProfile profile;
  profile.length = length;
  profile.areal_density = areal_density;
  const ElasticaSamples samples = sim_internal::SampleArcLengths(length, options);

  // Deflection scale for the error control: the small-load tip angle, capped at 1.
  const double alpha = areal_density * units::kGravity * length * length * length /
                       law.Stiffness(0.0);
  Shooter shooter(law, areal_density, length, alpha / 6.0,
                  options.variation.empty() ? nullptr : &options.variation);
  shooter.SetTimeCap(start, options.max_seconds);

  ShootingRun run;
  run.state.z = FirstUnknown(options, shooter.strip());
  const bool converged = RunShooting(shooter, options, samples.targets, &run, &profile);
  profile.integration_steps = shooter.total_steps();
  if (!converged) return profile;

  const std::array<double, kMaxDim> edge = CorrectedEdge(shooter, &run);
  AssembleShape(law, options, shooter, samples, run, edge, &profile);
  if (options.sensitivities) AssembleSensitivities(shooter, run, edge, &profile);

  profile.converged = true;
  std::ostringstream msg;
  msg << "converged in " << profile.shooting_iterations << " integrations";
  profile.message = msg.str();
  return profile;
}

}  // namespace textile
