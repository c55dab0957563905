#ifndef TEXTILE_SIM_LAW_BENDING_LAW_H_
#define TEXTILE_SIM_LAW_BENDING_LAW_H_

// The nonlinear moment-curvature law of Pabst et al., eq. 1, made odd and checked; or a
// monotone spline through measured knots, for fabrics the three constants cannot follow.
//
//   // The paper's Fig. 8 fabric, constants in KES units (gf·cm, gf·cm²).
//   textile::BendingLaw law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   double m = law.Moment(50.0);          // N (= N·m per m of width) at κ = 50 /m
//   double b = law.Stiffness(50.0);       // N·m
//   double k = law.Curvature(m);          // back to 50 /m
//
//   // A technical fabric's knee: stiff up to 0.3 /m, nearly constant moment past 2 /m.
//   textile::BendingLaw knee = textile::BendingLaw::FromSpline(
//       {0.0, 0.3, 2.0, 10.0, 20.0} /* κ [1/m] */, {0.0, 0.23, 0.25, 0.30, 0.39} /* M [N] */);
//   double b0 = knee.Stiffness(0.0);      // B(0) [N·m], also knee.b1()
//
// For κ ≥ 0:  M = b1 κ + c1 κ²      (κ ≤ κ0)
//             M = M0 + b2 κ         (κ > κ0)
// with κ0 = (b2 - b1) / (2 c1) and M0 = (b1 - b2) κ0 + c1 κ0², and M(-κ) = -M(κ).
// Degenerate cases are laws, not errors: b1 = b2 gives κ0 = 0 and M = b2 κ; c1 = 0 with
// b1 ≠ b2 gives κ0 = +∞ and M = b1 κ. B = dM/dκ runs linearly from b1 to b2 on [0, κ0], so
// b1 > 0, b2 > 0 and κ0 ≥ 0 make M strictly increasing and C1 everywhere.
//
// Spline laws (FromSpline): M is the piecewise cubic Hermite interpolant of knots (κ_i, M_i),
// κ_0 = 0, M_0 = 0, both strictly increasing, with Steffen's slopes (below), made odd; beyond
// the last knot it continues as the line with the last knot's slope. The Pabst accessors keep
// their meaning where they have one: b1() = B(0), b2() = the slope beyond the last knot,
// kappa0() = the last knot (where the law turns linear), moment0() = the intercept of that line,
// moment_at_kappa0() = the last knot's moment; c1() is NaN (no quadratic coefficient) and
// MomentGradient has no spline form (∂M/∂{b1, b2, c1} is not defined: elastica sensitivities
// refuse a spline law).

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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

  // A monotone spline law through knots (κ_i, M_i), i = 0..n-1: κ [1/m], M [N] (N·m per m of
  // width), optionally a 1-sigma band moment_sd [N] per knot (carried, scaled by β, not used
  // by the mechanics). Throws InputError unless SplineInvalidity is empty.
  static BendingLaw FromSpline(std::vector<double> kappa, std::vector<double> moment,
                               std::vector<double> moment_sd = {});
  // The same in KES units: κ [1/cm], M and moment_sd [gf·cm/cm].
  static BendingLaw FromSplineKes(std::vector<double> kappa_per_cm,
                                  std::vector<double> moment_gfcm_per_cm,
                                  std::vector<double> moment_sd_gfcm_per_cm = {});
  // Why the knots are not a valid spline law; empty when they are: at least 3 knots, the same
  // count for κ, M (and moment_sd when given), all finite, κ_0 = 0 and M_0 = 0, κ and M strictly
  // increasing, moment_sd ≥ 0. These properties do not depend on the unit, so the arrays may be
  // in any; the names are used in the message ("kappa_per_cm[2] = ...").
  static std::string SplineInvalidity(std::span<const double> kappa, std::span<const double> moment,
                                      std::span<const double> moment_sd = {},
                                      std::string_view kappa_name = "kappa",
                                      std::string_view moment_name = "moment",
                                      std::string_view moment_sd_name = "moment_sd");

  bool is_spline() const { return spline_ != nullptr; }
  // A spline's knots: κ_i [1/m], M_i [N], the interpolant's slopes B(κ_i) [N·m] and the band
  // [N] (empty when none was given). All empty for a Pabst law.
  const std::vector<double>& knot_kappa() const;
  const std::vector<double>& knot_moment() const;
  const std::vector<double>& knot_stiffness() const;
  const std::vector<double>& knot_moment_sd() const;

  double b1() const { return b1_; }  // initial stiffness B(0) [N·m]
  double b2() const { return b2_; }  // ultimate stiffness [N·m] (spline: beyond the last knot)
  double c1() const { return c1_; }  // quadratic coefficient [N·m²]; NaN for a spline
  // Curvature where the quadratic meets the line [1/m]; 0 when b1 = b2, +∞ when c1 = 0.
  // Spline: the last knot, past which the law is linear.
  double kappa0() const { return kappa0_; }
  // Intercept of the linear branch [N]: M = M0 + b2 κ for κ > κ0 (0 when κ0 is 0 or ∞).
  double moment0() const { return moment0_; }
  // M(κ0) [N], +∞ when κ0 = ∞.
  double moment_at_kappa0() const { return moment_at_kappa0_; }
  // Curvatures κ > 0 [1/m] where dB/dκ jumps (M is C1, not C2, there), ascending: κ0 of a
  // Pabst law when 0 < κ0 < ∞, else none; a spline's knots after κ_0 = 0. An ODE integrator
  // stops there; a quadrature splits there.
  std::vector<double> Breakpoints() const;
  // A lower bound of B(κ) over all κ [N·m]: min(b1, b2) for a Pabst law (B runs linearly from
  // b1 to b2; exact unless κ0 = ∞, where b2 is never reached); the exact minimum for a spline
  // (B is quadratic on each piece).
  double MinStiffness() const;

  // Moment per unit width M(κ) [N] at curvature κ [1/m]; odd in κ.
  double Moment(double kappa) const;
  // Stiffness B(κ) = dM/dκ [N·m]; even in κ, always > 0.
  double Stiffness(double kappa) const;
  // d²M/dκ² [N·m²] (2 c1 sign(κ) below κ0, 0 above; a spline's per piece, from the right at a
  // knot); used by consistent Jacobians.
  double StiffnessDerivative(double kappa) const;
  // Strain energy per unit area Ψ(κ) = ∫₀^κ M dκ' [J/m²]; even, Ψ' = M.
  double Energy(double kappa) const;
  // ∂M/∂{b1, b2, c1} at fixed κ [m, m, m²·... i.e. κ, κ, κ² units], odd in κ. Above κ0 the
  // envelope of M0 = -(b2 - b1)²/(4 c1) gives {κ0, |κ| - κ0, κ0²}; below, {|κ|, 0, κ²}; the two
  // agree at κ0 so the gradient is continuous. Used by sensitivities through the elastica.
  // Pabst laws only (a spline has no {b1, b2, c1}): asserts, NaN in a release build.
  std::array<double, 3> MomentGradient(double kappa) const;
  // Inverse law κ = M⁻¹(m) [1/m] for a moment m [N]; odd; exact (closed form). Spline: the
  // piece's cubic by safeguarded Newton to 1e-14 relative.
  double Curvature(double moment) const;

  // The law scaled by the linear bending stiffness factor β > 0 (section 3.4). With the
  // printed typo fixed (b2 := β b2), the printed α(κ) form reduces to M_β(κ) = β M(κ):
  // b1 -> β b1, b2 -> β b2, c1 -> β c1, and κ0 is unchanged. A spline's knot moments, slopes
  // and band are scaled by β, its knot curvatures unchanged.
  BendingLaw Scaled(double beta) const;

  // Constants in KES units, for people (c1_kes is NaN for a spline).
  double b1_kes() const;
  double b2_kes() const;
  double c1_kes() const;

  // True when the quadratic branch is in use at all (κ0 > 0); false for a spline.
  bool HasQuadraticBranch() const { return !spline_ && kappa0_ > 0.0; }

 private:
  struct Spline;  // knots, slopes and per-piece cubics (bending_law.cc)

  BendingLaw(double b1, double b2, double c1);
  explicit BendingLaw(std::shared_ptr<const Spline> spline);

  double SplineMoment(double k) const;               // k ≥ 0
  double SplineStiffness(double k) const;            // k ≥ 0
  double SplineStiffnessDerivative(double k) const;  // k ≥ 0
  double SplineEnergy(double k) const;               // k ≥ 0
  double SplineCurvature(double m) const;            // m ≥ 0

  double b1_ = 0.0, b2_ = 0.0, c1_ = 0.0;
  double kappa0_ = 0.0, moment0_ = 0.0, moment_at_kappa0_ = 0.0, energy_at_kappa0_ = 0.0;
  std::shared_ptr<const Spline> spline_;  // null for a Pabst law; immutable, so shared by copies
};

