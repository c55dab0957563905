#include "textile/fit/direct_fit.h"

#include <ceres/ceres.h>

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <tuple>

#include "cost_functions/profile_model.h"
#include "direct_fit_stages.h"
#include "textile/fit/clapp.h"
#include "law_parameters.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/textile_range.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using internal::ProfileModel;

// A constant whose 1-σ exceeds this fraction of its value is "not determined by the data".
constexpr double kUndeterminedRelSd = 0.5;

// Weight of the prior [mm per unit of ln b or ln κ0] at the noise it was set for, σ = 0.1 mm.
// Its pull on the estimate goes with (weight/σ)², so it is scaled with the fit's rms
// (kPriorPerRms, at least kPriorFloor) to keep the same relative pull: at a fixed 1e-2 mm it
// moved c1 of noise-free 200-250 mm strips 30 % or more off the truth, far outside their sd, and
// on σ = 0.5 mm data it was too weak to keep b1 of a soft shirting off its lower bound.
constexpr double kPriorWeight = 1e-2;
constexpr double kPriorPerRms = 0.1;
constexpr double kPriorFloor = 1e-3;

// Largest spacing of the model curve's elastica samples [m]: its cubic Hermite interpolation
// must follow the clamp's bend (a 250 mm strip at 41 samples, 6 mm apart, put c1 15 % off; 2 mm
// recover it to 0.2 %). Overhangs up to 80 mm keep options.curve_samples.
constexpr double kMaxSampleSpacing = 2e-3;

class LawPrior : public ceres::SizedCostFunction<2, 3> {
 public:
  LawPrior(double weight, double log_kappa_ref) : w_(weight), log_kappa_ref_(log_kappa_ref) {}
  double weight() const { return w_; }
  void set_weight(double w) { w_ = w; }
  bool Evaluate(double const* const* p, double* r, double** jac) const override {
    r[0] = w_ * (p[0][1] - p[0][0]);
    r[1] = w_ * (p[0][2] - log_kappa_ref_);
    if (jac && jac[0]) {
      const double j[6] = {-w_, w_, 0.0, 0.0, 0.0, w_};
      std::copy(j, j + 6, jac[0]);
    }
    return true;
  }

 private:
  double w_, log_kappa_ref_;
};


std::string Mm(double m) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << m * 1e3 << " mm";
  return s.str();
}

// The strip's length from its points, insensitive to their noise: the polyline through points
// at least 1/50 of the edge-to-tip chord apart. The plain arc length s grows by about σ²/h a
// segment for noise σ at spacing h: 3000 points with σ = 0.1 mm on a 60 mm strip measured
// 545 mm, and the start and the bounds of the fitted overhang, taken from it, excluded the truth.
double NoiseFreeLength(const Profile& p) {
  const size_t n = p.x.size();
  const double chord = std::hypot(p.x.back() - p.x.front(), p.y.back() - p.y.front());
  const double step = chord / 50.0;
  double length = 0.0;
  size_t last = 0;
  for (size_t i = 1; i < n; ++i) {
    const double d = std::hypot(p.x[i] - p.x[last], p.y[i] - p.y[last]);
    if (d >= step || i + 1 == n) {
      length += d;
      last = i;
    }
  }
  // s_mm may start past the edge (the first points cut off): the overhang includes that part.
  return std::max(0.0, p.s.front()) + std::max(length, chord);
}

}  // namespace

bool DirectFitOptions::Check(std::string* why) const {
  const auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (!std::isfinite(offset) || std::abs(offset) > 0.01)
    return fail("offset must be finite and within ±10 mm");
  // Ceres squares the Cauchy scale: beyond these bounds the cost over- or underflows (1e200 mm
  // gave a NaN cost and the start law back, exit 0).
  if (!(robust_scale == 0.0 || (robust_scale >= 1e-6 && robust_scale <= 0.1)))
    return fail("robust_scale must be 0 (off) or in [0.001, 100] mm");
  if (curve_samples < 11 || curve_samples > 10001)
    return fail("curve_samples must lie in [11, 10001]");
  if (!(elastica_tol >= 1e-14 && elastica_tol <= 1e-4))
    return fail("elastica_tol must lie in [1e-14, 1e-4]");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(max_seconds > 0.0)) return fail("max_seconds must be > 0");
  if (!(outlier_profile_rms > 0.0)) return fail("outlier_profile_rms must be > 0");
  return true;
}

double PeirceStiffnessEstimate(const Profile& p, double areal_density) {
  // Peirce (1930): c = L (cos(θc/2) / (8 tan θc))^(1/3), θc the chord angle to the tip;
  // G = ρ g c³. Only a starting point, so the angle is kept where the formula is sane.
  const double chord = std::atan2(-(p.y.back() - p.y.front()), p.x.back() - p.x.front());
  const double th = std::clamp(chord, 0.02, 1.45);
  const double L = NoiseFreeLength(p);
  const double c = L * std::cbrt(std::cos(th / 2) / (8 * std::tan(th)));
  return areal_density * units::kGravity * c * c * c;
}

