#ifndef TEXTILE_SIM_LAW_MATERIAL_PARAMETERS_H_
#define TEXTILE_SIM_LAW_MATERIAL_PARAMETERS_H_

// The material's scalar parameters by name, as the material file spells them, for
// sensitivities and what-ifs (docs/methods/sensitivity.md):
//
//   for (const std::string& name : textile::MaterialParameterNames(m))
//     std::cout << name << " = " << textile::MaterialParameterValue(m, name).lab << "\n";
//   textile::Material stiffer = textile::WithMaterialParameter(m, "b1", 1.1 * b1_si);
//
// Names: "b1", "b2", "c1" (the `bending` law), "bending_weft.b1" ... and "bending_bias.b1" ...
// where the material has those laws (Pabst laws only: a spline law has no constants),
// "beta", "areal_density_gsm", and the membrane's: "stretch.stiffness_N_per_m" and
// "stretch.poisson" (isotropic), or "stretch.warp", "stretch.weft" (each tensile curve scaled
// as a whole; its value is the small-strain modulus) and "stretch.shear" (orthotropic), and
// "stretch.compression_ratio".

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/law/material.h"

namespace textile {

struct MaterialParameterValue {
  double si = 0.0;   // the value in SI (N·m, N·m², kg/m², N/m, -)
  double lab = 0.0;  // in the unit below (gf·cm, gf·cm², g/m², N/m, -)
  std::string unit;  // "gf·cm", "gf·cm²", "g/m²", "N/m", "N/m/rad", "-"
  // The field is one the file left out (a documented default, Material::defaulted).
  bool defaulted = false;
};

// The parameters this material has, in a fixed order (bending, density, membrane), without
// those that cannot move it (ParameterWithoutEffect).
std::vector<std::string> MaterialParameterNames(const Material& material);

// Why `name` has no effect on the material and no derivative, or "" when it has: b1 and c1 of a
// linear law with b1 = b2 (κ0 = 0: M = b2 κ, and b1 alone cannot move without making κ0 < 0),
// b2 of one with c1 = 0 (κ0 infinite: M = b1 κ).
// Throws InputError for an unknown name.
std::string ParameterWithoutEffect(const Material& material, const std::string& name);

// The value of `name`. Throws InputError for a name the material does not have, listing the
// names it has.
MaterialParameterValue GetMaterialParameter(const Material& material, const std::string& name);

// The material with `name` set to `si` [SI]; everything else unchanged (a scaled tensile curve
// keeps its shape), except that b2 of a law with b1 = b2 (κ0 = 0, M = b2 κ) moves b1 with it:
// the line's slope. The field is no longer a default. Throws InputError for an unknown name,
// or naming the parameter and value when the material would not be valid (e.g. a law with
// κ0 < 0, a Poisson ratio ≥ 0.5).
Material WithMaterialParameter(const Material& material, const std::string& name, double si);

// The two materials a difference in `name` compares: p ± h (h = relative_step ×
// MaterialParameterScale), or where one side leaves the valid range (a compression ratio of 1,
// a Poisson ratio of 0, c1 = 0 of a law M = b1 κ) that side is p itself, a one-sided
// difference; span is the distance in p between them [SI]. Throws InputError naming the
// parameter when neither side is valid.
struct ParameterStep {
  Material up, down;
  double span = 0.0;
};
ParameterStep DifferenceStep(const Material& material, const std::string& name,
                             double relative_step);

// The parameters of a sensitivity request checked before any work: each known, none twice,
// each able to move the material (ParameterWithoutEffect) and to be differenced
// (DifferenceStep). Throws InputError naming the first problem.
void CheckSensitivityParameters(const Material& material, const std::vector<std::string>& names,
                                double relative_step);

// A step scale for differences in `name` [SI]: |value|, or where the value is 0 (c1 of a
// linear law) the size it takes in the law's curvature range (b1 × 1 cm).
double MaterialParameterScale(const Material& material, const std::string& name);

// The covariance of the `bending` law's {b1, b2, c1} [SI] that a fit wrote into the material
// (fit.covariance_kes, gf·cm and gf·cm²); none, with the reason in *why when given, when the
// material carries none or the fit left a constant undetermined (its b1_sd, b2_sd or c1_sd
// null: the matrix is then a pseudo-inverse without that direction). Throws InputError when it
// is not a symmetric 3×3 matrix of numbers or not positive semi-definite.
std::optional<Eigen::Matrix3d> MaterialFitCovariance(const Material& material,
                                                     std::string* why = nullptr);

// A parameter's uncertainty for the influence tables (docs/methods/sensitivity.md,
// "Uncertainties"): as a relative change Δln p (NaN for a parameter that is 0), the absolute
// change in SI, and where it comes from. `covariance`: MaterialFitCovariance's.
struct ParameterUncertainty {
  double ln = 0.0;
  double si = 0.0;
  std::string source;
};
ParameterUncertainty DefaultParameterUncertainty(const Material& material, const std::string& name,
                                                 const std::optional<Eigen::Matrix3d>& covariance);

// One parameter's influence on a scalar result Q of a simulation (a drape's DC, an ACPM
// crossing length), in Q's unit.
struct ParameterInfluence {
  std::string parameter;  // as the material file names it (a scene's or a seam's input:
                          // input_influence.h)
  double value = 0.0;     // in `unit`
  std::string unit;
  bool defaulted = false;          // a documented default, not a measured value
  double d_q_d_p = 0.0;            // ∂Q/∂p [per SI unit of p; a seam coefficient's per its
                                   // mm unit, as the seam file has it]
  double d_q_d_ln_p = 0.0;         // ∂Q/∂ln p = p ∂Q/∂p
  double uncertainty_ln = 0.0;     // Δp/p of DefaultParameterUncertainty (NaN for p = 0)
  std::string uncertainty_source;  // where Δp comes from
  double change = 0.0;             // |∂Q/∂p| Δp, the first-order change over the uncertainty
};
// The influences, the largest change first, and Q's 1-σ from the fit's covariance of the
// `bending` law's b1, b2, c1: √(gᵀ C g), g = ∂Q/∂{b1, b2, c1}; NaN when the material carries no
// covariance or the three are not all among `parameters`, with the reason in sigma_note.
struct InfluenceTable {
  std::vector<ParameterInfluence> rows;
  double sigma = std::numeric_limits<double>::quiet_NaN();
  std::string sigma_note;
};
// d_q_d_p: ∂Q/∂p for each of `parameters`, in order. Throws InputError for an unknown name or a
// malformed covariance.
InfluenceTable MakeInfluenceTable(const Material& material,
                                  const std::vector<std::string>& parameters,
                                  const std::vector<double>& d_q_d_p);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_MATERIAL_PARAMETERS_H_
