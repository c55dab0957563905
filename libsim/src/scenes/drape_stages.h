#ifndef TEXTILE_SIM_SRC_DRAPE_STAGES_H_
#define TEXTILE_SIM_SRC_DRAPE_STAGES_H_

// The stages of SimulateDrape that carry policy, for tests: the figures over the seeds and the
// trust checks (DrapeResult::notes, one function per check, so that a test can build a result
// and see which code comes out; drape_notes.cc). The others (the scene's meshes, each seed's
// settling and measurement) are drape.cc's own.

#include <optional>
#include <vector>

#include "textile/sim/law/input_influence.h"
#include "textile/sim/scenes/drape.h"
#include "textile/sim/solve/cloth_problem.h"
#include "textile/sim/solve/static_solver.h"
#include "textile/sim/core/note.h"

namespace textile::drape_internal {

// rim_shortfall: clamped without extrapolation, the first-order shortfall 0.1 e/ℓ of the rim's
// element e against the turn-down length ℓ (result.rim_turn_down) is over 0.02.
std::optional<Note> RimShortfallNote(const DrapeOptions& options, const DrapeResult& result);
// rim_auto_capped: `--rim-mm auto`'s vertex cap chose the rim's elements (rim_capped, from
// AutoRimElementSize).
std::optional<Note> RimAutoCappedNote(const DrapeOptions& options, const DrapeResult& result,
                                      bool rim_capped);
// bare_support: a seed's fabric left over 2 % of the support's top bare.
std::optional<Note> BareSupportNote(const DrapeResult& result);
// skirt_sink: a seed's skirt sank over 0.3 mm into the support (resting contact's penalty).
std::optional<Note> SkirtSinkNote(const DrapeOptions& options, const DrapeResult& result);
// reversed_bracket: a seed's split rim gave a lower DC than its base mesh.
std::optional<Note> ReversedBracketNote(const DrapeResult& result);

// scene_radii_skipped: every parameter's sensitivity asked for with shifted seams, which leave
// the scene's radii out (TakesSceneRadii).
std::optional<Note> SceneRadiiSkippedNote(const DrapeOptions& options, const DrapeResult& result);

// All of them, in the order above (DrapeResult::notes).
std::vector<Note> DrapeNotes(const DrapeOptions& options, const DrapeResult& result,
                             bool rim_capped);

// Over the converged seeds of result->per_seed: converged (all of them), message ("converged",
// else cleared for the caller's) and the means and sample sds (NaN unless converged).
void SummariseSeeds(DrapeResult* result);

// The shadow's stages after rasterising (MeasureShadow; also MeasureDrapeShadow for measured
// drapes): the support's own disk of support_radius [m] about the grid's origin added (> 0;
// the bare support cells counted in bare_support_area); holes filled (empty cells not reached
// from the border marked 2); the mask made 0/1 with the area and each of `bins` angle bins'
// largest radius (-1 where no cell falls); empty bins interpolated circularly.
void AddSupportShadow(double support_radius, DrapeShadow* shadow);
void FloodFromBorder(DrapeShadow* shadow);
void MeasureOutline(int bins, DrapeShadow* shadow);
void FillEmptyBins(Eigen::VectorXd* radii);

// Sensitivities (drape_sensitivity.cc). The parameters options.sensitivity asks for (every
// parameter of the material when none is named; none without sensitivity), each checked, and the
// material's fit covariance checked: InputError before any work.
std::vector<std::string> SensitivityParameters(const Material& material,
                                               const DrapeOptions& options);
// The seams of `options`' scene: DrapeSeamLines, each with options.seam_profile.
std::vector<Seam> DrapeSeamList(const DrapeOptions& options);

// Whether the run takes the scene's own inputs (the radii, the seam's coefficients) as
// parameters too: sensitivity asked for (not implied by Monte Carlo) for every parameter (no
// list).
bool TakesSceneParameters(const DrapeOptions& options);
// The scene's radii as parameters (docs/methods/sensitivity.md, "Scene radii"), in this order.
enum class SceneRadius { kSpecimen, kSupport };
constexpr int kSceneRadii = 2;
// Whether the run takes them: TakesSceneParameters, seams none or through the centre (a radial
// morph would bend shifted ones).
bool TakesSceneRadii(const DrapeOptions& options);
// The seam profile's coefficients a2, a1, a0 as parameters (docs/methods/sensitivity.md, "Seam
// coefficients"): TakesSceneParameters, with seams.
bool TakesSeamCoefficients(const DrapeOptions& options);
// The scene's inputs a run takes (the two above), the seam's coefficient steps checked
// (CheckSeamCoefficientSteps: InputError before any work).
struct SceneInputs {
  bool radii = false;
  bool seam = false;
};
SceneInputs TakenSceneInputs(const DrapeOptions& options);
// The rest disk's radial morph that moves one radius by a metre and keeps the other (#V×3
// [m/m], z 0): u(r) r̂ with, R_s the support's radius and R the specimen's,
//   specimen: u = 0 within R_s, (r − R_s)/(R − R_s) beyond;
//   support:  u = r/R_s within R_s, (R − r)/(R − R_s) beyond.
// Diameters stay straight; the clamp's vertices move with the support's radius only.
Vertices RadiusMorph(const TriangleMesh& rest, SceneRadius which, const DrapeOptions& options);

// For tests of the radii's and the seam coefficients' derivatives: the equilibrium of
// `options`' scene (its first seed's problem; one clamped equilibrium: InputError otherwise)
// with the fine mesh morphed by t·RadiusMorph [m] instead of meshed anew (shifted seams, which
// the morph would bend: t = 0 only), and with the seams of `seam_profile` when given (on the
// mesh refined for options.seam_profile), solved from `start` (an equilibrium of the nominal
// mesh) carried along: the same branch. The morphed mesh and the moved support's radius too.
struct MorphedSeed {
  TriangleMesh mesh;
  double support_radius = 0.0;
  Vertices positions;
  SolveSummary summary;
};
MorphedSeed SolveMorphedSeed(const Material& material, const DrapeOptions& options,
                             SceneRadius which, double t, const Vertices& start,
                             const SeamProfile* seam_profile = nullptr);

// ∂DC/∂p of one equilibrium x of `problem`: `material` for each parameter [per SI unit]; with
// scene.radii for each SceneRadius [per m], with scene.seam for each seam coefficient a2, a1,
// a0 [per 1/mm², 1/mm, 1] (else empty). Through the
// traced outline's area and its adjoint (EquilibriumSensitivity), with the specimen's and the
// support's areas' own changes in DC = (A_shadow − A_support) / (A_specimen − A_support).
// scene_seconds: the wall time of the radii and the coefficients [s].
struct DcDerivativeSet {
  std::vector<double> material;
  std::vector<double> radii;
  std::vector<double> seam;
  double scene_seconds = 0.0;
};
DcDerivativeSet DcDerivatives(ClothProblem* problem, const Vertices& x,
                              const Material& material, const DrapeOptions& options,
                              const DrapeResult& result, const std::vector<std::string>& parameters,
                              SceneInputs scene);
// result->sensitivities (means over the seeds' derivatives, with each parameter's uncertainty,
// largest dc_change first), drape_coefficient_sigma and sigma_note; result->scene_sensitivities
// when the seeds carry radii, result->seam_sensitivities when they carry seam coefficients.
void SummariseSensitivities(const Material& material, const std::vector<std::string>& parameters,
                            const std::vector<DcDerivativeSet>& seed_derivatives,
                            const DrapeOptions& options, DrapeResult* result);

}  // namespace textile::drape_internal

#endif  // TEXTILE_SIM_SRC_DRAPE_STAGES_H_