std::string DirectFitSummary::BriefReport() const {
  std::ostringstream s;
  s.precision(4);
  if (!converged || !law) return "direct fit failed: " + message;
  // An sd the covariance could not give is said so, not printed as "nan".
  const auto sd = [](double v) {
    std::ostringstream o;
    o.precision(4);
    if (std::isfinite(v))
      o << v;
    else
      o << "(no sd)";
    return o.str();
  };
  s << "direct fit: b1 = " << law->b1_kes() << " ± " << sd(units::SiStiffnessToKes(b1_sd))
    << " gf·cm, b2 = " << law->b2_kes() << " ± " << sd(units::SiStiffnessToKes(b2_sd))
    << " gf·cm, c1 = " << law->c1_kes() << " ± " << sd(units::SiQuadraticToKes(c1_sd))
    << " gf·cm²; rms " << Mm(rms) << " over " << profiles.size() << " profile(s), " << iterations
    << " iterations, " << seconds * 1e3 << " ms. " << observability;
  return s.str();
}

namespace {

// Where a solve starts: the law p = (ln b1, ln b2, ln κ0) and the centre of its bounds.
struct LawStart {
  std::array<double, 3> p{};
  double b_centre = 0.0;  // b1, b2 bounded within a factor 100 of this [N·m]
  std::string name;       // "Peirce" or "Clapp", for reports
};

// A linear law from Peirce's formula (geometric mean over profiles), κ0 at the curvature
// scale 1/c of that law.
LawStart PeirceStart(const std::vector<Profile>& profiles, double areal_density) {
  double log_b = 0.0;
  for (const Profile& p : profiles) log_b += std::log(PeirceStiffnessEstimate(p, areal_density));
  const double b0 = std::exp(log_b / profiles.size());
  const double c0 = std::cbrt(b0 / (areal_density * units::kGravity));
  return {{std::log(b0), std::log(b0), std::log(1.0 / c0)}, b0, "Peirce"};
}

// The data's own M-κ: Clapp's regression (clapp.h) on the same profiles, robust, with the
// digitised points' distances as weights. Its law follows a softening the linear start cannot
// reach within its bounds (a technical fabric whose moment is nearly constant past a small
// curvature). None when the regression fails.
std::optional<LawStart> ClappStart(const std::vector<Profile>& profiles, double areal_density) {
  ClappOptions o;
  o.weighting = ClappWeighting::kRadius;
  o.loss = ClappLoss::kCauchy;
  o.max_seconds = 2.0;
  try {
    const ClappResult r = FitClapp(profiles, areal_density, o);
    if (!r.success || !r.law) return std::nullopt;
    const std::array<double, 3> p = internal::ParametersFromLaw(*r.law);
    return LawStart{p, std::exp(0.5 * (p[0] + p[1])), "Clapp"};
  } catch (const InputError&) {
    return std::nullopt;  // too few points for its polynomial: the direct fit's start stands
  }
}

DirectFitSummary FitDirectFrom(const std::vector<Profile>& profiles, double areal_density,
                               const DirectFitOptions& options, const LawStart& start);

// A fit whose rms exceeds this many times the points' scatter (and kLackOfFitFloor) is one the
// law does not follow: the fit tries its other start, and the report says where it misses.
constexpr double kLackOfFitRatio = 3.0;
constexpr double kLackOfFitFloor = 0.05e-3;  // [m]: below it a misfit is within any claim

bool LacksFit(const DirectFitSummary& fit) {
  return fit.converged && fit.rms > kLackOfFitFloor &&
         fit.rms > kLackOfFitRatio * fit.point_scatter;
}

}  // namespace

DirectFitSummary FitDirect(const std::vector<Profile>& profiles, double areal_density,
                           const DirectFitOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!options.Check(&why)) throw InputError("direct fit options: " + why);
  if (profiles.empty()) throw InputError("direct fit: no profiles given");
  if (!(areal_density > 0.0) || !std::isfinite(areal_density)) {
    throw InputError("direct fit: areal density must be a finite number > 0");
  }
  for (const Profile& p : profiles) CheckProfile(p);
  // Peirce's linear start first; where it fails or the law misses the data by more than
  // their scatter, the data's own M-κ (Clapp) as a second start, keeping the better fit.
  DirectFitSummary fit = FitDirectFrom(profiles, areal_density, options,
                                       PeirceStart(profiles, areal_density));
  if (!fit.converged || LacksFit(fit)) {
    if (const std::optional<LawStart> clapp = ClappStart(profiles, areal_density)) {
      DirectFitSummary other = FitDirectFrom(profiles, areal_density, options, *clapp);
      if (other.converged && (!fit.converged || other.cost < fit.cost)) {
        other.iterations += fit.iterations;
        fit = std::move(other);
      } else {
        fit.iterations += other.iterations;
      }
    }
  }
  fit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return fit;
}

