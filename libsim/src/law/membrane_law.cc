#include "textile/sim/law/membrane_law.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

bool Finite(double v) { return std::isfinite(v); }

// The knots (0, 0) + given, checked: strains and forces strictly increasing and positive.
void CheckKnots(const std::vector<double>& strain, const std::vector<double>& force) {
  if (strain.empty() || strain.size() != force.size()) {
    throw InputError("tensile curve: needs one force per strain and at least one point, got " +
                     std::to_string(strain.size()) + " strains and " +
                     std::to_string(force.size()) + " forces");
  }
  double last_strain = 0.0, last_force = 0.0;
  for (size_t i = 0; i < strain.size(); ++i) {
    if (!Finite(strain[i]) || !Finite(force[i]) || !(strain[i] > last_strain) ||
        !(force[i] > last_force)) {
      throw InputError("tensile curve: point " + std::to_string(i) + " (" +
                       NumberText(strain[i]) + ", " + NumberText(force[i]) +
                       " N/m) is not monotone: strains and forces must increase from (0, 0)");
    }
    last_strain = strain[i];
    last_force = force[i];
  }
}

// Fritsch-Butland interior slopes and shape-preserving end slopes, the one at zero kept within
// [0.1, 3] × the first secant.
std::vector<double> MonotoneSlopes(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  std::vector<double> h(n - 1), d(n - 1), m(n);
  for (size_t k = 0; k + 1 < n; ++k) {
    h[k] = x[k + 1] - x[k];
    d[k] = (y[k + 1] - y[k]) / h[k];
  }
  if (n == 2) return {d[0], d[0]};
  for (size_t k = 1; k + 1 < n; ++k) {
    const double w1 = 2 * h[k] + h[k - 1], w2 = h[k] + 2 * h[k - 1];
    m[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
  }
  const auto end_slope = [](double h0, double h1, double d0, double d1) {
    double s = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (s <= 0.0) s = 0.0;
    return std::min(s, 3 * d0);
  };
  m[0] = std::clamp(end_slope(h[0], h[1], d[0], d[1]), 0.1 * d[0], 3 * d[0]);
  m[n - 1] = end_slope(h[n - 2], h[n - 3], d[n - 2], d[n - 3]);
  if (!(m[n - 1] > 0.0)) m[n - 1] = d[n - 2];  // a curve flattening at its end keeps a slope
  return m;
}

// Hermite basis on t in [0, 1]: values, derivatives and integrals from 0 to t.
struct Hermite {
  double h00, h10, h01, h11;
};
Hermite Basis(double t) {
  return {2 * t * t * t - 3 * t * t + 1, t * t * t - 2 * t * t + t, -2 * t * t * t + 3 * t * t,
          t * t * t - t * t};
}
Hermite BasisDerivative(double t) {
  return {6 * t * t - 6 * t, 3 * t * t - 4 * t + 1, -6 * t * t + 6 * t, 3 * t * t - 2 * t};
}
Hermite BasisIntegral(double t) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t;
  return {t4 / 2 - t3 + t, t4 / 4 - 2 * t3 / 3 + t2 / 2, -t4 / 2 + t3, t4 / 4 - t3 / 3};
}

}  // namespace

TensileCurve TensileCurve::Linear(double modulus) {
  if (!(modulus > 0.0) || !Finite(modulus)) {
    throw InputError("tensile modulus must be a positive number of N/m, got " +
                     NumberText(modulus));
  }
  return FromHermite({1.0}, {modulus}, {modulus, modulus});
}

TensileCurve TensileCurve::FromPoints(const std::vector<double>& strain,
                                      const std::vector<double>& force) {
  CheckKnots(strain, force);
  std::vector<double> x{0.0}, y{0.0};
  x.insert(x.end(), strain.begin(), strain.end());
  y.insert(y.end(), force.begin(), force.end());
  const std::vector<double> m = MonotoneSlopes(x, y);
  return FromHermite(strain, force, m);
}

TensileCurve TensileCurve::FromHermite(const std::vector<double>& strain,
                                       const std::vector<double>& force,
                                       const std::vector<double>& slope) {
  CheckKnots(strain, force);
  TensileCurve c;
  c.strain_ = {0.0};
  c.force_ = {0.0};
  c.strain_.insert(c.strain_.end(), strain.begin(), strain.end());
  c.force_.insert(c.force_.end(), force.begin(), force.end());
  c.slope_ = slope;
  if (c.slope_.size() != c.strain_.size()) {
    throw InputError("tensile curve: needs a slope at zero and at each point (" +
                     std::to_string(c.strain_.size()) + "), got " +
                     std::to_string(slope.size()));
  }
  for (size_t k = 0; k < c.slope_.size(); ++k) {
    if (!(c.slope_[k] > 0.0) || !Finite(c.slope_[k])) {
      throw InputError("tensile curve: slope " + std::to_string(k) + " must be positive, got " +
                       NumberText(c.slope_[k]));
    }
  }
  c.energy_.assign(c.strain_.size(), 0.0);
  for (size_t k = 0; k + 1 < c.strain_.size(); ++k) {
    const double h = c.strain_[k + 1] - c.strain_[k];
    const double delta = (c.force_[k + 1] - c.force_[k]) / h;
    const double a = c.slope_[k] / delta, b = c.slope_[k + 1] / delta;
    if (a * a + b * b > 9.0 * (1 + 1e-9)) {
      throw InputError("tensile curve: the slopes at points " + std::to_string(k) + " and " +
                       std::to_string(k + 1) + " would make it non-monotone between them");
    }
    const Hermite i = BasisIntegral(1.0);
    c.energy_[k + 1] = c.energy_[k] + h * (i.h00 * c.force_[k] + i.h10 * h * c.slope_[k] +
                                           i.h01 * c.force_[k + 1] + i.h11 * h * c.slope_[k + 1]);
  }
  return c;
}

