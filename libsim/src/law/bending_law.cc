#include "textile/sim/law/bending_law.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Newton steps below this, relative to κ, end the spline's inversion (the error after the
// step is O(step²); the moment's rounding alone moves κ by ~eps M/(B κ), a few 1e-15 on a
// flat piece).
constexpr double kInverseRelTol = 1e-14;

const std::vector<double> kNoKnots;

std::string Number(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Steffen's slopes (M. Steffen, "A simple method for monotonic interpolation in one dimension",
// Astron. Astrophys. 239, 443-450, 1990, eqs. 11 and 26-27) for strictly increasing knots.
// Why Steffen rather than Fritsch-Carlson: it is local and one pass (no fix-up sweep), every
// slope is at most twice either adjacent secant, so on each piece (d_i/s, d_i+1/s) lies in
// (0, 2]², strictly inside the region where the cubic Hermite is monotone (it meets the
// region's edge only at slopes 0 or 3 s): B = dM/dκ > 0 everywhere, not just ≥ 0. And where
// the limiter is idle the slope is that of the parabola through three knots, so a law that is
// quadratic or linear over three knots (a sampled Pabst law away from κ0) is reproduced
// exactly. Ends: the one-sided parabola (eq. 26), kept in [s/2, 2 s] of the end secant s
// (Steffen lets it fall to 0; B(0) and the slope beyond the last knot must stay > 0).
std::vector<double> SteffenSlopes(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  std::vector<double> h(n - 1), s(n - 1), d(n);
  for (size_t i = 0; i + 1 < n; ++i) {
    h[i] = x[i + 1] - x[i];
    s[i] = (y[i + 1] - y[i]) / h[i];
  }
  for (size_t i = 1; i + 1 < n; ++i) {
    const double p = (s[i - 1] * h[i] + s[i] * h[i - 1]) / (h[i - 1] + h[i]);
    d[i] = std::min({2.0 * s[i - 1], 2.0 * s[i], p});
  }
  const auto end = [](double s_end, double s_next, double h_end, double h_next) {
    const double p = s_end + (s_end - s_next) * h_end / (h_end + h_next);
    return std::clamp(p, 0.5 * s_end, 2.0 * s_end);
  };
  d[0] = end(s[0], s[1], h[0], h[1]);
  d[n - 1] = end(s[n - 2], s[n - 3], h[n - 2], h[n - 3]);
  return d;
}

}  // namespace

// The knots and, per piece i (κ_i ≤ κ ≤ κ_i+1, u = κ - κ_i), the cubic
// M = M_i + u (d_i + u (c2_i + u c3_i)) with Ψ at its start.
struct BendingLaw::Spline {
  std::vector<double> kappa, moment, slope, moment_sd, energy;  // per knot (energy: Ψ(κ_i))
  std::vector<double> c2, c3;                                   // per piece

  // The piece holding k ≥ 0 (the last one for k at or past the last knot is not asked for).
  size_t Piece(double k) const {
    const auto it = std::upper_bound(kappa.begin(), kappa.end(), k);
    return static_cast<size_t>(it - kappa.begin()) - 1;
  }
};

std::string BendingLaw::SplineInvalidity(std::span<const double> kappa,
                                         std::span<const double> moment,
                                         std::span<const double> moment_sd,
                                         std::string_view kappa_name, std::string_view moment_name,
                                         std::string_view moment_sd_name) {
  const std::string kn(kappa_name), mn(moment_name), sn(moment_sd_name);
  const auto at = [](const std::string& name, size_t i) {
    return name + "[" + std::to_string(i) + "]";
  };
  if (kappa.size() < 3) {
    return kn + ": " + std::to_string(kappa.size()) +
           " knots, a spline law needs at least 3 (κ = 0 and two more)";
  }
  if (moment.size() != kappa.size()) {
    return mn + ": " + std::to_string(moment.size()) + " values for " +
           std::to_string(kappa.size()) + " knots in " + kn + " (one moment per curvature)";
  }
  if (!moment_sd.empty() && moment_sd.size() != kappa.size()) {
    return sn + ": " + std::to_string(moment_sd.size()) + " values for " +
           std::to_string(kappa.size()) + " knots in " + kn;
  }
  for (const auto& [values, name] :
       {std::pair{kappa, kn}, std::pair{moment, mn}, std::pair{moment_sd, sn}}) {
    for (size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i]))
        return at(name, i) + ": must be a finite number, got " + Number(values[i]);
    }
  }
  if (kappa[0] != 0.0)
    return at(kn, 0) + ": must be 0, got " + Number(kappa[0]) + " (the law starts at κ = 0, M = 0)";
  if (moment[0] != 0.0)
    return at(mn, 0) + ": must be 0, got " + Number(moment[0]) +
           " (the law starts at κ = 0, M = 0)";
  for (size_t i = 1; i < kappa.size(); ++i) {
    if (!(kappa[i] > kappa[i - 1])) {
      return at(kn, i) + ": " + Number(kappa[i]) + " is not above " + at(kn, i - 1) + " = " +
             Number(kappa[i - 1]) + " (the curvatures must be strictly increasing)";
    }
    if (!(moment[i] > moment[i - 1])) {
      return at(mn, i) + ": " + Number(moment[i]) + " is not above " + at(mn, i - 1) + " = " +
             Number(moment[i - 1]) +
             " (the moments must be strictly increasing: a law has B = dM/dκ > 0)";
    }
  }
  for (size_t i = 0; i < moment_sd.size(); ++i) {
    if (moment_sd[i] < 0.0) return at(sn, i) + ": must be >= 0, got " + Number(moment_sd[i]);
  }
  return "";
}

