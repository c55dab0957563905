#ifndef TEXTILE_SIM_SCENES_DRAPE_COMPARE_H_
#define TEXTILE_SIM_SCENES_DRAPE_COMPARE_H_

// A simulated drape against a measured one (`textile drape --compare MEASURED.json`): the drape
// coefficients, the node counts and the outlines r(θ), with a verdict on stated tolerances
// (docs/guide/drape.md, "Compared with a measured drape").
//
//   textile::MeasuredDrape measured = textile::ParseMeasuredDrapeJson(text, "m.json");
//   textile::CheckDrapesComparable(measured, drape_options);   // before simulating
//   textile::DrapeResult r = textile::SimulateDrape(material, drape_options);
//   textile::DrapeCompareOptions o;                             // |ΔDC| ≤ 0.03, nodes ± 1
//   textile::DrapeComparison c = textile::CompareDrapes(r, measured, o);
//   std::cout << c.Verdict() << ": " << textile::JoinNoteTexts(c.notes, "; ") << "\n";
//
// Verdict. The DC agrees when |DC_simulated − DC_measured| ≤ dc_tolerance; the seeds' sd does
// not widen it (a noisier simulation must not pass more easily; a note says when the sd is
// large against the tolerance). The nodes agree when |mean simulated count − measured count| ≤
// node_tolerance. The outline (the radius RMS after the best rotation, mean over the seeds) is
// judged only when outline_tolerance > 0: where the folds fall depends on the handling as much
// as on the fabric, and no tolerance follows from one measurement. The verdict passes when every
// judged part does.
//
// Definitions. The measured DC divides by π R² (the specimen as cut); the simulated one by the
// meshed pattern's area, a polygon about 0.1 % smaller (h = 12 mm), whose shadow is smaller
// by about as much, so that its ratio estimates the true disk's DC. The comparison keeps the
// simulated DC as it is and also reports simulated_dc_pi_r2, the same shadows over π R² (what
// `drape-measure` of the drape's own mesh gives): about 0.001 lower.
//
// Units: SI inside (m, rad).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"
#include "textile/sim/scenes/drape.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile {

struct DrapeCompareOptions {
  double dc_tolerance = 0.03;      // largest |DC_simulated − DC_measured| that agrees, (0, 1]
  double node_tolerance = 1.0;     // largest |mean simulated nodes − measured nodes|, [0, 100]
  double outline_tolerance = 0.0;  // largest mean outline RMS after rotation [m]; 0: not judged

  // False with "<field>: <problem>" when a field is out of range.
  bool Check(std::string* why) const;
};

// How one outline lies on another, both r(θ) on uniform bins from 0 (bin b's centre at
// (b + ½) 2π / #B).
struct OutlineAlignment {
  // The measured outline turned counterclockwise by this angle lies closest to the simulated
  // one: r_m(θ − rotation) ≈ r_s(θ); in (−π, π] [rad].
  double rotation = 0.0;
  double rms = 0.0;            // radius RMS at that rotation [m]
  double rms_unrotated = 0.0;  // radius RMS as measured (rotation 0) [m]
  Eigen::VectorXd aligned;     // #B_s: r_m(θ_b − rotation) on the simulated bins [m]
};

// r(θ) (#B ≥ 1, uniform bins from 0) at the centres of `bins` uniform bins, by circular linear
// interpolation (the same values when bins = #B).
Eigen::VectorXd ResampleOutline(const Eigen::VectorXd& radii, int bins);

// The rotation of `measured` (any #B_m ≥ 8, resampled to #B_s first) that minimises the radius
// RMS against `simulated` (#B_s ≥ 8): every whole-bin shift (above 1440 bins, every
// ⌊#B_s/720⌋-th one, then the neighbours of the best), then the exact minimum of the RMS
// between the best shift and either neighbour, where the interpolated outline's squared error
// is a quadratic in the fraction of a bin. Throws InputError for fewer than 8 bins.
OutlineAlignment AlignOutlines(const Eigen::VectorXd& simulated, const Eigen::VectorXd& measured);

// One seed of the simulation against the measured drape.
struct DrapeSeedComparison {
  unsigned seed = 0;
  double drape_coefficient = 0.0;  // the seed's, as simulated
  int nodes = 0;
  OutlineAlignment outline;  // the measured outline on this seed's bins
};

struct DrapeComparison {
  std::string measured_source;  // what the measured drape was measured from
  double measured_dc = 0.0;
  double simulated_dc = 0.0, simulated_dc_sd = 0.0;  // the result's (meshed pattern's area)
  double simulated_dc_pi_r2 = 0.0;                   // the same shadows over π R²
  double dc_difference = 0.0;                        // simulated − measured
  double dc_tolerance = 0.0;
  bool dc_ok = false;

  int measured_nodes = 0;
  double simulated_nodes = 0.0, simulated_nodes_sd = 0.0;  // mean and sample sd over the seeds
  double node_tolerance = 0.0;
  bool nodes_ok = false;

  // Over the seeds: the mean RMS after each seed's best rotation and its sample sd, the mean
  // RMS without rotation [m]; best_rotation is the first seed's [rad] (the seed of the outline
  // CSV and the picture; each seed's folds sit elsewhere).
  double outline_rms = 0.0, outline_rms_sd = 0.0, outline_rms_unrotated = 0.0;
  double best_rotation = 0.0;
  double outline_tolerance = 0.0;  // [m]; 0: not judged
  bool outline_judged = false;
  bool outline_ok = true;  // true when not judged

  std::vector<DrapeSeedComparison> per_seed;
  bool pass = false;  // every judged part agrees
  // Why a part failed, and what to know about the verdict:
  //   dc_differs         |ΔDC| beyond the tolerance ("the simulation drapes less than measured")
  //   nodes_differ       the node counts beyond theirs
  //   outline_differs    the outline RMS beyond its tolerance (when judged)
  //   seed_spread        the seeds' DC sd is over half the DC tolerance
  //   single_seed        one seed: no spread to judge the simulated figures by
  //   simulated_dc_low   the drape's own notes say its DC may be low (rim_shortfall)
  std::vector<Note> notes;

  std::string Verdict() const { return pass ? "pass" : "fail"; }
  // The failed parts' notes (dc_differs, nodes_differ, outline_differs) joined by "; "; "" when
  // the verdict passes.
  std::string FailureReason() const;
};

// Throws InputError "measured with a <R> mm specimen on a <R_s> mm support; the simulation's is
// <R'> mm on <R_s'> mm: ..." when the measured drape's specimen or support radius differs from
// the options' by more than 0.01 mm (the radii are the flags' values, not measured ones).
void CheckDrapesComparable(const MeasuredDrape& measured, const DrapeOptions& options);

// The comparison (see the top of this file). The simulation's radii are its pattern's: R the
// outermost vertex's radius, R_s from support_area. Throws ComputeError for a result that did
// not converge, InputError for options that fail Check or radii that differ
// (CheckDrapesComparable's message).
DrapeComparison CompareDrapes(const DrapeResult& simulated, const MeasuredDrape& measured,
                              const DrapeCompareOptions& options);

// The comparison as drape.json's `comparison` (mm and degrees; docs/guide/drape.md): every
// figure, the per-seed rows, the verdict and the notes; the caller adds `measured_file`.
nlohmann::json DrapeComparisonJson(const DrapeComparison& comparison);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_COMPARE_H_
