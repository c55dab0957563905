#ifndef TEXTILE_SIM_LAW_MATERIAL_H_
#define TEXTILE_SIM_LAW_MATERIAL_H_

// A fabric as the simulators see it, read from and written to the material JSON of
// docs/spec/cli.md.
//
//   textile::Material m = textile::ReadMaterial("samples/materials/pabst-fig8.json");
//   textile::BendingLaw law = m.EffectiveLaw();   // β applied; SI inside
//   double rho = m.areal_density;                  // [kg/m²]
//
// Files carry lab units ("kes": b in gf·cm, c1 in gf·cm², a spline's κ in 1/cm and M in
// gf·cm/cm; or "si"); areal density in g/m².
// Every problem in a file is an InputError "<file>: <field>: <problem>", one line.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/core/note.h"
#include "textile/sim/law/membrane_law.h"

namespace textile {

// The softest compression a membrane takes (Material::compression_ratio,
// MembraneLame::compression): below it Newton's steps meet a nearly singular Hessian wherever
// a drape compresses the sheet.
constexpr double kMinCompressionRatio = 1e-3;
// The compression ratio a material gets when its file gives none (docs/methods/drapemeter.md,
// "Compression": why this value): a woven sheet buckles at a small fraction of the load it takes
// in tension, and no lab instrument measures it in-plane. 1 is the spec's StVK, as stiff in
// compression as in tension, kept as an option (stretch.compression_ratio, --compression-ratio).
constexpr double kDefaultCompressionRatio = 0.01;
// The largest buckling strain a file takes (stretch.buckling_strain) [-]: 5 %, past any woven
// fabric's crimp (a larger one is a percentage written as a fraction's number).
constexpr double kMaxBucklingStrain = 0.05;

// The isotropic membrane's defaults when its file gives stretch.stiffness_N_per_m or
// stretch.poisson but not both.
constexpr double kDefaultStretchStiffness = 1000.0;  // [N/m]
constexpr double kDefaultPoisson = 0.3;              // [-]

// The orthotropic membrane's defaults (docs/methods/materials.md, "Membrane": a woven apparel
// fabric on KES-FB1 at the standard 500 gf/cm): warp EMT 4 %, weft EMT 6 %, LT 0.65 both,
// shear rigidity G 0.8 gf/cm/deg (45 N/m per radian).
constexpr double kDefaultWarpEmtPercent = 4.0;   // [%]
constexpr double kDefaultWeftEmtPercent = 6.0;   // [%]
constexpr double kDefaultLinearity = 0.65;       // KES LT [-]
constexpr double kDefaultShearKes = 0.8;         // KES G [gf/cm/deg]
// The membrane those constants make (TensileCurveFromKes, KesShearToNewtonPerMetre).
OrthotropicMembrane DefaultOrthotropicMembrane();

struct Material {
  std::string name;                          // free text
  double areal_density = 0.0;                // ρ [kg/m²]
  BendingLaw bending = BendingLaw::FromKes(0.1, 0.1, 0.0);  // warp law (or the only law)
  std::optional<BendingLaw> bending_weft;    // weft law, when anisotropic
  // A measured bias law (a strip cut at 45°), when the lab measured one. The hinge bending
  // blends it with warp and weft by angle (DirectionWeights in bending_law.h); exports and
  // reports carry it (ARCSim's 45° row, the fork's pcb_bending_bias, CLO and Browzwear's bias).
  std::optional<BendingLaw> bending_bias;
  double beta = 1.0;                         // linear bending stiffness factor β (section 3.4)
  // The membrane (docs/methods/materials.md, "Membrane"). Isotropic (stabilised StVK of
  // docs/spec/physics.md) with stretch_stiffness and poisson when the file gives only
  // stretch.stiffness_N_per_m / stretch.poisson; orthotropic (membrane_law.h) when it gives
  // stretch.warp, stretch.weft or stretch.shear, or no membrane at all (documented defaults).
  double stretch_stiffness = kDefaultStretchStiffness;  // isotropic membrane stiffness [N/m]
  double poisson = kDefaultPoisson;                      // isotropic Poisson ratio [-]
  std::optional<OrthotropicMembrane> orthotropic;  // set: the orthotropic membrane
  // The fields the file left out whose documented defaults the membrane uses ("stretch.shear",
  // "stretch.compression_ratio", ...), in file order; each run says so (MaterialDefaultNotes).
  std::vector<std::string> defaulted;
  // The membrane fields the file gave, normalised: "warp", "weft", "shear" as their objects
  // (stiffness_N_per_m beside shear only becomes {"modulus_N_per_m": k} for warp and weft),
  // "compression_ratio", "buckling_strain" as numbers. MaterialToJson writes a given form back
  // as it was read (a KES curve stays its EMT and LT); null for a material built in code, whose
  // curves are written as a modulus (linear) or their knots. Code that replaces
  // orthotropic->warp, ->weft or ->shear_modulus erases the field here.
  nlohmann::json stretch_given;
  // The membrane's stiffness against compression as a fraction of its stretch stiffness [-]
  // (stretch.compression_ratio, kMinCompressionRatio .. 1): 1, the default, is the stabilised
  // StVK of docs/spec/physics.md, as stiff in compression as in tension (membrane.h).
  double compression_ratio = kDefaultCompressionRatio;
  // Strain a yarn takes at full stiffness before buckling (stretch.buckling_strain) [-],
  // 0 .. kMaxBucklingStrain; 0 (the default, not listed in defaulted) buckles at once.
  double buckling_strain = 0.0;
  double friction = 0.3;                     // Coulomb coefficient against supports [-]
  nlohmann::json fit;                        // the `fit` report when a fit made this file
  nlohmann::json extra;                      // "notes"/"assumptions"/"source", carried through