BendingLaw BendingLaw::FromSpline(std::vector<double> kappa, std::vector<double> moment,
                                  std::vector<double> moment_sd) {
  if (std::string why = SplineInvalidity(kappa, moment, moment_sd); !why.empty()) {
    throw InputError("spline bending law: " + why);
  }
  auto spline = std::make_shared<Spline>();
  spline->slope = SteffenSlopes(kappa, moment);
  const size_t pieces = kappa.size() - 1;
  spline->c2.resize(pieces);
  spline->c3.resize(pieces);
  spline->energy.resize(pieces + 1);
  spline->energy[0] = 0.0;
  for (size_t i = 0; i < pieces; ++i) {
    const double h = kappa[i + 1] - kappa[i], s = (moment[i + 1] - moment[i]) / h;
    const double d0 = spline->slope[i], d1 = spline->slope[i + 1];
    const double c2 = (3.0 * s - 2.0 * d0 - d1) / h, c3 = (d0 + d1 - 2.0 * s) / (h * h);
    spline->c2[i] = c2;
    spline->c3[i] = c3;
    spline->energy[i + 1] =
        spline->energy[i] + h * (moment[i] + h * (0.5 * d0 + h * (c2 / 3.0 + h * c3 / 4.0)));
  }
  spline->kappa = std::move(kappa);
  spline->moment = std::move(moment);
  spline->moment_sd = std::move(moment_sd);
  return BendingLaw(std::move(spline));
}

BendingLaw BendingLaw::FromSplineKes(std::vector<double> kappa_per_cm,
                                     std::vector<double> moment_gfcm_per_cm,
                                     std::vector<double> moment_sd_gfcm_per_cm) {
  if (std::string why =
          SplineInvalidity(kappa_per_cm, moment_gfcm_per_cm, moment_sd_gfcm_per_cm, "kappa_per_cm",
                           "moment_gfcm_per_cm", "moment_sd_gfcm_per_cm");
      !why.empty()) {
    throw InputError("spline bending law: " + why);
  }
  for (double& k : kappa_per_cm) k = units::KesCurvatureToSi(k);
  for (double& m : moment_gfcm_per_cm) m = units::KesMomentToSi(m);
  for (double& m : moment_sd_gfcm_per_cm) m = units::KesMomentToSi(m);
  return FromSpline(std::move(kappa_per_cm), std::move(moment_gfcm_per_cm),
                    std::move(moment_sd_gfcm_per_cm));
}

BendingLaw::BendingLaw(std::shared_ptr<const Spline> spline) : spline_(std::move(spline)) {
  const Spline& sp = *spline_;
  b1_ = sp.slope.front();
  b2_ = sp.slope.back();
  c1_ = kNaN;
  kappa0_ = sp.kappa.back();
  moment_at_kappa0_ = sp.moment.back();
  moment0_ = moment_at_kappa0_ - b2_ * kappa0_;
  energy_at_kappa0_ = sp.energy.back();
}

const std::vector<double>& BendingLaw::knot_kappa() const {
  return spline_ ? spline_->kappa : kNoKnots;
}
const std::vector<double>& BendingLaw::knot_moment() const {
  return spline_ ? spline_->moment : kNoKnots;
}
const std::vector<double>& BendingLaw::knot_stiffness() const {
  return spline_ ? spline_->slope : kNoKnots;
}
const std::vector<double>& BendingLaw::knot_moment_sd() const {
  return spline_ ? spline_->moment_sd : kNoKnots;
}

