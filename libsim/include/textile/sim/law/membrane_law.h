#ifndef TEXTILE_SIM_LAW_MEMBRANE_LAW_H_
#define TEXTILE_SIM_LAW_MEMBRANE_LAW_H_

// The in-plane behaviour of a woven fabric as labs measure it (docs/methods/materials.md,
// "Membrane"): a tensile curve along the warp and one along the weft, a shear modulus between
// them, and how far the sheet gives under compression. SI inside: force per width [N/m] against
// engineering strain [-] (the stretch of a yarn line minus one), shear in N/m per radian.
//
//   textile::TensileCurve warp = textile::TensileCurveFromKes(5.0, 0.65);  // EMT 5 %, LT 0.65
//   double f = warp.Force(0.01);      // [N/m] at 1 % strain
//   double w = warp.Energy(0.01);     // ∫₀^ε F dε [J/m²]
//   double k = warp.Stiffness(0.01);  // dF/dε [N/m]
//
// The tension side of a curve is monotone (C¹, piecewise cubic through the knots, slopes that
// keep it monotone (Fritsch-Carlson), linear past the last knot with the last slope). The
// compression side is not part of the curve: the membrane applies its compression model
// (MembraneCompression) to the curve's small-strain modulus.

#include <vector>

namespace textile {

// One yarn direction's tensile law F(ε), ε ≥ 0.
class TensileCurve {
 public:
  // A straight line F = modulus ε. Throws InputError unless 0 < modulus < ∞ [N/m].
  static TensileCurve Linear(double modulus);
  // A monotone curve through (0, 0) and the given knots (strain [-], force per width [N/m]),
  // strains strictly increasing and > 0, forces strictly increasing and > 0. Throws InputError
  // naming the first bad knot (index from 0).
  // The slopes are Fritsch-Carlson's (monotone); the slope at zero is kept between a tenth of
  // and three times the first knot's secant, so that the sheet is stiff at rest.
  static TensileCurve FromPoints(const std::vector<double>& strain,
                                 const std::vector<double>& force);
  // A cubic Hermite curve with the given slopes at zero and at each knot (strain.size() + 1
  // slopes; an analytic curve sampled: the slopes are its derivatives). The same checks as FromPoints, plus slopes > 0 and within
  // Fritsch-Carlson's monotonicity region (α² + β² ≤ 9 on each interval).
  static TensileCurve FromHermite(const std::vector<double>& strain,
                                  const std::vector<double>& force,
                                  const std::vector<double>& slope);

  // For ε < 0 the three continue the curve linearly with its small-strain modulus (the
  // membrane applies its compression model instead: YarnForce below).
  double Force(double strain) const;      // F(ε) [N/m]
  double Energy(double strain) const;     // W(ε) = ∫₀^ε F [J/m²]
  double Stiffness(double strain) const;  // F'(ε) [N/m]; ≥ 0, > 0 at the knots
  // The slope at zero strain, which the compression model scales [N/m].
  double SmallStrainModulus() const { return Stiffness(0.0); }

  const std::vector<double>& strains() const { return strain_; }  // knots, (0, 0) first
  const std::vector<double>& forces() const { return force_; }
  const std::vector<double>& slopes() const { return slope_; }    // F' at each knot

 private:
  int Segment(double strain) const;  // the knot interval holding ε (last: beyond the knots)
  std::vector<double> strain_, force_, slope_;
  std::vector<double> energy_;       // W at each knot
};

// How the sheet gives under compression along a yarn (a negative strain ε < 0), as a fraction
// of the small-strain modulus k0 (docs/methods/drapemeter.md, "Compression"):
//   F(ε) = k0 ε                                         for -buckling_strain ≤ ε < 0,
//   F(ε) = -k0 buckling_strain + ratio k0 (ε + buckling_strain)   past it.
// ratio = 1, buckling_strain = 0 is a membrane as stiff in compression as in tension.
struct MembraneCompression {
  double ratio = 1.0;            // c, kMinCompressionRatio ≤ c ≤ 1 (material.h)
  double buckling_strain = 0.0;  // ε_b ≥ 0 [-]
};

// One yarn's law in tension (the curve) and compression (the model), ε any sign.
double YarnForce(const TensileCurve& curve, const MembraneCompression& c, double strain);
double YarnEnergy(const TensileCurve& curve, const MembraneCompression& c, double strain);
double YarnStiffness(const TensileCurve& curve, const MembraneCompression& c, double strain);

// The orthotropic membrane: pattern x is the warp, y the weft (as for bending).
// Energy per rest area ψ = W_warp(ε_warp) + W_weft(ε_weft) + ½ G γ², with ε_a = |F a| - 1 the
// engineering strain of the yarn line a (W extended by MembraneCompression for ε < 0) and
// γ = (F x)·(F y), twice the Green shear strain E12, the yarns' engineering shear for small
// strains (KES-FB1 shear angle in radians).
// The compression model is the material's (Material::Compression()), shared with the
// isotropic membrane.
struct OrthotropicMembrane {
  TensileCurve warp = TensileCurve::Linear(1000.0);
  TensileCurve weft = TensileCurve::Linear(1000.0);
  double shear_modulus = 45.0;  // G [N/m per radian]
};

// Unit conversions at the file's edge.
// KES-FB1 shear rigidity G: 1 gf/cm/degree = 9.80665e-3 N / 1e-2 m / (π/180) = 56.19 N/m per rad.
double KesShearToNewtonPerMetre(double g_gf_per_cm_deg);
// KES-FB1 tensile force per width: 1 gf/cm = 0.980665 N/m.
constexpr double kGfPerCmInNewtonPerMetre = 0.980665;
// The KES-FB1 standard maximum load, 500 gf/cm [N/m].
constexpr double kKesMaxLoad = 500.0 * kGfPerCmInNewtonPerMetre;

// A monotone tensile curve from a KES-FB1 tensile test at the standard 500 gf/cm:
// EMT [%] the strain at the maximum load, LT [-] the linearity WT / (½ F_m EMT), and, when given,
// WT [gf·cm/cm²] the tensile energy, which must agree with LT and EMT within 5 %
// (docs/methods/materials.md gives the curve's form). Throws InputError naming the field.
// The form: F = F_m (A x + B xⁿ), x = ε/EMT, A + B = 1 (the curve meets F_m at EMT) and
// A/2 + B/(n+1) = LT/2 (its energy is WT): n = 3 (A = 2 LT - 1, B = 2 (1 - LT)) for
// 0.55 ≤ LT < 1.25, and below 0.55 A = 0.1 (a tenth of the secant modulus at rest) with
// n = (1.9 - LT) / (LT - 0.1). LT must lie in (0.1, 1.25); EMT in (0, 100].
TensileCurve TensileCurveFromKes(double emt_percent, double lt);
// FAST-3 extensibility E100 [%] at 100 gf/cm: a linear modulus 100 gf/cm / (E100/100).
TensileCurve TensileCurveFromFastE100(double e100_percent);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_MEMBRANE_LAW_H_
