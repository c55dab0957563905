#ifndef TEXTILE_SIM_SCENES_DRAPE_H_
#define TEXTILE_SIM_SCENES_DRAPE_H_

// The virtual drapemeter (Cusick test; Pabst et al. section 5.2, Fig. 8;
// docs/spec/drapemeter.md): a disk of fabric held on a smaller disk drapes under its own
// weight; the drape coefficient and the folds ("nodes") of its shadow are measured.
//
//   textile::DrapeOptions options;                       // 150 mm specimen, 90 mm support, clamped
//   options.seams = textile::DrapeSeams::kWeft;           // one seam through the centre
//   options.seam_profile = textile::SeamPreset("C-plain");
//   options.seeds = 3;                                    // three handlings of the specimen
//   textile::DrapeResult r = textile::SimulateDrape(material, options);
//   if (!r.converged) throw textile::ComputeError(r.message);   // no DC from such a run
//   std::cout << r.drape_coefficient << " ± " << r.drape_coefficient_sd << ", "
//             << r.nodes << " nodes\n";
//
// Scene. The pattern is meshed by Gmsh (MeshDisk) with the seam lines and the support's circle
// embedded as edge paths, so that the clamp edge is a true circle of the support's radius.
// - clamped (the standard): every vertex within the support circle is held flat at z = 0 (the
//   specimen is held between two disks); the rest hangs.
// - resting (the paper's wording): the specimen lies on Support::Disk (top face z = 0, rounded rim)
//   with penalty contact and Coulomb friction (μ from the material) as a potential from where
//   each node landed (ContactOptions::friction_potential), nothing fixed. Not coarse to fine;
//   the rim extrapolation carries the friction anchors over (ClothProblem::CarryAnchorsFrom).
// Start: flat (resting: drop_height above the support) plus a seeded smooth out-of-plane
// perturbation w(r, θ) = A ((r - R_s) / (R - R_s))² Σ_k c_k cos(k (θ - frame) + φ_k) on the
// overhang, so that folds can form; the static equilibrium is found by Newton (optionally
// coarse → fine, SolveCascadic, which did not pay off here).
//
// Measurement (MeasureShadow): the draped mesh's triangles are projected on the plane z = 0 and
// rasterised on a square grid (cell centres sampled); holes are filled (cells not reachable
// from the grid's border through empty cells count as shadow); the support disk is shadow too
// (its own, as the opaque disk casts it), so r(θ) ≥ R_s; A_shadow = shadow cells × cell area. DC =
// (A_shadow - A_support) / (A_specimen - A_support), with A_specimen the area of the meshed pattern
// (so a flat specimen gives DC = 1 on any mesh) and A_support = π R_s². The outline r(θ) is the
// largest radius of a shadow cell centre in each of `outline_bins` equal angle bins (the shadow is
// star-shaped about the centre in every drape we have seen; a bin that no cell reaches is
// interpolated). Nodes (FindNodes) are the local maxima of r(θ), smoothed by a circular moving
// average, whose topographic prominence reaches the threshold.
//
// Units: SI inside (m, kg, rad); the CLI converts to mm.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/law/material.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/monte_carlo.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/core/note.h"
#include "textile/sim/law/seam.h"
#include "textile/sim/scenes/drape_sensitivity.h"
#include "textile/sim/solve/static_solver.h"

namespace textile {

enum class DrapeMount { kClamped, kResting };
enum class DrapeSeams { kNone, kWeft, kWeftWarp, kShifted };

std::string DrapeMountName(DrapeMount mount);         // "clamped" | "resting"
DrapeMount ParseDrapeMount(const std::string& name);  // InputError naming the value
std::string DrapeSeamsName(DrapeSeams seams);         // "none" | "weft" | "weft+warp" | "shifted"
DrapeSeams ParseDrapeSeams(const std::string& name);  // InputError naming the value

// The relative residual below which a drape's Newton steps try the exact Hessian first
// (SolveOptions::exact_below; DefaultDrapeSolveOptions).
constexpr double kDrapeExactBelow = 10.0;

// The solver settings a drape starts from: Newton + CHOLMOD, relative residual 1e-4 (DC is
// stable to ~1e-4 there; docs/methods/drapemeter.md), 3000 iterations, 600 s.
SolveOptions DefaultDrapeSolveOptions();

struct DrapeOptions {
  double specimen_radius = 0.15;  // R [m] (Cusick, BS 5058, ISO 9073-9)
  double support_radius = 0.09;   // R_s [m], < R, ≥ element_size / 4
  DrapeMount mount = DrapeMount::kClamped;
  // Resting mount: the support disk's thickness and rim rounding [m], the start height of the
  // flat specimen above it [m].
  double support_thickness = 0.005;
  double rim_rounding = 0.001;
  double drop_height = 0.001;
  // Resting mount: the contact penalty, as how far a node sinks into the support under its own
  // weight [m] (ContactOptions::sink_under_own_weight). The rim carries the hanging overhang, many
  // times a node's weight: at 1e-5 the Fig. 8 fabric's skirt sank up to 1 mm into the disk's side
  // and its DC came out about 0.03 low; 1e-6 sank it 0.25 mm, 0.006 low, at twice the steps, but
  // 3 of 15 runs did not settle (their lagged friction forces cycled), so it is not the default
  // (docs/methods/drapemeter.md, "Contact stiffness").
  double contact_sink = 1e-5;