std::vector<double> BendingLaw::Breakpoints() const {
  if (spline_) return std::vector<double>(spline_->kappa.begin() + 1, spline_->kappa.end());
  if (kappa0_ > 0.0 && std::isfinite(kappa0_)) return {kappa0_};
  return {};
}

double BendingLaw::MinStiffness() const {
  if (!spline_) return std::min(b1_, b2_);
  // B = d + 2 c2 u + 3 c3 u² on each piece: its ends (the knot slopes), or its vertex inside.
  const Spline& sp = *spline_;
  double lowest = *std::min_element(sp.slope.begin(), sp.slope.end());
  for (size_t i = 0; i < sp.c2.size(); ++i) {
    const double h = sp.kappa[i + 1] - sp.kappa[i], c2 = sp.c2[i], c3 = sp.c3[i];
    if (!(c3 > 0.0)) continue;
    const double u = -c2 / (3.0 * c3);
    if (u > 0.0 && u < h) lowest = std::min(lowest, sp.slope[i] + u * (2.0 * c2 + 3.0 * c3 * u));
  }
  return lowest;
}

double BendingLaw::SplineMoment(double k) const {
  const Spline& sp = *spline_;
  if (k >= kappa0_) return moment_at_kappa0_ + b2_ * (k - kappa0_);
  const size_t i = sp.Piece(k);
  const double u = k - sp.kappa[i];
  return sp.moment[i] + u * (sp.slope[i] + u * (sp.c2[i] + u * sp.c3[i]));
}

double BendingLaw::SplineStiffness(double k) const {
  const Spline& sp = *spline_;
  if (k >= kappa0_) return b2_;
  const size_t i = sp.Piece(k);
  const double u = k - sp.kappa[i];
  return sp.slope[i] + u * (2.0 * sp.c2[i] + 3.0 * sp.c3[i] * u);
}

double BendingLaw::SplineStiffnessDerivative(double k) const {
  const Spline& sp = *spline_;
  if (k >= kappa0_) return 0.0;
  const size_t i = sp.Piece(k);
  return 2.0 * sp.c2[i] + 6.0 * sp.c3[i] * (k - sp.kappa[i]);
}

double BendingLaw::SplineEnergy(double k) const {
  const Spline& sp = *spline_;
  if (k >= kappa0_) {
    const double u = k - kappa0_;
    return energy_at_kappa0_ + u * (moment_at_kappa0_ + 0.5 * b2_ * u);
  }
  const size_t i = sp.Piece(k);
  const double u = k - sp.kappa[i];
  return sp.energy[i] +
         u * (sp.moment[i] + u * (0.5 * sp.slope[i] + u * (sp.c2[i] / 3.0 + u * sp.c3[i] / 4.0)));
}

double BendingLaw::SplineCurvature(double m) const {
  const Spline& sp = *spline_;
  if (m >= moment_at_kappa0_) return kappa0_ + (m - moment_at_kappa0_) / b2_;
  const auto it = std::upper_bound(sp.moment.begin(), sp.moment.end(), m);
  const size_t i = static_cast<size_t>(it - sp.moment.begin()) - 1;
  const double k_i = sp.kappa[i], h = sp.kappa[i + 1] - k_i, target = m - sp.moment[i];
  const double d = sp.slope[i], c2 = sp.c2[i], c3 = sp.c3[i];
  // The cubic is increasing on [0, h] (Steffen's slopes): Newton from the chord's guess, kept
  // inside the bracket by bisection.
  double lo = 0.0, hi = h;
  double u = h * target / (sp.moment[i + 1] - sp.moment[i]);
  for (int it = 0; it < 100; ++it) {
    const double f = u * (d + u * (c2 + u * c3)) - target;
    if (f == 0.0) break;
    (f > 0.0 ? hi : lo) = u;
    const double step = f / (d + u * (2.0 * c2 + 3.0 * c3 * u));
    // A step this small is the last (the error after it is O(step²)); tested before the
    // bracket, which a step of an ulp or less may not leave room for.
    if (std::abs(step) <= kInverseRelTol * (k_i + u)) {
      u = std::clamp(u - step, lo, hi);
      break;
    }
    u -= step;
    if (!(u > lo && u < hi)) u = 0.5 * (lo + hi);
    if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * (k_i + hi)) break;
  }
  return k_i + u;
}