int TensileCurve::Segment(double strain) const {
  const auto it = std::upper_bound(strain_.begin(), strain_.end(), strain);
  return static_cast<int>(it - strain_.begin()) - 1;  // -1: ε < 0; size-1: past the knots
}

double TensileCurve::Force(double strain) const {
  const int k = Segment(strain);
  const int last = static_cast<int>(strain_.size()) - 1;
  if (k < 0) return slope_[0] * strain;
  if (k >= last) return force_[last] + slope_[last] * (strain - strain_[last]);
  const double h = strain_[k + 1] - strain_[k], t = (strain - strain_[k]) / h;
  const Hermite b = Basis(t);
  return b.h00 * force_[k] + b.h10 * h * slope_[k] + b.h01 * force_[k + 1] +
         b.h11 * h * slope_[k + 1];
}

double TensileCurve::Energy(double strain) const {
  const int k = Segment(strain);
  const int last = static_cast<int>(strain_.size()) - 1;
  if (k < 0) return 0.5 * slope_[0] * strain * strain;
  if (k >= last) {
    const double s = strain - strain_[last];
    return energy_[last] + force_[last] * s + 0.5 * slope_[last] * s * s;
  }
  const double h = strain_[k + 1] - strain_[k], t = (strain - strain_[k]) / h;
  const Hermite i = BasisIntegral(t);
  return energy_[k] + h * (i.h00 * force_[k] + i.h10 * h * slope_[k] + i.h01 * force_[k + 1] +
                           i.h11 * h * slope_[k + 1]);
}

double TensileCurve::Stiffness(double strain) const {
  const int k = Segment(strain);
  const int last = static_cast<int>(strain_.size()) - 1;
  if (k < 0) return slope_[0];
  if (k >= last) return slope_[last];
  const double h = strain_[k + 1] - strain_[k], t = (strain - strain_[k]) / h;
  const Hermite d = BasisDerivative(t);
  return (d.h00 * force_[k] + d.h01 * force_[k + 1]) / h + d.h10 * slope_[k] +
         d.h11 * slope_[k + 1];
}

double YarnForce(const TensileCurve& curve, const MembraneCompression& c, double strain) {
  if (strain >= 0.0) return curve.Force(strain);
  const double k0 = curve.SmallStrainModulus(), eb = c.buckling_strain;
  if (strain >= -eb) return k0 * strain;
  return -k0 * eb + c.ratio * k0 * (strain + eb);
}

double YarnEnergy(const TensileCurve& curve, const MembraneCompression& c, double strain) {
  if (strain >= 0.0) return curve.Energy(strain);
  const double k0 = curve.SmallStrainModulus(), eb = c.buckling_strain;
  if (strain >= -eb) return 0.5 * k0 * strain * strain;
  const double past = strain + eb;  // < 0
  return 0.5 * k0 * eb * eb - k0 * eb * past + 0.5 * c.ratio * k0 * past * past;
}

double YarnStiffness(const TensileCurve& curve, const MembraneCompression& c, double strain) {
  if (strain >= 0.0) return curve.Stiffness(strain);
  const double k0 = curve.SmallStrainModulus();
  return strain >= -c.buckling_strain ? k0 : c.ratio * k0;
}

double KesShearToNewtonPerMetre(double g_gf_per_cm_deg) {
  return g_gf_per_cm_deg * kGfPerCmInNewtonPerMetre * 180.0 / std::numbers::pi;
}

TensileCurve TensileCurveFromKes(double emt_percent, double lt) {
  if (!(emt_percent > 0.0 && emt_percent <= 100.0)) {
    throw InputError("EMT must be in (0, 100] %, got " + NumberText(emt_percent));
  }
  if (!(lt > 0.1 && lt < 1.25)) {
    throw InputError("LT must be in (0.1, 1.25), got " + NumberText(lt));
  }
  const double a = lt >= 0.55 ? 2 * lt - 1 : 0.1;
  const double b = 1.0 - a;
  const double n = lt >= 0.55 ? 3.0 : (1.9 - lt) / (lt - 0.1);
  const double em = emt_percent / 100.0, fm = kKesMaxLoad;
  constexpr int kKnots = 32;
  std::vector<double> strain, force, slope{fm / em * a};
  for (int k = 1; k <= kKnots; ++k) {
    const double x = static_cast<double>(k) / kKnots;
    strain.push_back(x * em);
    force.push_back(fm * (a * x + b * std::pow(x, n)));
    slope.push_back(fm / em * (a + b * n * std::pow(x, n - 1)));
  }
  return TensileCurve::FromHermite(strain, force, slope);
}

TensileCurve TensileCurveFromFastE100(double e100_percent) {
  if (!(e100_percent > 0.0 && e100_percent <= 100.0)) {
    throw InputError("E100 must be in (0, 100] %, got " + NumberText(e100_percent));
  }
  return TensileCurve::Linear(100.0 * kGfPerCmInNewtonPerMetre / (e100_percent / 100.0));
}

}  // namespace textile