  // Repeated tests: seeds first_seed, first_seed + 1, ...; each seed is one perturbation.
  int seeds = 1;
  unsigned first_seed = 1;
  // Largest out-of-plane perturbation at the rim, A [m]; > 0 (0 would leave a perfectly
  // symmetric start, from which the folds form only by round-off).
  double perturbation = 0.002;
  // The start's overhang is turned down about the support's edge by this angle [rad] (a cone;
  // 0: flat). A start nearer the drape saves Newton iterations; the cone is compressed along
  // its circumference, so the perturbation decides where the folds go, as from flat.
  double start_droop = 0.0;
  // Angular harmonics k = min_harmonic .. max_harmonic, each with a random weight and phase.
  int min_harmonic = 3;
  int max_harmonic = 8;
  // Rotates the seams and the perturbation (not the mesh, not the material axes) about the
  // centre [rad]: DC must not depend on how the mesh sits under them (isotropic fabrics).
  // Any finite angle; used modulo 2π.
  double frame_angle = 0.0;

  // Target edge length of the fine mesh away from seams [m]. The default keeps a single-seed
  // plain drape under 0.5 s (the budget is 5 s). Its DC is low, mostly because of the
  // support's rim (below), little because of the rest of the disk (docs/methods/drapemeter.md).
  double element_size = 0.012;
  // The support's rim, where the overhang turns down over the length RimTurnDownLength (8.6 mm
  // for the Fig. 8 fabric). A mesh of element_size there folds along the clamp's edges too
  // cheaply, and the DC comes out low, by about 0.1 × element / turn-down length for a plain
  // fabric (docs/methods/drapemeter.md, "Resolution at the rim"). Edges are at most rim_element_size [m]
  // from one such element inside the support to rim_band [m] beyond its edge, growing by half the
  // distance past that; 0: no band (the default, for run time).
  double rim_element_size = 0.0;
  double rim_band = 0.02;
  // Rim extrapolation (clamped mount, rim_element_size > 0, rim_band ≥ rim_element_size;
  // docs/methods/drapemeter.md, "Extrapolated DC"): after each seed's solve, the triangles of the rim
  // band are split in four (RefineTriangles), the equilibrium is carried over (the same
  // surface, the same folds) and solved again. The DC converges from below at an order between
  // 1 and 2 in the rim element (measured on three nested levels), so the converged value lies
  // near the bracket [DC_split, 2 DC_split − DC_base] (within it, or up to 0.001 beyond for
  // orders near 1): the DC reported is its middle, DC_split + (DC_split − DC_base)/2, and the
  // bound its half-width.
  bool rim_extrapolation = false;
  // rim_element_size is AutoRimElementSize's (`--rim-mm auto`, ChooseDrapeRim): the result's
  // notes then say when its vertex cap decided (rim_auto_capped).
  bool rim_auto = false;
  // Coarse → fine: solve on a mesh coarse_factor × element_size first and prolong (cascadic).
  // Off by default: the folds of the coarse solution are not the fine mesh's, and the fine level
  // spent more Newton steps re-folding than a cold start needs (8 mm: 236 steps and 13 CPU s
  // against 138 and 7 s; docs/methods/drapemeter.md).
  bool coarse_to_fine = false;
  double coarse_factor = 2.0;
  // Points on the embedded support circle (also on the coarse mesh).
  int circle_segments = 0;  // 0: about one per element_size along the circle

