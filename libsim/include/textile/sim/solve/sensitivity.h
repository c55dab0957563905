#ifndef TEXTILE_SIM_SOLVE_SENSITIVITY_H_
#define TEXTILE_SIM_SOLVE_SENSITIVITY_H_

// Design sensitivity of a static equilibrium (Umetani et al., Sensitive Couture, section 4):
// at a converged state x, R(x, p) = ∇E(x; p) = 0 (SC eq. 1 with R the net force), and a
// parameter change dp moves the equilibrium by the incremental update of SC section 4,
//
//   K dx = -(∂R/∂p) dp,   K = ∇ₓR = ∇²E(x), the exact (unprojected) Hessian,
//
// one back-substitution per parameter with one Cholesky factorisation of K, or one for all the
// parameters for a single quantity of the state (the adjoint form; docs/methods/sensitivity.md):
//
//   textile::EquilibriumSensitivity s(&problem, x, material);   // factorises K once
//   textile::Vertices dx = s.Displacement("b1");                // ∂x/∂ln b1 [m]
//
// ∂R/∂p is a central difference of ClothProblem::MaterialGradient at fixed x over p ± 1e-4 of
// its scale (DifferenceStep: one-sided at the edge of a parameter's range; the elements are not
// differentiated by hand; the truncation error is ~1e-8 relative, 1e-4 one-sided). Contact and
// friction anchors stay as they are: the contact set is frozen.

#include <functional>
#include <memory>
#include <vector>
#include <string>

#include "textile/sim/law/material.h"
#include "textile/sim/solve/cloth_problem.h"

namespace textile {

class EquilibriumSensitivity {
 public:
  // Factorises K at x (#V×3 [m], fixed vertices in place). `material` is the one `problem`
  // was built with. Throws InputError for a state of the wrong size or not finite;
  // ComputeError when x is not an equilibrium of the problem (relative residual above
  // max_residual: a sensitivity there means nothing) or K is not positive definite (a buckling
  // point, where the branch may change; no sensitivity exists).
  EquilibriumSensitivity(ClothProblem* problem, const Vertices& x, const Material& material,
                         double max_residual = 1e-4);
  ~EquilibriumSensitivity();
  EquilibriumSensitivity(const EquilibriumSensitivity&) = delete;
  EquilibriumSensitivity& operator=(const EquilibriumSensitivity&) = delete;

  // dx for a change of the net force dR (#V×3 [N]): K dx = -dR; zero on fixed vertices.
  Vertices Solve(const Vertices& residual_change) const;
  // ∂R/∂p [N per unit of p, SI] for a material parameter (material_parameters.h), by central
  // differences; throws InputError for an unknown name or when the stepped material is invalid.
  Vertices ResidualDerivative(const std::string& parameter) const;
  // ∂x/∂p [m per unit of p, SI]: -K⁻¹ ∂R/∂p.
  Vertices DisplacementPerUnit(const std::string& parameter) const;
  // ∂x/∂ln p = p ∂x/∂p [m] (zero for a parameter that is 0, e.g. c1 of a linear law).
  Vertices Displacement(const std::string& parameter) const;

  // The adjoint form, for a scalar quantity Q(x) of the equilibrium and many parameters: with
  // g = ∂Q/∂x (#V×3), dQ/dp = g · ∂x/∂p = λ · ∂R/∂p, λ = -K⁻¹ g (K is symmetric). Adjoint(g)
  // is λ, one back-substitution; QuantityDerivativePerUnit(λ, p) is dQ/dp [per unit of p, SI]
  // without one.
  Vertices Adjoint(const Vertices& quantity_gradient) const;
  double QuantityDerivativePerUnit(const Vertices& adjoint, const std::string& parameter) const;

  // A scene's lengths (a radius, an overhang) as parameters: a morph of the problem's rest
  // mesh, rest + t·d_rest (#V×3 [m per unit of t]), the held vertices moved along, and the seam
  // lines as seams_at(t) gives them (the problem's when empty). The state is carried with the
  // same field, x + t·d_rest (smooth, so the difference is), and the equilibrium's change is
  // that plus a correction: dx/dt = d_rest + Solve(T), T = ∂R/∂t along the carried state, which
  // this returns (#V×3, zero on the held vertices; central differences at t = ±step of
  // ClothProblem::MaterialGradient on the morphed rest, contact left out). For a quantity:
  // dQ/dt = g · d_rest + λ · T. Take the step small (1e-8 of the scene's size): a membrane soft
  // in compression has a kink at zero strain, which a larger step straddles
  // (docs/methods/sensitivity.md, "Scene radii"). `parts` (ClothProblem::MaterialPart bits)
  // limits the forces to those the change moves: a seam profile's step with no morph moves the
  // bending only.
  using SeamsAt = std::function<std::vector<Seam>(double t)>;
  Vertices RestShapeResidualChange(const Vertices& d_rest, double step,
                                   const SeamsAt& seams_at = {},
                                   int parts = ClothProblem::kAllParts) const;

 private:
  struct Factor;
  ClothProblem* problem_;
  Vertices x_;
  Material material_;
  std::unique_ptr<Factor> factor_;
};

}  // namespace textile

#endif  // TEXTILE_SIM_SOLVE_SENSITIVITY_H_
