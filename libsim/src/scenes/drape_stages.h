#ifndef TEXTILE_SIM_SRC_DRAPE_STAGES_H_
#define TEXTILE_SIM_SRC_DRAPE_STAGES_H_

// The stages of SimulateDrape that carry policy, for tests: the figures over the seeds and the
// trust checks (DrapeResult::notes, one function per check, so that a test can build a result
// and see which code comes out; drape_notes.cc). The others (the scene's meshes, each seed's
// settling and measurement) are drape.cc's own.

#include <optional>
#include <vector>

#include "textile/sim/scenes/drape.h"
#include "textile/sim/solve/cloth_problem.h"
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
// ∂DC/∂p [per SI unit] of one equilibrium x of `problem` (on `triangles`) for each parameter:
// the equilibrium's sensitivity (EquilibriumSensitivity) through the traced outline's area.
std::vector<double> DcDerivatives(ClothProblem* problem, const Vertices& x,
                                  const Triangles& triangles, const Material& material,
                                  const DrapeOptions& options, const DrapeResult& result,
                                  const std::vector<std::string>& parameters);
// result->sensitivities (means over the seeds' derivatives, with each parameter's uncertainty,
// largest dc_change first), drape_coefficient_sigma and sigma_note.
void SummariseSensitivities(const Material& material, const std::vector<std::string>& parameters,
                            const std::vector<std::vector<double>>& seed_derivatives,
                            DrapeResult* result);

}  // namespace textile::drape_internal

#endif  // TEXTILE_SIM_SRC_DRAPE_STAGES_H_