  DrapeSeams seams = DrapeSeams::kNone;
  // The seam type (Table 2 preset or a fitted file) of every seam.
  SeamProfile seam_profile = SeamPreset("C-plain");
  // The shifted seam runs parallel to the weft seam, this far from the centre [m];
  // |seam_shift| ≤ MaxSeamShift (one element inside the edge).
  double seam_shift = 0.05;
  // Section 4.3 refinement near seams (element area / ⌈S(d)⌉), applied within this distance of
  // the seam lines (not of the support circle) [m]; 0 (the default) turns it off: at h = 12 mm
  // 20 mm of it (C-plain: ⌈S⌉ = 10 at the seam) moved the weft and weft + warp DCs by at most
  // 0.003 at 1.4-1.7× the vertices and up to 2.3× the time (docs/methods/drapemeter.md, "Seam
  // refinement"). Any range > 0 refines the seam line itself (d = 0 there).
  double seam_refinement_range = 0.0;

  // Newton by default; tolerance on the residual relative to the weight.
  SolveOptions solver = DefaultDrapeSolveOptions();

  // Measurement.
  double raster_cell = 0.0005;  // shadow grid cell [m]
  int outline_bins = 360;       // angle bins of r(θ)
  int smoothing_bins = 5;       // circular moving average before node detection (odd, ≥ 1)
  // A node's prominence must reach max(node_prominence, node_prominence_relative × (max r - min
  // r)).
  double node_prominence = 0.003;          // [m]
  double node_prominence_relative = 0.15;  // [-]

  // Called with one line of progress (meshing, each seed's outcome); may be empty.
  std::function<void(const std::string&)> progress;

  // Sensitivities (drape_sensitivity.h, docs/methods/sensitivity.md): the DC's derivative for
  // each of sensitivity_parameters (empty: every parameter of the material,
  // MaterialParameterNames), its influence and the DC's 1-σ. Clamped mount only.
  bool sensitivity = false;
  std::vector<std::string> sensitivity_parameters;
  // Monte Carlo check of the σ (law/monte_carlo.h, docs/methods/sensitivity.md): this many
  // materials drawn from the fit's covariance of b1, b2, c1 (0: none; else ≥ 2), each draped
  // for every seed from that seed's equilibrium, so on its branch, as the linear σ assumes.
  // Implies sensitivity (the linear σ beside it). Needs a material with a fit covariance.
  int monte_carlo_samples = 0;
  unsigned monte_carlo_seed = 1;