namespace {

// Where and how a converged fit misses the data (DirectFitSummary::fit_pattern): per profile
// the signed residuals' runs (noise changes sign about every other point; a law that cannot
// follow leaves long runs) and the rms on the law's two branches, the stretch nearer the clamp
// where κ > κ0 (b2, the linear branch) and beyond it (b1, c1: the quadratic).
std::string DescribeMisfit(const std::vector<Profile>& profiles,
                           const std::vector<std::unique_ptr<ProfileModel>>& models,
                           const DirectFitSummary& fit) {
  std::ostringstream s;
  s.precision(3);
  s << "the law does not follow the data: rms " << fit.rms * 1e3 << " mm against the points' own "
    << "scatter of " << fit.point_scatter * 1e3 << " mm";
  for (size_t i = 0; i < models.size(); ++i) {
    const ProfileModel& m = *models[i];
    const Profile& p = profiles[i];
    const double kink = m.solution().kink_arc_length;  // NaN: κ0 not reached
    const double scale = fit.profiles[i].overhang / std::max(p.s.back(), 1e-9);
    int runs = 1;
    double sum2[2] = {0.0, 0.0};
    int n[2] = {0, 0};
    for (int j = 0; j < m.num_points(); ++j) {
      const double r = m.residual(j);  // [mm]
      if (j > 0 && (r > 0.0) != (m.residual(j - 1) > 0.0)) ++runs;
      const int branch = std::isfinite(kink) && p.s[j] * scale < kink ? 0 : 1;
      sum2[branch] += r * r;
      ++n[branch];
    }
    s << "; " << p.source << ": " << runs << " sign runs in " << m.num_points()
      << " points (noise: about " << (m.num_points() + 1) / 2 << ")";
    if (n[0] > 0) {
      s << ", rms " << std::sqrt(sum2[0] / n[0]) << " mm on the linear branch (κ > κ0, the "
        << kink * 1e3 << " mm next to the edge)";
    }
    if (n[1] > 0) {
      s << (n[0] > 0 ? " and " : ", rms ") << std::sqrt(sum2[1] / n[1])
        << " mm on the quadratic branch (κ ≤ κ0)";
    }
  }
  s << ": Pabst's three constants cannot follow this fabric everywhere, or the profile is not a "
       "clean cantilever (a bend near the clamp, fibres, the strip's face)";
  return s.str();
}

// What a fit that did not converge left: its last law and rms, so that a user sees whether it
// was close (a cap too tight) or far (a law that cannot follow the data).
std::string LastIterateSummary(const std::vector<std::unique_ptr<ProfileModel>>& models,
                               std::array<double, 3> law_p, std::vector<double> lengths,
                               std::array<double, 2> rig) {
  double sum2 = 0.0;
  int n = 0;
  for (size_t i = 0; i < models.size(); ++i) {
    if (!models[i]->Update(law_p.data(), &lengths[i], rig.data(), false)) return "";
    for (int j = 0; j < models[i]->num_points(); ++j, ++n)
      sum2 += models[i]->residual(j) * models[i]->residual(j);
  }
  std::ostringstream s;
  s.precision(4);
  const BendingLaw law = internal::LawFromParameters(law_p.data());
  s << "; at its last step b1 = " << law.b1_kes() << ", b2 = " << law.b2_kes()
    << " gf·cm, kappa0 = " << units::SiCurvatureToKes(law.kappa0()) << " /cm, rms "
    << std::sqrt(sum2 / std::max(1, n)) << " mm";
  return s.str();
}

}  // namespace

namespace internal {

std::optional<std::array<double, 2>> LogStiffnessBounds(double b_centre) {
  const double lo_b =
      std::log(std::max(b_centre / 100.0, units::KesStiffnessToSi(range::kMinStiffnessKes)));
  const double hi_b =
      std::log(std::min(b_centre * 100.0, units::KesStiffnessToSi(range::kMaxStiffnessKes)));
  if (!(lo_b < hi_b)) return std::nullopt;
  return std::array<double, 2>{lo_b, hi_b};
}

std::optional<double> RescaledPriorWeight(double rms_mm, double current_weight) {
  const double w = std::max(kPriorFloor, kPriorPerRms * rms_mm);
  if (std::abs(std::log(w / current_weight)) > std::log(1.25)) return w;
  return std::nullopt;
}

void RefuseMixedStrips(const std::vector<Profile>& profiles, const DirectFitSummary& fit,
                       double outlier_profile_rms,
                       const std::function<double(const Profile&)>& rms_alone) {
  // One law for several profiles that fits badly, while each profile alone fits well, means
  // the profiles are not of one strip (or one is a bad extraction): refuse rather than average.
  if (profiles.size() < 2 || !(fit.rms > outlier_profile_rms)) return;
  const auto worse = [](const ProfileFitReport& a, const ProfileFitReport& b) {
    return a.rms < b.rms;
  };
  const size_t worst =
      std::max_element(fit.profiles.begin(), fit.profiles.end(), worse) - fit.profiles.begin();
  std::vector<double> alone;
  for (const Profile& p : profiles) alone.push_back(rms_alone(p));
  const double worst_alone = *std::max_element(alone.begin(), alone.end());
  if (worst_alone < fit.rms / 3.0) {
    throw InputError(profiles[worst].source + ": the profiles do not fit one law (rms " +
                     Mm(fit.rms) + " together, at most " + Mm(worst_alone) +
                     " each alone): profiles of different strips, or a bad extraction?");
  }
}

std::string PinnedBoundMessage(const std::array<double, 3>& law_p,
                               const std::array<double, 2>& lower,
                               const std::array<double, 2>& upper) {
  // A law pinned to a stiffness bound is not a fit: the data do not bend (or bend without
  // limit) within the textile range.
  for (int k = 0; k < 2; ++k) {
    if (law_p[k] - lower[k] < 1e-6 || upper[k] - law_p[k] < 1e-6) {
      std::ostringstream m;
      m.precision(3);
      m << "the fit ran into the bound b" << k + 1 << " = "
        << units::SiStiffnessToKes(std::exp(law_p[k]))
        << " gf·cm: the profiles do not determine a textile law (almost no bending, or not a "
           "cantilever shape)";
      return m.str();
    }
  }
  return "";
}

void CovarianceFromJacobian(const Eigen::MatrixXd& free_jacobian, double sigma2,
                            const BendingLaw& law, double log_kappa0, DirectFitSummary* fit) {
  // Pseudo-inverse, so that an undetermined direction (b1 = b2 makes κ0 free; κ0 beyond the
  // data makes b2 free) shows up as an infinite variance, not a crash.
  const Eigen::Index n = free_jacobian.cols();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(free_jacobian, Eigen::ComputeThinV);
  const auto& sv = svd.singularValues();
  const double cutoff = 1e-8 * sv(0);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd null_weight = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < sv.size(); ++k) {
    const Eigen::VectorXd v = svd.matrixV().col(k);
    if (sv(k) > cutoff)
      cov += v * v.transpose() / (sv(k) * sv(k));
    else
      null_weight += v.cwiseAbs2();
  }
  cov *= sigma2;
  const Eigen::Matrix3d cov_p = cov.topLeftCorner<3, 3>();
  const double b1 = law.b1(), b2 = law.b2(), k0 = std::exp(log_kappa0), c1 = law.c1();
  Eigen::Matrix3d D;  // ∂(b1, b2, c1)/∂(ln b1, ln b2, ln κ0)
  D << b1, 0, 0, 0, b2, 0, -b1 / (2 * k0), b2 / (2 * k0), -c1;
  fit->covariance = D * cov_p * D.transpose();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fit->b1_sd = null_weight(0) > 0.5 ? nan : std::sqrt(fit->covariance(0, 0));
  fit->b2_sd = null_weight(1) > 0.5 ? nan : std::sqrt(fit->covariance(1, 1));
  fit->c1_sd = null_weight(2) > 0.5 && c1 != 0.0 ? nan : std::sqrt(fit->covariance(2, 2));
}

