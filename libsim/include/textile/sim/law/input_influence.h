#ifndef TEXTILE_SIM_LAW_INPUT_INFLUENCE_H_
#define TEXTILE_SIM_LAW_INPUT_INFLUENCE_H_

// Influence rows for the inputs that are not the material's: a scene's lengths and angles, and
// a seam profile's coefficients, beside the material's table (material_parameters.h) in the
// drape's and the ACPM's sensitivities (docs/methods/sensitivity.md, "Scene radii", "Seam
// coefficients", "ACPM"). None of them enters the σ.
//
//   double h = textile::SeamCoefficientStep(profile, 2, 1e-4);          // a0's step
//   textile::SeamProfile up = textile::SteppedSeamProfile(profile, 2, h);
//   ... dq_da[2] = (Q(up) - Q(down)) / (2 h);
//   std::vector<textile::ParameterInfluence> rows = textile::SeamInfluences(profile, dq_da);

#include <string>
#include <vector>

#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/seam.h"

namespace textile {

// A scene input's row: its value p [SI] shown as p × display in `unit`, ∂Q/∂p [per SI unit],
// its uncertainty Δp [SI] and where that comes from; change = |∂Q/∂p| Δp, uncertainty_ln
// Δp/|p| (NaN for p = 0). Not defaulted: the value is the run's own.
ParameterInfluence SceneInfluence(const std::string& name, double value, double display,
                                  const std::string& unit, double d_q_d_p, double uncertainty,
                                  const std::string& source);

// The seam profile's coefficients of B_f(d) = a2 d² + a1 d + a0 (d in mm, Pabst et al.
// Table 2), in the order of SeamProfile::coefficients_mm: 0 is a2, 1 a1, 2 a0.
inline constexpr int kSeamCoefficients = 3;
// `profile` with coefficient k moved by t [1/mm^(2-k)], typed "fitted" (a preset's coefficients
// are Table 2's).
SeamProfile SteppedSeamProfile(const SeamProfile& profile, int k, double t);
// A difference step for coefficient k [1/mm^(2-k)]: the one that changes B_f by `relative` of
// |B_f(0)| (at least 1) at the influence distance d_max, where the term is largest.
double SeamCoefficientStep(const SeamProfile& profile, int k, double relative);
// Throws InputError, before a run, when a ±step of `relative` (SeamCoefficientStep) of some
// coefficient makes a profile that fails SeamProfile::Check (one at the edge of its bounds), or
// one that fades beyond d_max by the other of SeamProfile::Multiplier's two fades (S jumps
// between them: the difference would be meaningless).
void CheckSeamCoefficientSteps(const SeamProfile& profile, double relative);
// The seam's rows from ∂Q/∂a_k (kSeamCoefficients values, per 1/mm², 1/mm, 1): "seam.a2",
// "seam.a1", "seam.a0" with the values and units of the seam file (1/mm², 1/mm, -), then
// "seam.scale", B_f scaled as a whole (value 1, ∂Q/∂ln scale = Σ a_k ∂Q/∂a_k). Uncertainties:
// with the profile's covariance C its sds, and for the scale √(gᵀ C g) (the three together,
// correlated); without, ±10 % of each coefficient (of a zero one: the step that moves B_f by
// 10 % of B_f(0) at d_max) and of the scale. Throws InputError for another number of
// derivatives.
std::vector<ParameterInfluence> SeamInfluences(const SeamProfile& profile,
                                               const std::vector<double>& d_q_d_a);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_INPUT_INFLUENCE_H_
