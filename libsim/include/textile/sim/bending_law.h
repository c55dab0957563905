#ifndef TEXTILE_SIM_BENDING_LAW_H_
#define TEXTILE_SIM_BENDING_LAW_H_

// The nonlinear moment-curvature law of Pabst et al., eq. 1, made odd and checked.
//
//   // The paper's Fig. 8 fabric, constants in KES units (gf·cm, gf·cm²).
//   textile::BendingLaw law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   double m = law.Moment(50.0);          // N (= N·m per m of width) at κ = 50 /m
//   double b = law.Stiffness(50.0);       // N·m
//   double k = law.Curvature(m);          // back to 50 /m
//
// For κ ≥ 0:  M = b1 κ + c1 κ²      (κ ≤ κ0)
//             M = M0 + b2 κ         (κ > κ0)
// with κ0 = (b2 - b1) / (2 c1) and M0 = (b1 - b2) κ0 + c1 κ0², and M(-κ) = -M(κ).
// Degenerate cases are laws, not errors: b1 = b2 gives κ0 = 0 and M = b2 κ; c1 = 0 with
// b1 ≠ b2 gives κ0 = +∞ and M = b1 κ. B = dM/dκ runs linearly from b1 to b2 on [0, κ0], so
// b1 > 0, b2 > 0 and κ0 ≥ 0 make M strictly increasing and C1 everywhere.

#include <array>
#include <limits>
#include <string>

namespace textile {

class BendingLaw {
 public:
  // Constants in SI: b1, b2 [N·m], c1 [N·m²]. Throws InputError when the law is invalid
  // (non-finite, b ≤ 0, κ0 < 0), naming the three constants.
  static BendingLaw FromSi(double b1, double b2, double c1);
  // Constants in KES units: b1, b2 [gf·cm], c1 [gf·cm²].
  static BendingLaw FromKes(double b1, double b2, double c1);

  // Why {b1, b2, c1} [SI] is not a valid law; empty when it is.
  static std::string Invalidity(double b1, double b2, double c1);

  double b1() const { return b1_; }  // initial stiffness [N·m]
  double b2() const { return b2_; }  // ultimate stiffness [N·m]
  double c1() const { return c1_; }  // quadratic coefficient [N·m²]
  // Curvature where the quadratic meets the line [1/m]; 0 when b1 = b2, +∞ when c1 = 0.
  double kappa0() const { return kappa0_; }
  // Intercept of the linear branch [N]: M = M0 + b2 κ for κ > κ0 (0 when κ0 is 0 or ∞).
  double moment0() const { return moment0_; }
  // M(κ0) [N], +∞ when κ0 = ∞.
  double moment_at_kappa0() const { return moment_at_kappa0_; }

  // Moment per unit width M(κ) [N] at curvature κ [1/m]; odd in κ.
  double Moment(double kappa) const;
  // Stiffness B(κ) = dM/dκ [N·m]; even in κ, always > 0.
  double Stiffness(double kappa) const;
  // d²M/dκ² [N·m²] (2 c1 sign(κ) below κ0, 0 above); used by consistent Jacobians.
  double StiffnessDerivative(double kappa) const;
  // Strain energy per unit area Ψ(κ) = ∫₀^κ M dκ' [J/m²]; even, Ψ' = M.
  double Energy(double kappa) const;
  // ∂M/∂{b1, b2, c1} at fixed κ [m, m, m²·... i.e. κ, κ, κ² units], odd in κ. Above κ0 the
  // envelope of M0 = -(b2 - b1)²/(4 c1) gives {κ0, |κ| - κ0, κ0²}; below, {|κ|, 0, κ²}; the two
  // agree at κ0 so the gradient is continuous. Used by sensitivities through the elastica.
  std::array<double, 3> MomentGradient(double kappa) const;
  // Inverse law κ = M⁻¹(m) [1/m] for a moment m [N]; odd; exact (closed form).
  double Curvature(double moment) const;

  // The law scaled by the linear bending stiffness factor β > 0 (section 3.4). With the
  // printed typo fixed (b2 := β b2), the printed α(κ) form reduces to M_β(κ) = β M(κ):
  // b1 -> β b1, b2 -> β b2, c1 -> β c1, and κ0 is unchanged.
  BendingLaw Scaled(double beta) const;

  // Constants in KES units, for people.
  double b1_kes() const;
  double b2_kes() const;
  double c1_kes() const;

  // True when the quadratic branch is in use at all (κ0 > 0).
  bool HasQuadraticBranch() const { return kappa0_ > 0.0; }

 private:
  BendingLaw(double b1, double b2, double c1);

  double b1_ = 0.0, b2_ = 0.0, c1_ = 0.0;
  double kappa0_ = 0.0, moment0_ = 0.0, moment_at_kappa0_ = 0.0, energy_at_kappa0_ = 0.0;
};

// Warp/weft anisotropy (physics.md): a hinge whose edge makes angle φ with the warp direction
// bends with M(κ) = cos²φ M_warp(κ) + sin²φ M_weft(κ). The blend of two laws is again odd,
// C1 and strictly increasing; its inverse is found by safeguarded Newton.
class BlendedLaw {
 public:
  // phi: angle between the hinge edge and the warp direction [rad].
  BlendedLaw(const BendingLaw& warp, const BendingLaw& weft, double phi);
  double Moment(double kappa) const;      // [N]
  double Stiffness(double kappa) const;   // [N·m]
  double Energy(double kappa) const;      // [J/m²]
  double Curvature(double moment) const;  // [1/m], to 1e-14 relative
  double warp_weight() const { return w_warp_; }

 private:
  BendingLaw warp_, weft_;
  double w_warp_, w_weft_;
};

}  // namespace textile

#endif  // TEXTILE_SIM_BENDING_LAW_H_