void ObserveConstants(BendingLaw* law_io, DirectFitSummary* fit) {
  BendingLaw& law = *law_io;
  DirectFitSummary& out = *fit;
  const double k0 = law.kappa0();
  const auto undetermined = [](double sd, double v) {
    return !std::isfinite(sd) || sd > kUndeterminedRelSd * std::abs(v);
  };
  out.b2_observed = k0 < out.kappa_max && !undetermined(out.b2_sd, law.b2());
  out.b1_observed = k0 > 0.02 * out.kappa_max && !undetermined(out.b1_sd, law.b1());
  out.c1_observed = out.b1_observed && !undetermined(out.c1_sd, law.c1());
  std::ostringstream obs;
  obs.precision(4);
  const double kmax_cm = units::SiCurvatureToKes(out.kappa_max);
  if (k0 >= out.kappa_max) {
    // The linear branch is never reached: report the quadratic up to the data's reach and its
    // last slope beyond, not an invented b2.
    const double b2_at_max = law.b1() + 2.0 * law.c1() * out.kappa_max;
    if (b2_at_max > 0.0) {
      const double raw_b2 = law.b2();
      law = BendingLaw::FromSi(law.b1(), b2_at_max, law.c1());
      obs << "b2 is not observed: kappa0 (" << units::SiCurvatureToKes(k0)
          << " /cm) lies beyond the largest curvature in the data (" << kmax_cm
          << " /cm); b2 is set to the slope there, " << law.b2_kes() << " gf·cm (the optimiser's "
          << units::SiStiffnessToKes(raw_b2) << " is arbitrary). ";
    }
    out.b2_observed = false;
    out.b2_sd = std::numeric_limits<double>::quiet_NaN();
  }
  const auto pct = [](double sd, double v) {
    std::ostringstream t;
    t.precision(2);
    if (std::isfinite(sd))
      t << "±" << 100.0 * sd / std::abs(v) << " %";
    else
      t << "undetermined";
    return t.str();
  };
  if (!out.b1_observed) obs << "b1 is poorly determined (" << pct(out.b1_sd, law.b1()) << "). ";
  // (b2 beyond the data's curvatures was said above; here the data reach κ0 but do not pin b2.)
  if (!out.b2_observed && k0 < out.kappa_max)
    obs << "b2 is poorly determined (" << pct(out.b2_sd, law.b2()) << "). ";
  if (!out.c1_observed) {
    obs << "c1 is poorly determined (" << pct(out.c1_sd, law.c1())
        << "): these curvatures do not resolve the quadratic branch, the data are also "
           "consistent with a law closer to linear. ";
  }
  if (out.b1_observed && out.b2_observed && out.c1_observed) {
    obs << "All three constants are determined by the data (curvatures up to " << kmax_cm
        << " /cm). ";
  }
  obs << "The moment curve M(κ) is determined for 0 ≤ κ ≤ " << kmax_cm << " /cm.";
  out.observability = obs.str();
}

}  // namespace internal