  // False, with "<field>: <problem>" in *why (if non-null), when a value lies outside what a
  // material file accepts (textile_range.h's bounds, the law's own validity): the parser's
  // checks and wording, without the file name, on the numbers MaterialToJson would write.
  //   if (std::string why; !m.Check(&why)) throw InputError("fitted law: " + why);
  bool Check(std::string* why) const;

  MembraneCompression Compression() const { return {compression_ratio, buckling_strain}; }
  // A representative small-strain stretch modulus [N/m]: stretch_stiffness, or the mean of the
  // orthotropic warp and weft curves' small-strain moduli (penalty and friction scales).
  double MembraneModulus() const {
    return orthotropic ? 0.5 * (orthotropic->warp.SmallStrainModulus() +
                                orthotropic->weft.SmallStrainModulus())
                       : stretch_stiffness;
  }

  // True when `field` ("stretch.shear") is listed in defaulted.
  bool IsDefaulted(const std::string& field) const;

  // The warp law with β applied (M_β = β M), which every simulation uses.
  BendingLaw EffectiveLaw() const { return bending.Scaled(beta); }
  // The weft law with β applied, or the warp law when the material is isotropic.
  BendingLaw EffectiveWeftLaw() const { return (bending_weft ? *bending_weft : bending).Scaled(beta); }
  // The measured bias law with β applied; none when the file gives none.
  std::optional<BendingLaw> EffectiveBiasLaw() const {
    return bending_bias ? std::optional<BendingLaw>(bending_bias->Scaled(beta)) : std::nullopt;
  }
  // The effective laws blended for bending at angle phi [rad] to the warp (DirectionWeights).
  BlendedLaw EffectiveLawAt(double phi) const {
    return BlendedLaw(EffectiveLaw(), EffectiveWeftLaw(), EffectiveBiasLaw(), phi);
  }
};

// One note a default the material's membrane uses (code "membrane_default"), naming the field,
// the value and docs/methods/materials.md; none when the file gave every membrane field.
std::vector<Note> MaterialDefaultNotes(const Material& material);

// A material of a law and an areal density [kg/m²] alone, as a file with only
// `areal_density_gsm` and `bending` reads: its membrane the documented defaults, each listed in
// `defaulted` (MaterialDefaultNotes names them in every run; MaterialToJson leaves them out).
// What a fit knows of a fabric; no membrane is claimed that nobody measured.
Material LawOnlyMaterial(const BendingLaw& law, double areal_density);

// Parses material JSON text; `source` names the file in messages. Throws InputError.
Material ParseMaterialJson(const std::string& text, const std::string& source);
// Reads a material file. Throws InputError (unreadable file or any invalid field).
Material ReadMaterial(const std::string& path);
// The material as JSON in the file format, bending constants in KES units.
nlohmann::json MaterialToJson(const Material& material);
// A law as the file format's "bending" object, KES units: {"units": "kes", "b1", "b2", "c1"}, or
// {"units": "kes", "law": "spline", "kappa" [1/cm], "moment" [gf·cm/cm], "moment_sd"} (the
// band only when the law carries one). with_units = false leaves "units" out, for reports
// whose key says the units ("law_kes").
nlohmann::json LawToJson(const BendingLaw& law, bool with_units = true);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_MATERIAL_H_