// The weights of the warp, weft and bias laws for bending in a direction (the curvature's,
// across a hinge's edge) at angle φ to the warp (docs/methods/materials.md, "Warp, weft and
// bias"); none negative, their sum 1. cos_sq_phi = cos²φ in [0, 1].
// - Without a bias law: cos²φ, sin²φ, 0 (docs/spec/physics.md), so the bias is the mean of the
//   warp and weft laws.
// - With one, linear in cos 2φ between the two measured directions φ lies between:
//   cos 2φ ≥ 0 (φ ≤ 45°): warp cos 2φ, bias 1 - cos 2φ; else weft |cos 2φ|, bias 1 - |cos 2φ|.
//   A bias law equal to the mean of warp and weft gives the cos²φ blend back exactly.
struct LawWeights {
  double warp = 1.0, weft = 0.0, bias = 0.0;
};
LawWeights DirectionWeights(double cos_sq_phi, bool with_bias);

// The laws of the directions a lab measures: the warp (the only one of an isotropic fabric), and
// where measured the weft and the bias (a strip cut at 45°).
struct DirectionLaws {
  BendingLaw warp;
  std::optional<BendingLaw> weft, bias;
};

// Warp/weft(/bias) anisotropy: bending whose direction makes angle φ with the warp follows
// M(κ) = w_warp M_warp(κ) + w_weft M_weft(κ) + w_bias M_bias(κ), the weights of
// DirectionWeights: the warp law is the bending of a strip cut along the warp, as a lab measures
// it, the bias law that of a strip cut at 45°. A blend of laws is again odd, C1 and strictly
// increasing; its inverse is found by safeguarded Newton.
class BlendedLaw {
 public:
  // phi: angle between the bending direction (the curvature's: across a hinge's edge) and the
  // warp [rad]; 0 is a strip cut along the warp, π/2 one cut along the weft.
  BlendedLaw(const BendingLaw& warp, const BendingLaw& weft, double phi);
  // The same with a measured bias law (none: the two-law blend above).
  BlendedLaw(const BendingLaw& warp, const BendingLaw& weft, const std::optional<BendingLaw>& bias,
             double phi);
  double Moment(double kappa) const;      // [N]
  double Stiffness(double kappa) const;   // [N·m]
  double Energy(double kappa) const;      // [J/m²]
  double Curvature(double moment) const;  // [1/m], to 1e-14 relative
  double warp_weight() const { return w_.warp; }
  const LawWeights& weights() const { return w_; }

 private:
  BendingLaw warp_, weft_, bias_;
  LawWeights w_;
};

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_BENDING_LAW_H_