namespace {

// What one solve of the direct fit (FitDirectFrom) works on, stage by stage.
struct DirectFitState {
  DirectFitState(const std::vector<Profile>& profiles, double areal_density,
                 const DirectFitOptions& options, const LawStart& start)
      : profiles(profiles),
        areal_density(areal_density),
        options(options),
        start(start),
        t0(std::chrono::steady_clock::now()),
        law_p(start.p),
        problem(OwningProblemOptions()) {}

  static ceres::Problem::Options OwningProblemOptions() {
    ceres::Problem::Options o;
    o.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    o.loss_function_ownership = ceres::TAKE_OWNERSHIP;
    return o;
  }

  const std::vector<Profile>& profiles;
  double areal_density;  // [kg/m²]
  const DirectFitOptions& options;
  const LawStart& start;
  std::chrono::steady_clock::time_point t0;
  // The unknowns: the law p = (ln b1, ln b2, ln κ0), each profile's overhang [m], the rig
  // (offset [m], rotation [rad]).
  std::array<double, 3> law_p;
  std::vector<double> lengths;
  std::array<double, 2> rig{};
  ceres::Problem problem;
  std::vector<std::unique_ptr<ProfileModel>> models;  // one per profile, residuals in mm
  LawPrior* prior = nullptr;                          // owned by problem
  ceres::Solver::Options solver_options;
  ceres::Solver::Summary solver_summary;
  std::optional<BendingLaw> law;  // at the solution
  double sum2 = 0.0;              // Σ of the points' squared normal distances [m²]
  int count = 0;                  // points over all profiles
  double scatter = 0.0;           // the points' pooled scatter [m]
  DirectFitSummary out;
};

// The summary as it stands, with the time spent.
DirectFitSummary Finish(DirectFitState& s) {
  s.out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.t0).count();
  return s.out;
}

// Models of the profiles and their residuals: each point's normal distance under the robust
// loss and the tip's position; each overhang within [0.2, 2] of its noise-free length.
void BuildProblem(DirectFitState& s) {
  const DirectFitOptions& options = s.options;
  for (const Profile& p : s.profiles) s.lengths.push_back(NoiseFreeLength(p));
  s.rig = {options.fit_offset ? 0.0 : options.offset, 0.0};
  for (size_t i = 0; i < s.profiles.size(); ++i) {
    const int samples =
        std::max(options.curve_samples,
                 std::min(2001, static_cast<int>(std::ceil(s.lengths[i] / kMaxSampleSpacing)) + 1));
    s.models.push_back(std::make_unique<ProfileModel>(s.profiles[i], s.areal_density, samples,
                                                      options.elastica_tol));
    ProfileModel* m = s.models.back().get();
    for (int j = 0; j < m->num_points(); ++j) {
      ceres::LossFunction* loss =
          options.robust_scale > 0.0 ? new ceres::CauchyLoss(options.robust_scale * 1e3) : nullptr;
      s.problem.AddResidualBlock(new internal::PointResidual(m, j), loss, s.law_p.data(),
                                 &s.lengths[i], s.rig.data());
    }
    s.problem.AddResidualBlock(new internal::TipResidual(m), nullptr, s.law_p.data(), &s.lengths[i],
                               s.rig.data());
    s.problem.SetParameterLowerBound(&s.lengths[i], 0, 0.2 * s.lengths[i]);
    s.problem.SetParameterUpperBound(&s.lengths[i], 0, 2.0 * s.lengths[i]);
  }
}

// Bounds: b1, b2 within a factor 100 of the start and inside the textile range that material
// files accept (1e-5 .. 1e5 gf·cm), κ0 within a factor 1000 of the curvature scale. Without
// them, data that no law explains (mixed strips) drive b2 towards 0, a plastic hinge. False,
// with the message, when the start lies outside any textile.
bool BoundLaw(DirectFitState& s) {
  const std::optional<std::array<double, 2>> bounds =
      internal::LogStiffnessBounds(s.start.b_centre);
  if (!bounds) {
    std::ostringstream m;
    m.precision(3);
    m << "the profiles' shape asks for a bending stiffness of about "
      << units::SiStiffnessToKes(s.start.b_centre)
      << " gf·cm, outside any textile (1e-5 .. 1e5 gf·cm): is --gsm right, is y up?";
    s.out.message = m.str();
    return false;
  }
  const auto [lo_b, hi_b] = *bounds;
  for (int k = 0; k < 2; ++k) {
    s.law_p[k] = std::clamp(s.law_p[k], lo_b, hi_b);
    s.problem.SetParameterLowerBound(s.law_p.data(), k, lo_b);
    s.problem.SetParameterUpperBound(s.law_p.data(), k, hi_b);
  }
  s.problem.SetParameterLowerBound(s.law_p.data(), 2, s.law_p[2] - std::log(1000.0));
  s.problem.SetParameterUpperBound(s.law_p.data(), 2, s.law_p[2] + std::log(1000.0));
  return true;
}