std::string BendingLaw::Invalidity(double b1, double b2, double c1) {
  std::ostringstream why;
  why.precision(6);
  const auto constants = [&] {
    std::ostringstream s;
    s.precision(6);
    s << "{b1 = " << units::SiStiffnessToKes(b1) << " gf·cm, b2 = " << units::SiStiffnessToKes(b2)
      << " gf·cm, c1 = " << units::SiQuadraticToKes(c1) << " gf·cm²}";
    return s.str();
  };
  if (!std::isfinite(b1) || !std::isfinite(b2) || !std::isfinite(c1)) {
    return "bending law constants must be finite numbers";
  }
  if (b1 <= 0.0) why << "b1 must be > 0 in " << constants();
  else if (b2 <= 0.0) why << "b2 must be > 0 in " << constants();
  else if (c1 != 0.0 && b1 != b2 && (b2 - b1) / (2.0 * c1) < 0.0)
    why << "kappa0 = (b2 - b1)/(2 c1) < 0 in " << constants()
        << ": the quadratic never reaches slope b2 (sign of c1 must match sign of b2 - b1)";
  return why.str();
}

BendingLaw BendingLaw::FromSi(double b1, double b2, double c1) {
  if (std::string why = Invalidity(b1, b2, c1); !why.empty()) throw InputError(why);
  return BendingLaw(b1, b2, c1);
}

BendingLaw BendingLaw::FromKes(double b1, double b2, double c1) {
  return FromSi(units::KesStiffnessToSi(b1), units::KesStiffnessToSi(b2),
                units::KesQuadraticToSi(c1));
}

BendingLaw::BendingLaw(double b1, double b2, double c1) : b1_(b1), b2_(b2), c1_(c1) {
  if (b1 == b2) {
    kappa0_ = 0.0;  // pure line M = b2 κ, whatever c1 says
  } else if (c1 == 0.0) {
    kappa0_ = kInf;  // pure line M = b1 κ
  } else {
    kappa0_ = (b2 - b1) / (2.0 * c1);
  }
  if (std::isfinite(kappa0_)) {
    moment0_ = (b1 - b2) * kappa0_ + c1 * kappa0_ * kappa0_;
    moment_at_kappa0_ = b1 * kappa0_ + c1 * kappa0_ * kappa0_;
    energy_at_kappa0_ = 0.5 * b1 * kappa0_ * kappa0_ + c1 * kappa0_ * kappa0_ * kappa0_ / 3.0;
  } else {
    moment0_ = 0.0;
    moment_at_kappa0_ = kInf;
    energy_at_kappa0_ = kInf;
  }
}

double BendingLaw::Moment(double kappa) const {
  const double k = std::abs(kappa);
  if (spline_) return std::copysign(SplineMoment(k), kappa);
  const double m = k <= kappa0_ ? (b1_ + c1_ * k) * k : moment0_ + b2_ * k;
  return std::copysign(m, kappa);
}

double BendingLaw::Stiffness(double kappa) const {
  const double k = std::abs(kappa);
  if (spline_) return SplineStiffness(k);
  return k <= kappa0_ ? b1_ + 2.0 * c1_ * k : b2_;
}

double BendingLaw::StiffnessDerivative(double kappa) const {
  if (spline_) {
    const double db = SplineStiffnessDerivative(std::abs(kappa));
    return kappa < 0.0 ? -db : db;
  }
  if (std::abs(kappa) > kappa0_) return 0.0;
  return kappa < 0.0 ? -2.0 * c1_ : 2.0 * c1_;
}

std::array<double, 3> BendingLaw::MomentGradient(double kappa) const {
  assert(!spline_ && "MomentGradient: a spline law has no {b1, b2, c1}");
  if (spline_) return {kNaN, kNaN, kNaN};
  const double k = std::abs(kappa), sign = kappa < 0.0 ? -1.0 : 1.0;
  if (k <= kappa0_) return {sign * k, 0.0, sign * k * k};
  return {sign * kappa0_, sign * (k - kappa0_), sign * kappa0_ * kappa0_};
}

double BendingLaw::Energy(double kappa) const {
  const double k = std::abs(kappa);
  if (spline_) return SplineEnergy(k);
  if (k <= kappa0_) return (0.5 * b1_ + c1_ * k / 3.0) * k * k;
  return energy_at_kappa0_ + moment0_ * (k - kappa0_) + 0.5 * b2_ * (k * k - kappa0_ * kappa0_);
}

