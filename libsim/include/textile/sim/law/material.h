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

#include <nlohmann/json.hpp>

#include "textile/sim/law/bending_law.h"

namespace textile {

// The softest compression a membrane takes (Material::compression_ratio,
// MembraneLame::compression): below it Newton's steps meet a nearly singular Hessian wherever
// a drape compresses the sheet.
constexpr double kMinCompressionRatio = 1e-3;

struct Material {
  std::string name;                          // free text
  double areal_density = 0.0;                // ρ [kg/m²]
  BendingLaw bending = BendingLaw::FromKes(0.1, 0.1, 0.0);  // warp law (or the only law)
  std::optional<BendingLaw> bending_weft;    // weft law, when anisotropic
  double beta = 1.0;                         // linear bending stiffness factor β (section 3.4)
  double stretch_stiffness = 1000.0;  // membrane stiffness [N/m] (docs/spec/physics.md default)
  double poisson = 0.3;                      // Poisson ratio [-]
  // The membrane's stiffness against compression as a fraction of its stretch stiffness [-]
  // (stretch.compression_ratio, kMinCompressionRatio .. 1): 1, the default, is the stabilised
  // StVK of docs/spec/physics.md, as stiff in compression as in tension (membrane.h).
  double compression_ratio = 1.0;
  double friction = 0.3;                     // Coulomb coefficient against supports [-]
  nlohmann::json fit;                        // the `fit` report when a fit made this file
  nlohmann::json extra;                      // "notes"/"assumptions"/"source", carried through

  // False, with "<field>: <problem>" in *why (if non-null), when a value lies outside what a
  // material file accepts (textile_range.h's bounds, the law's own validity): the parser's
  // checks and wording, without the file name, on the numbers MaterialToJson would write.
  //   if (std::string why; !m.Check(&why)) throw InputError("fitted law: " + why);
  bool Check(std::string* why) const;

  // The warp law with β applied (M_β = β M), which every simulation uses.
  BendingLaw EffectiveLaw() const { return bending.Scaled(beta); }
  // The weft law with β applied, or the warp law when the material is isotropic.
  BendingLaw EffectiveWeftLaw() const { return (bending_weft ? *bending_weft : bending).Scaled(beta); }
};

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