// A weak prior towards a linear law with κ0 at the data's curvature scale: it settles the
// directions the data leave free (b1 = b2 makes κ0 free; κ0 beyond the data makes b2 free)
// and is negligible elsewhere (1e-2 mm per unit of ln, against hundreds of points whose
// residuals move millimetres per unit of ln). The rig's fixed parts are held constant.
void AddPriorAndRig(DirectFitState& s) {
  s.prior = new LawPrior(kPriorWeight, s.law_p[2]);
  s.problem.AddResidualBlock(s.prior, nullptr, s.law_p.data());
  const DirectFitOptions& options = s.options;
  if (!options.fit_offset && !options.fit_rotation) {
    s.problem.SetParameterBlockConstant(s.rig.data());
  } else if (!options.fit_offset || !options.fit_rotation) {
    s.problem.SetManifold(s.rig.data(), new ceres::SubsetManifold(2, {options.fit_offset ? 1 : 0}));
  }
}

void Solve(DirectFitState& s) {
  const DirectFitOptions& options = s.options;
  ceres::Solver::Options& solver_options = s.solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.max_solver_time_in_seconds = options.max_seconds;
  // The model's own numerical floor (elastica tolerance, foot-point projection) makes the cost
  // repeatable to ~1e-8 relative; asking for less only buys rejected steps.
  solver_options.function_tolerance = 1e-7;
  solver_options.parameter_tolerance = 1e-10;
  solver_options.gradient_tolerance = 1e-14;
  const bool debug = std::getenv("TEXTILE_DEBUG_FIT") != nullptr;
  solver_options.logging_type = debug ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = debug;
  ceres::Solve(solver_options, &s.problem, &s.solver_summary);
}

bool Settled(const ceres::Solver::Summary& summary) {
  return summary.IsSolutionUsable() && summary.termination_type != ceres::NO_CONVERGENCE;
}

// Data more or less precise than the prior's σ = 0.1 mm: again, with the prior scaled to
// their rms (from the first solve's result, a few iterations).
void SolveWithRescaledPrior(DirectFitState& s) {
  if (!Settled(s.solver_summary)) return;
  double sum2 = 0.0;
  int n = 0;
  bool ok = true;
  for (size_t i = 0; i < s.models.size() && ok; ++i) {
    ok = s.models[i]->Update(s.law_p.data(), &s.lengths[i], s.rig.data(), false);
    for (int j = 0; ok && j < s.models[i]->num_points(); ++j, ++n)
      sum2 += s.models[i]->residual(j) * s.models[i]->residual(j);  // [mm²]
  }
  const std::optional<double> w =
      internal::RescaledPriorWeight(std::sqrt(sum2 / std::max(1, n)), s.prior->weight());
  if (!ok || !w) return;
  s.prior->set_weight(*w);
  const DirectFitOptions& options = s.options;
  const int first_iterations = static_cast<int>(s.solver_summary.iterations.size());
  const double first_seconds = s.solver_summary.total_time_in_seconds;
  s.solver_options.max_num_iterations = std::max(1, options.max_iterations - first_iterations);
  s.solver_options.max_solver_time_in_seconds = std::max(1e-3, options.max_seconds - first_seconds);
  const auto first_law = s.law_p;
  const auto first_lengths = s.lengths;
  const auto first_rig = s.rig;
  ceres::Solver::Summary second;
  ceres::Solve(s.solver_options, &s.problem, &second);
  if (Settled(second)) {
    second.iterations.insert(second.iterations.begin(), s.solver_summary.iterations.begin(),
                             s.solver_summary.iterations.end());
    s.solver_summary = second;
  } else {
    // A refinement that does not settle (profiles no law fits, which the check below
    // names) keeps the first solve's result.
    s.law_p = first_law, s.lengths = first_lengths, s.rig = first_rig;
    s.prior->set_weight(kPriorWeight);
  }
}

// The solver's verdict, and the models at the solution with their jacobians (for reports and
// the covariance). False, with the message, when it did not converge.
bool ReachSolution(DirectFitState& s) {
  s.out.iterations = static_cast<int>(s.solver_summary.iterations.size());
  if (!Settled(s.solver_summary)) {
    s.out.message = "the fit did not converge (" + s.solver_summary.message + ")" +
                    LastIterateSummary(s.models, s.law_p, s.lengths, s.rig);
    return false;
  }
  for (size_t i = 0; i < s.models.size(); ++i) {
    if (!s.models[i]->Update(s.law_p.data(), &s.lengths[i], s.rig.data(), true)) {
      s.out.message = "the elastica failed at the fitted constants";
      return false;
    }
  }
  s.law = internal::LawFromParameters(s.law_p.data());
  return true;
}

// Residual statistics per profile (normal distances only), the largest curvature, the rig.
void MeasureProfiles(DirectFitState& s) {
  DirectFitSummary& out = s.out;
  for (size_t i = 0; i < s.models.size(); ++i) {
    const ProfileModel& m = *s.models[i];
    ProfileFitReport r;
    r.source = s.profiles[i].source;
    r.overhang = s.lengths[i];
    r.data_length = s.profiles[i].s.back();
    double s2 = 0.0;
    for (int j = 0; j < m.num_points(); ++j) {
      const double d = m.residual(j) * 1e-3;
      s2 += d * d;
      r.max = std::max(r.max, std::abs(d));
    }
    s.sum2 += s2;
    s.count += m.num_points();
    r.rms = std::sqrt(s2 / m.num_points());
    r.clamp_curvature = m.solution().clamp_curvature;
    out.kappa_max = std::max(out.kappa_max, r.clamp_curvature);
    out.profiles.push_back(r);
  }
  out.rms = std::sqrt(s.sum2 / s.count);
  double scatter2 = 0.0;
  for (const Profile& p : s.profiles) scatter2 += std::pow(ProfilePointScatter(p), 2);
  s.scatter = std::sqrt(scatter2 / s.profiles.size());
  out.cost = s.solver_summary.final_cost;
  out.offset = s.rig[0];
  out.rotation = s.rig[1];
}

