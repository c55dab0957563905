#include "textile/sim/bending_law.h"

#include <cmath>
#include <sstream>

#include "textile/sim/error.h"
#include "textile/sim/units.h"

namespace textile {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

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
  const double m = k <= kappa0_ ? (b1_ + c1_ * k) * k : moment0_ + b2_ * k;
  return std::copysign(m, kappa);
}

double BendingLaw::Stiffness(double kappa) const {
  const double k = std::abs(kappa);
  return k <= kappa0_ ? b1_ + 2.0 * c1_ * k : b2_;
}

double BendingLaw::StiffnessDerivative(double kappa) const {
  if (std::abs(kappa) > kappa0_) return 0.0;
  return kappa < 0.0 ? -2.0 * c1_ : 2.0 * c1_;
}

std::array<double, 3> BendingLaw::MomentGradient(double kappa) const {
  const double k = std::abs(kappa), sign = kappa < 0.0 ? -1.0 : 1.0;
  if (k <= kappa0_) return {sign * k, 0.0, sign * k * k};
  return {sign * kappa0_, sign * (k - kappa0_), sign * kappa0_ * kappa0_};
}

double BendingLaw::Energy(double kappa) const {
  const double k = std::abs(kappa);
  if (k <= kappa0_) return (0.5 * b1_ + c1_ * k / 3.0) * k * k;
  return energy_at_kappa0_ + moment0_ * (k - kappa0_) + 0.5 * b2_ * (k * k - kappa0_ * kappa0_);
}

double BendingLaw::Curvature(double moment) const {
  const double m = std::abs(moment);
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
  return BendingLaw(beta * b1_, beta * b2_, beta * c1_);
}

double BendingLaw::b1_kes() const { return units::SiStiffnessToKes(b1_); }
double BendingLaw::b2_kes() const { return units::SiStiffnessToKes(b2_); }
double BendingLaw::c1_kes() const { return units::SiQuadraticToKes(c1_); }

BlendedLaw::BlendedLaw(const BendingLaw& warp, const BendingLaw& weft, double phi)
    : warp_(warp), weft_(weft) {
  const double c = std::cos(phi);
  w_warp_ = c * c;
  w_weft_ = 1.0 - w_warp_;
}

double BlendedLaw::Moment(double kappa) const {
  return w_warp_ * warp_.Moment(kappa) + w_weft_ * weft_.Moment(kappa);
}

double BlendedLaw::Stiffness(double kappa) const {
  return w_warp_ * warp_.Stiffness(kappa) + w_weft_ * weft_.Stiffness(kappa);
}

double BlendedLaw::Energy(double kappa) const {
  return w_warp_ * warp_.Energy(kappa) + w_weft_ * weft_.Energy(kappa);
}

double BlendedLaw::Curvature(double moment) const {
  // M is strictly increasing; each pure law's inverse brackets the blend's.
  double lo = warp_.Curvature(moment), hi = weft_.Curvature(moment);
  if (lo > hi) std::swap(lo, hi);
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