double BendingLaw::Curvature(double moment) const {
  const double m = std::abs(moment);
  if (spline_) return std::copysign(SplineCurvature(m), moment);
  double k;
  if (m <= moment_at_kappa0_) {
    // c1 k² + b1 k - m = 0, the root that starts at 0, in the cancellation-free form.
    // The discriminant is ≥ b2² > 0 on this branch (it equals B(κ)² at the solution).
    k = 2.0 * m / (b1_ + std::sqrt(b1_ * b1_ + 4.0 * c1_ * m));
  } else {
    k = (m - moment0_) / b2_;
  }
  return std::copysign(k, moment);
}

BendingLaw BendingLaw::Scaled(double beta) const {
  if (!(beta > 0.0) || !std::isfinite(beta)) {
    std::ostringstream s;
    s << "beta must be a finite number > 0, got " << beta;
    throw InputError(s.str());
  }
  if (spline_) {
    std::vector<double> moment = spline_->moment, sd = spline_->moment_sd;
    for (double& m : moment) m *= beta;
    for (double& m : sd) m *= beta;
    return FromSpline(spline_->kappa, std::move(moment), std::move(sd));
  }
  return BendingLaw(beta * b1_, beta * b2_, beta * c1_);
}

double BendingLaw::b1_kes() const { return units::SiStiffnessToKes(b1_); }
double BendingLaw::b2_kes() const { return units::SiStiffnessToKes(b2_); }
double BendingLaw::c1_kes() const { return units::SiQuadraticToKes(c1_); }

LawWeights DirectionWeights(double cos_sq_phi, bool with_bias) {
  const double c2 = std::clamp(cos_sq_phi, 0.0, 1.0);
  if (!with_bias) return {c2, 1.0 - c2, 0.0};
  double c = 2.0 * c2 - 1.0;  // cos 2φ
  if (std::abs(c) < 1e-12) c = 0.0;  // φ = 45° up to round-off (cos²(π/4) = 0.5000000000000001)
  if (c >= 0.0) return {c, 0.0, 1.0 - c};
  return {0.0, -c, 1.0 + c};
}

BlendedLaw::BlendedLaw(const BendingLaw& warp, const BendingLaw& weft, double phi)
    : BlendedLaw(warp, weft, std::nullopt, phi) {}

BlendedLaw::BlendedLaw(const BendingLaw& warp, const BendingLaw& weft,
                       const std::optional<BendingLaw>& bias, double phi)
    : warp_(warp), weft_(weft), bias_(bias ? *bias : warp) {
  const double c = std::cos(phi);
  w_ = DirectionWeights(c * c, bias.has_value());
}

namespace {

// w_warp f(warp) + w_weft f(weft) + w_bias f(bias), skipping the laws of weight 0.
template <class F>
double Blend(const LawWeights& w, const BendingLaw& warp, const BendingLaw& weft,
             const BendingLaw& bias, F&& f) {
  double sum = 0.0;
  if (w.warp != 0.0) sum += w.warp * f(warp);
  if (w.weft != 0.0) sum += w.weft * f(weft);
  if (w.bias != 0.0) sum += w.bias * f(bias);
  return sum;
}

}  // namespace

double BlendedLaw::Moment(double kappa) const {
  return Blend(w_, warp_, weft_, bias_, [&](const BendingLaw& l) { return l.Moment(kappa); });
}

double BlendedLaw::Stiffness(double kappa) const {
  return Blend(w_, warp_, weft_, bias_, [&](const BendingLaw& l) { return l.Stiffness(kappa); });
}

double BlendedLaw::Energy(double kappa) const {
  return Blend(w_, warp_, weft_, bias_, [&](const BendingLaw& l) { return l.Energy(kappa); });
}

double BlendedLaw::Curvature(double moment) const {
  // M is strictly increasing; the inverses of the laws it blends bracket the blend's.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const auto bracket = [&](double weight, const BendingLaw& law) {
    if (weight == 0.0) return;
    const double k = law.Curvature(moment);
    lo = std::min(lo, k);
    hi = std::max(hi, k);
  };
  bracket(w_.warp, warp_);
  bracket(w_.weft, weft_);
  bracket(w_.bias, bias_);
  double k = 0.5 * (lo + hi);
  for (int it = 0; it < 100 && hi > lo; ++it) {
    const double f = Moment(k) - moment;
    if (f == 0.0) return k;
    (f > 0.0 ? hi : lo) = k;
    double next = k - f / Stiffness(k);  // Newton, kept inside the bracket
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - k) <= 1e-15 * std::abs(k)) return next;
    k = next;
  }
  return k;
}

}  // namespace textile