// False, with the message, when b1 or b2 ended on a bound.
bool CheckNotPinned(DirectFitState& s) {
  std::array<double, 2> lower{}, upper{};
  for (int k = 0; k < 2; ++k) {
    lower[k] = s.problem.GetParameterLowerBound(s.law_p.data(), k);
    upper[k] = s.problem.GetParameterUpperBound(s.law_p.data(), k);
  }
  s.out.message = internal::PinnedBoundMessage(s.law_p, lower, upper);
  return s.out.message.empty();
}

// Covariance: (JᵀJ)⁺ σ̂² over all free parameters, from the unrobustified Jacobian, with
// σ̂² = Σr² / (N - n). Columns of J: ln b1, ln b2, ln κ0, offset, rotation, the overhangs.
void EstimateCovariance(DirectFitState& s) {
  const DirectFitOptions& options = s.options;
  const int n_res = s.count + 2 * static_cast<int>(s.models.size());
  const int n_par = 3 + 2 + static_cast<int>(s.lengths.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n_res, n_par);
  int row = 0;
  std::vector<int> free_cols = {0, 1, 2};
  if (options.fit_offset) free_cols.push_back(3);
  if (options.fit_rotation) free_cols.push_back(4);
  for (size_t i = 0; i < s.models.size(); ++i) {
    free_cols.push_back(5 + static_cast<int>(i));
    const auto put = [&](const std::array<double, 6>& g) {
      for (int k = 0; k < 3; ++k) J(row, k) = g[k];
      J(row, 3) = g[4];
      J(row, 4) = g[5];
      J(row, 5 + static_cast<int>(i)) = g[3];
      ++row;
    };
    for (int j = 0; j < s.models[i]->num_points(); ++j) put(s.models[i]->gradient(j));
    put(s.models[i]->tip_gradient()[0]);
    put(s.models[i]->tip_gradient()[1]);
  }
  Eigen::MatrixXd Jf(n_res, free_cols.size());
  for (size_t k = 0; k < free_cols.size(); ++k) Jf.col(k) = J.col(free_cols[k]);
  const int dof = std::max(1, n_res - static_cast<int>(free_cols.size()));
  s.out.num_residuals = n_res;
  s.out.num_free_parameters = static_cast<int>(free_cols.size());
  const double sigma2 = s.sum2 * 1e6 / dof;  // [mm²]: residuals are in mm
  internal::CovarianceFromJacobian(Jf, sigma2, *s.law, s.law_p[2], &s.out);
}

DirectFitSummary FitDirectFrom(const std::vector<Profile>& profiles, double areal_density,
                               const DirectFitOptions& options, const LawStart& start) {
  DirectFitState s(profiles, areal_density, options, start);
  BuildProblem(s);
  if (!BoundLaw(s)) return s.out;  // no time taken: nothing was solved
  AddPriorAndRig(s);
  Solve(s);
  SolveWithRescaledPrior(s);
  if (!ReachSolution(s)) return Finish(s);
  MeasureProfiles(s);
  internal::RefuseMixedStrips(profiles, s.out, options.outlier_profile_rms, [&](const Profile& p) {
    const DirectFitSummary single = FitDirect({p}, areal_density, options);
    return single.converged ? single.rms : std::numeric_limits<double>::infinity();
  });
  if (!CheckNotPinned(s)) return Finish(s);
  EstimateCovariance(s);
  // Observability (docs/spec/cantilever.md): which constants the data determine.
  internal::ObserveConstants(&*s.law, &s.out);
  DirectFitSummary& out = s.out;
  out.law = s.law;
  out.converged = true;
  out.message = "converged (" + s.solver_summary.message + ")";
  out.start = start.name;
  out.point_scatter = s.scatter;
  if (LacksFit(out)) out.fit_pattern = DescribeMisfit(profiles, s.models, out);
  return Finish(s);
}

}  // namespace
}  // namespace textile

