#ifndef TEXTILE_SIM_EXCHANGE_MATERIAL_EXPORT_H_
#define TEXTILE_SIM_EXCHANGE_MATERIAL_EXPORT_H_

// A material file in the formats other tools read (docs/guide/export.md): ARCSim's material
// JSON (and ClothDrapeTester's principal-curvature keys), a physics-only U3M 1.1 file, and a
// CSV of one row a direction (warp, weft, bias) with the numbers a lab report prints.
//
//   textile::Material m = textile::ReadMaterial("samples/expected/pabst-fig8.fitted.json");
//   textile::ExportedMaterial e = textile::ExportMaterial(m, textile::ExportFormat::kArcsim, {});
//   // e.text: the file; e.notes: what the format could not carry, and how it was written.
//
// Directions follow the material: pattern x (ARCSim's material u axis) is the warp. The warp
// law is the bending of a warp strip, curvature along the warp, so a hinge whose edge runs along
// the weft bends with it (docs/methods/materials.md, "Warp, weft and bias"). The bias is the
// material's measured bias law where it has one (bending_bias), else the 45° blend of warp and
// weft. Every format gets the laws with β applied: what the simulators use.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "textile/sim/core/note.h"
#include "textile/sim/law/material.h"

namespace textile {

enum class ExportFormat { kArcsim, kU3m, kCsv };

// "arcsim", "u3m", "csv" -> the format; throws InputError naming the three otherwise.
ExportFormat ParseExportFormat(const std::string& name);

struct ExportOptions {
  // U3M material.created and .modified, ISO 8601 UTC ("2026-12-07T08:00:00Z"); empty: the time
  // of SOURCE_DATE_EPOCH when that is set (reproducible outputs), else now (ExportTimestamp).
  std::string timestamp;
  // U3M physics.thickness [mm]; none: null (no cantilever measures it).
  std::optional<double> thickness_mm;
  // Fail (InputError naming the fields) where a block would otherwise be left out with a note:
  // ARCSim's stretching of a membrane the material leaves to defaults.
  bool strict = false;
  // Who wrote the file, for U3M's custom.textile.producer ("textile 0.3.0"); empty: left out.
  std::string producer;
};

struct ExportedMaterial {
  std::string text;         // the whole file, newline-terminated
  std::vector<Note> notes;  // what the format cannot carry or carries approximately
};

// The material in `format`. Throws InputError for a material the format cannot express (named
// field: U3M without a name; --strict and a defaulted membrane) or a thickness that is not a
// finite number > 0. Deterministic: the same material and options give the same bytes.
ExportedMaterial ExportMaterial(const Material& material, ExportFormat format,
                                const ExportOptions& options);

// The pieces, for tests and library users.

// ARCSim's bending table. dde.cpp reads column j at α = 5 j /m (its comment: "samples are per
// 0.05 cm^-1"), where α = θ l / (2 (A₀ + A₁)) is half the hinge curvature κ = θ / h̄ of Pabst
// eq. 2; physics.cpp's hinge energy is ke l² θ² / (8 (A₀ + A₁)), a quarter of Pabst's ½ B κ² A
// for ke = B, and its moment ke κ / 4. The hinge ARCSim builds from the table bends as the law
// when column j holds ke_j = 4 M(κ_j) / κ_j at κ_j = 2 α_j = 10 j /m (4 B(0) at j = 0).
constexpr std::array<double, 5> kArcsimBendingAlpha = {0.0, 5.0, 10.0, 15.0, 20.0};  // [1/m]
constexpr double kArcsimCurvaturePerAlpha = 2.0;    // κ = 2 α
constexpr double kArcsimStiffnessPerSecant = 4.0;  // ke = 4 M(κ) / κ

// The secant stiffness M(κ)/κ [N·m] of a law, B(0) at κ = 0.
double SecantStiffness(const BendingLaw& law, double kappa);
double SecantStiffness(const BlendedLaw& law, double kappa);

// ClothDrapeTester's pcb_bending_*: M(κ) = k1 κ + k2 κ² [N·m, N·m²]. A Pabst law's quadratic
// branch exactly ({b1, c1}; {b2, 0} when κ0 = 0); a spline the quadratic of least relative error on
// 0..κ_fit, with the largest relative moment error there in *max_relative_error.
struct QuadraticBending {
  double k1 = 0.0;  // [N·m]
  double k2 = 0.0;  // [N·m²]
  double max_relative_error = 0.0;  // on 0 < κ ≤ kappa_fit; 0 where exact
  double kappa_fit = 0.0;           // [1/m]; +∞ where exact for every κ
};
QuadraticBending PcbBending(const BendingLaw& law);

// The bias law (45°): M = ½ (M_warp + M_weft) (BlendedLaw at π/4), as a monotone spline
// through 41 knots on 0.01-1000 /m (its moment within 1e-4 relative); the warp law itself when
// the material has no weft law.
BendingLaw BiasLaw(const Material& material);

// Small-strain uniaxial moduli of the membrane [N/m] when the file gave it (not defaulted):
// warp, weft and 45° (4 / (1/E_warp + 1/E_weft + 1/G) for the orthotropic membrane, the
// stiffness for the isotropic one) and the shear modulus; none otherwise.
struct MembraneModuli {
  double warp = 0.0, weft = 0.0, bias = 0.0, shear = 0.0;  // [N/m]
};
std::optional<MembraneModuli> MeasuredMembraneModuli(const Material& material);

// A UUID version 4 string whose 122 free bits come from a hash of `content`: the same material
// exports with the same id.
std::string ContentUuid4(const std::string& content);

// options.timestamp's default: SOURCE_DATE_EPOCH (seconds) when set and valid, else now, as
// ISO 8601 UTC. Throws InputError for a SOURCE_DATE_EPOCH that is not a whole number ≥ 0.
std::string ExportTimestamp();

}  // namespace textile

#endif  // TEXTILE_SIM_EXCHANGE_MATERIAL_EXPORT_H_