  // False with "<field>: <problem>" when a field is out of range.
  bool Check(std::string* why) const;
};

// The start's harmonics as "MIN-MAX" ("3-8"), 1 ≤ MIN ≤ MAX ≤ 64, into o->min_harmonic and
// o->max_harmonic. InputError naming the text.
void ParseStartModes(const std::string& text, DrapeOptions* o);

// The shadow of a draped specimen: a raster mask and the polar outline.
struct DrapeShadow {
  double area = 0.0;                      // A_shadow, holes filled [m²]
  double cell = 0.0;                      // raster cell [m]
  double origin_x = 0.0, origin_y = 0.0;  // centre of cell (0, 0) [m]
  int width = 0, height = 0;              // cells
  std::vector<std::uint8_t> mask;         // height × width, row-major (row = y), 1 = shadow
  Eigen::VectorXd angles;                 // #B bin centres θ_b ∈ [0, 2π) [rad]
  Eigen::VectorXd radii;                  // #B outline radius r(θ_b) [m]
  // Support cells no fabric covers (a specimen that left the disk's top) × cell area [m²]; 0
  // without a support radius.
  double bare_support_area = 0.0;
};

// Projects the triangles of x (#V×3 [m]; triangles #F×3) on z = 0 and measures the shadow
// about the origin, with the support's own shadow (a disk of support_radius [m] about the
// origin; 0: none) added as the drapemeter's opaque disk casts it. cell [m] > 0, bins ≥ 8.
// Throws InputError for bad sizes or non-finite x.
DrapeShadow MeasureShadow(const Vertices& x, const Triangles& triangles, double cell, int bins,
                          double support_radius = 0.0);

struct DrapeNodes {
  std::vector<double> angles;       // [rad], ascending
  std::vector<double> radii;        // outline radius at each node [m]
  std::vector<double> prominences;  // [m]
};
// Local maxima of the circular signal radii (#B, uniform bins from angle 0) after a circular
// moving average over `smoothing_bins`, with prominence ≥ max(min_prominence,
// relative × (max - min)). A constant signal has no nodes.
DrapeNodes FindNodes(const Eigen::VectorXd& radii, int smoothing_bins, double min_prominence,
                     double relative_prominence);

// (A_shadow - A_support) / (A_specimen - A_support); InputError unless A_specimen > A_support > 0.
double DrapeCoefficient(double shadow_area, double specimen_area, double support_area);

// One seed's drape.
struct DrapeSeedResult {
  unsigned seed = 0;
  bool converged = false;
  SolveSummary summary;            // fine level (with coarse figures when cascadic)
  double drape_coefficient = 0.0;  // NaN unless converged
  DrapeShadow shadow;              // empty unless converged
  DrapeNodes nodes;                // empty unless converged
  double min_radius = 0.0, max_radius = 0.0, mean_radius = 0.0;  // of the outline [m]
  Vertices positions;  // #V×3 final state [m] (also when not converged)
  // Resting mount: how deep the deepest node lies inside the support [m] (0 clamped, or when
  // not converged); the penalty's sink under the rim's load (contact_sink).
  double max_penetration = 0.0;
  // Rim extrapolation only (else NaN / empty): the DC of the base mesh and of the split one,
  // and the bound (DC_split − DC_base)/2 on the extrapolated drape_coefficient above; shadow,
  // nodes, radii and positions are the split mesh's (positions: the base state carried over
  // when the base solve failed). summary is the base mesh's solve, split_summary the split's.
  double base_drape_coefficient = 0.0, split_drape_coefficient = 0.0;
  double extrapolation_bound = 0.0;
  // The split rim's DC is below the base's: the bracket is reversed, against the convergence
  // from below that the extrapolation assumes (ExtrapolateRim).
  bool extrapolation_reversed = false;
  SolveSummary split_summary;
};

// The rim extrapolation's figures from the base mesh's DC and the split one's
// (docs/methods/drapemeter.md, "Extrapolated DC"): the middle of the bracket [DC_split,
// 2 DC_split − DC_base] (DC_split + Δ/2, Δ = DC_split − DC_base), the bound |Δ|/2 (≥ 0), and
// whether Δ < 0 (reversed: the DC fell as the rim was refined, which the method does not
// expect; the figures are still the bracket's).
struct RimExtrapolation {
  double drape_coefficient = 0.0;
  double bound = 0.0;
  bool reversed = false;
};
RimExtrapolation ExtrapolateRim(double base_dc, double split_dc);

struct DrapeResult {
  bool converged = false;  // every seed converged; otherwise no figure below is meaningful
  std::string message;     // why not (the first failing seed), or "converged"
  // Over the seeds (sd: sample standard deviation, 0 for a single seed); NaN unless converged.
  double drape_coefficient = 0.0, drape_coefficient_sd = 0.0;
  double nodes = 0.0, nodes_sd = 0.0;
  double mean_radius = 0.0, min_radius = 0.0, max_radius = 0.0;           // means over seeds [m]
  double mean_radius_sd = 0.0, min_radius_sd = 0.0, max_radius_sd = 0.0;  // their sample sd [m]
  std::vector<DrapeSeedResult> per_seed;
  TriangleMesh mesh;                         // the fine pattern (rest, z = 0); split at the rim
                                             // with rim_extrapolation
  int base_vertices = 0;                     // before the rim's split (= mesh's without it)
  std::vector<std::vector<int>> seam_paths;  // vertex ids along each seam of the scene
  std::vector<SeamLine> seam_lines;          // the seams of the scene [m]
  int coarse_vertices = 0;                   // 0 without coarse → fine
  double specimen_area = 0.0;                // meshed pattern area [m²]
  double support_area = 0.0;                 // π R_s² [m²]
  double mass = 0.0;                         // total mass incl. seam bands [kg]
  double rim_turn_down = 0.0;                // RimTurnDownLength of the scene [m]
  double seconds = 0.0;                      // wall time, meshing included [s]
  // What to know before trusting the DC, in this order (docs/methods/drapemeter.md):
  //   rim_shortfall      clamped, no extrapolation: the rim's elements are coarse against the
  //                      turn-down length (first-order shortfall 0.1 e/ℓ over 0.02)
  //   rim_auto_capped    rim_auto: the vertex cap, not ℓ, chose the rim's elements
  //   bare_support       the fabric left over 2 % of the support's top bare
  //   skirt_sink         resting: the skirt sank over 0.3 mm into the support
  //   reversed_bracket   rim extrapolation: a seed's split rim gave a lower DC than its base
  //   scene_radii_skipped  sensitivities with shifted seams: none in the scene's radii
  std::vector<Note> notes;
  // With options.sensitivity (and converged): each parameter's influence, the largest
  // dc_change first; the DC's 1-σ from the fit's covariance of the bending law's b1, b2, c1
  // (NaN when the material carries none, sigma_note saying so).
  std::vector<ParameterInfluence> sensitivities;  // Q = the DC
  // With options.sensitivity (not only implied by monte_carlo_samples) and no
  // sensitivity_parameters (and converged): the DC's derivatives in the scene's radii,
  // "specimen_radius" then "support_radius" (value and uncertainty in mm;
  // docs/methods/sensitivity.md, "Scene radii"). Not in the σ. Empty with shifted seams (a note
  // says why).
  std::vector<ParameterInfluence> scene_sensitivities;
  // With options.sensitivity (not only implied), no sensitivity_parameters and seams (and
  // converged): the DC's derivatives in the seam profile's coefficients of B_f(d) =
  // a2 d² + a1 d + a0 (d in mm), "seam.a2", "seam.a1", "seam.a0" (value and unit as the seam
  // file has them, 1/mm², 1/mm, -), then "seam.scale", B_f scaled as a whole (value 1), with
  // the seam file's covariance or a default ±10 % (docs/methods/sensitivity.md, "Seam
  // coefficients"). Not in the σ.
  std::vector<ParameterInfluence> seam_sensitivities;
  double drape_coefficient_sigma = std::numeric_limits<double>::quiet_NaN();
  std::string sigma_note;
  // Wall time of the sensitivities, all seeds and equilibria: factorisations, the parameters'
  // differences and back-substitutions, the outlines [s].
  double sensitivity_seconds = 0.0;
  int sensitivity_equilibria = 0;  // equilibria differentiated (two a seed with a split rim)
  // The part of sensitivity_seconds spent on the scene's radii and the seam's coefficients
  // (their rest and seam changes, one force difference each) [s].
  double scene_sensitivity_seconds = 0.0;
  // With options.monte_carlo_samples (and converged): the DC's spread over the samples (each
  // the mean over the seeds), beside the linear σ; monte_carlo_node_changes samples whose node
  // count differed from the nominal drape's for some seed (another branch).
  std::optional<MonteCarloSpread> monte_carlo;
  int monte_carlo_node_changes = 0;
};

// The largest |seam_shift| [m] a shifted seam may have: one element (element_size) inside the
// specimen's edge (closer, the chord is too short and too near the rim for the mesher).
double MaxSeamShift(const DrapeOptions& options);

// The seam lines of a configuration [m] (frame_angle applied).
std::vector<SeamLine> DrapeSeamLines(const DrapeOptions& options);

// ℓ = sqrt(B / (ρ g (R − R_s))) [m]: the length over which the overhang turns down at the rim,
// the boundary layer of a strip of stiffness B [N·m] clamped flat and pulled down by the weight
// of the hanging overhang (ρ g (R − R_s) [N/m]); B is the smallest initial or ultimate stiffness
// of the warp, weft and bias laws (β applied). The DC's shortfall scales with the rim's element size
// over ℓ (docs/methods/drapemeter.md, "Resolution at the rim"); `--rim-mm auto` meshes the rim with
// ℓ/3. Throws InputError for a material without a density or a specimen not larger than the
// support.
double RimTurnDownLength(const Material& material, const DrapeOptions& options);

// The rim element size of `--rim-mm auto` [m]: ℓ/2 for a rim extrapolation (the split halves
// it), else ℓ/3 (docs/methods/drapemeter.md, "Extrapolated DC"); at least 0.5 mm, and at least the
// size that keeps the rim band (support radius to rim_band past it) under about
// kAutoRimMaxVertices vertices (a limp fabric asks for far more; *capped, when given, says
// whether this bound decided); at most options.element_size. Throws as RimTurnDownLength.
inline constexpr double kAutoRimMaxVertices = 10000.0;
double AutoRimElementSize(const Material& material, const DrapeOptions& options, bool extrapolate,
                          bool* capped = nullptr);

// How a caller asks for the rim extrapolation (`--extrapolate`, `--no-extrapolate` or neither).
enum class DrapeExtrapolation { kDefault, kOn, kOff };

// Settles the rim of a run in *options: rim_extrapolation (kDefault: wherever it applies, a
// clamped specimen with a rim band at least one rim element wide; docs/methods/drapemeter.md,
// "Extrapolated DC") and, with rim_auto, rim_element_size = AutoRimElementSize (ℓ/2 when
// extrapolating, else ℓ/3) and options->rim_auto. Throws as RimTurnDownLength; does not Check
// the options it leaves.
void ChooseDrapeRim(const Material& material, bool rim_auto, DrapeExtrapolation extrapolation,
                    DrapeOptions* options);

// Runs the drapemeter. Throws InputError for bad options or material (a specimen not larger
// than the support, ...) and ComputeError when meshing fails; a solve that does not converge is
// reported in the result (converged = false), never as a DC. The result's notes say what
// to check before trusting the DC.
DrapeResult SimulateDrape(const Material& material, const DrapeOptions& options);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_H_