namespace textile {
namespace {

// The fitted offset below which a note says the profiles' origin is off [m]: noise and the
// trace line (upper or lower edge) move it by tenths of a millimetre.
constexpr double kOffsetNoteM = 0.0005;
// Above it the offset is more than half the thickest strip a profile may show [m].
constexpr double kOffsetMaxM = 0.003;

// Smallest tilt the fit adopts [rad]. Below it the rotation fitted to photos is the extraction's
// correlated residuals, not a tilt (the shipped photos: −0.04°, which would move c1 by 30 %).
constexpr double kMinTiltRad = 0.1 * std::numbers::pi / 180.0;
// The longest profile at least this many times the shortest for the tilt to be looked for.
constexpr double kMinLengthRatioForTilt = 1.2;

// Whether a fit with a rig rotation explains the data so much better than the fit without one
// that the tilt is real: a likelihood-ratio test on the objective both minimise (the robust
// loss, so that stray points neither hide a tilt nor fake one), 2 (F₀ − F₁) / σ̂₁² above 9
// (three standard deviations of noise's χ²₁), σ̂₁² = 2 F₁ / (residuals − free parameters), and a
// tilt of at least kMinTiltRad. A fit without rotation that failed (a tilt of a degree can drive
// b1 into its bound) counts as infinitely worse.
bool TiltIsSignificant(const DirectFitSummary& level, const DirectFitSummary& tilted) {
  if (!tilted.converged || std::abs(tilted.rotation) < kMinTiltRad) return false;
  if (!level.converged) return true;
  const double dof = std::max(1, tilted.num_residuals - tilted.num_free_parameters);
  const double sigma2 = 2.0 * tilted.cost / dof;
  return 2.0 * (level.cost - tilted.cost) > 9.0 * sigma2;
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

DirectFitSummary FitDirectCheckingTilt(const std::vector<Profile>& profiles, double areal_density,
                                       const DirectFitOptions& options,
                                       std::vector<std::string>* notes, DirectFitOptions* used) {
  std::vector<std::string> said;
  DirectFitOptions o = options;
  DirectFitSummary fit = FitDirect(profiles, areal_density, o);
  const auto deg = [](double rad) { return Fixed(rad * 180.0 / std::numbers::pi, 2); };
  // Only overhangs of different lengths tell a tilt from the law: on one profile (or several of
  // one length) the rotation trades against b1 and c1, and the shipped 40 mm photo alone "found"
  // −0.73° with b1 = 3.2 gf·cm, c1 = −2000 gf·cm² (the truth 0.1 and −0.0092).
  double shortest = std::numeric_limits<double>::infinity(), longest = 0.0;
  for (const Profile& p : profiles) {
    shortest = std::min(shortest, NoiseFreeLength(p));
    longest = std::max(longest, NoiseFreeLength(p));
  }
  if (!o.fit_rotation && longest >= kMinLengthRatioForTilt * shortest) {
    // A rig that is not level (or a camera rolled against it) tilts every profile alike; half a
    // degree already sent b1 2.5× off and one degree c1 to -800 gf·cm², with rms hardly worse.
    DirectFitOptions turned = o;
    turned.fit_rotation = true;
    DirectFitSummary tilted;
    try {
      tilted = FitDirect(profiles, areal_density, turned);
    } catch (const InputError&) {
      // Only the fit without rotation speaks for the input (profiles of different strips).
    }
    if (TiltIsSignificant(fit, tilted)) {
      said.push_back("the profiles are tilted by " + deg(tilted.rotation) +
                     "° (a rig not level or a camera rolled against it): fitted with that "
                     "rotation, rms " +
                     Fixed(tilted.rms * 1e3, 3) + " mm instead of " +
                     (fit.converged ? Fixed(fit.rms * 1e3, 3) + " mm" : "no fit") + " without it");
      fit = tilted;
      o = turned;
    } else if (fit.converged && tilted.converged && std::abs(tilted.rotation) >= kMinTiltRad) {
      // A tilt the data do not show clearly can still move the law by more than its sds (a
      // 0.2-0.3° tilt: b1 8-80 % high): say what it would change, b1 or b2, whichever moves
      // more in the tilted fit's sds.
      double z = 0.0, level_b = 0.0, tilted_b = 0.0;
      const char* name = "";
      const std::array<std::tuple<double, double, double, const char*>, 2> pairs = {
          std::tuple{fit.law->b1(), tilted.law->b1(), tilted.b1_sd, "b1"},
          std::tuple{fit.law->b2(), tilted.law->b2(), tilted.b2_sd, "b2"}};
      for (const auto& [a, b, sd, n] : pairs) {
        if (!(sd > 0.0) || !std::isfinite(sd) || std::abs(a - b) / sd <= z) continue;
        z = std::abs(a - b) / sd, level_b = a, tilted_b = b, name = n;
      }
      if (z > 2.0) {
        said.push_back("a tilt of " + deg(tilted.rotation) +
                       "°, which the data do not show clearly, would change " + name + " by " +
                       Fixed(100.0 * (tilted_b - level_b) / level_b, 2) + " % (" + Fixed(z, 2) +
                       " sd): if the rig is not known to be level within 0.1°, fit with "
                       "--fit-rotation");
      }
    }
  }
  // The mid-line's height at the edge is half the strip's thickness (at most 3 mm: profiles
  // rising higher are refused); a fitted offset outside that means the profiles' origin is not
  // the platform's edge. A shift in y alone is what the offset absorbs (the law unchanged); one
  // in x changes the law (2 mm: b2 2.3× low), which no offset can tell apart.
  if (fit.converged && o.fit_offset && (fit.offset < -kOffsetNoteM || fit.offset > kOffsetMaxM)) {
    said.push_back("the fitted offset at the edge, " + Fixed(fit.offset * 1e3, 3) +
                   " mm, is not half a strip's thickness (0 to 3 mm): the profiles' y = 0 is "
                   "not the platform's top, or x = 0 is not its edge (a shift in y alone leaves "
                   "the law as it is, one in x does not): check the platform edge");
  }
  if (fit.converged && !fit.fit_pattern.empty()) said.push_back(fit.fit_pattern);
  if (notes) notes->insert(notes->end(), said.begin(), said.end());
  if (used) *used = o;
  return fit;
}

}  // namespace textile
