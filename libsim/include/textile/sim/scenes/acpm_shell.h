#ifndef TEXTILE_SIM_SCENES_ACPM_SHELL_H_
#define TEXTILE_SIM_SCENES_ACPM_SHELL_H_

// The shell model of the virtual ACPM200 (acpm.h, scene types in acpm_types.h): the 3D cloth engine (cloth_problem.h,
// static_solver.h) pushes the sample over the platform edge in quasi-static steps.
//
//   textile::AcpmOptions options;                    // plain 200 mm sample
//   options.model = textile::AcpmModelKind::kShell;  // RunAcpm plugs this model in
//   textile::AcpmResult r = textile::RunAcpm(fabric, options);
//
// The scene at overhang L: the sample's overhanging part [0, L] × [0, W] (x along the push, y
// across the width, z up) plus one cell on the platform, whose vertices are held flat: the
// platform holds the sample as the elastica's clamp does (the part on the platform stays flat
// under its own weight, docs/spec/cantilever.md). A tensor-product grid with a constant number of
// cells stretches with L, so each step is warm-started from the last state; a seam along the push
// direction lies on a grid line, a seam across it at its distance behind the front. The front
// edge's height over the 41.5° barrier plane is interpolated at every ray; the push steps
// until every ray is cut, then each ray's crossing is refined (Illinois regula falsi on the
// solved states) to AcpmOptions::crossing_tolerance. Solved states are shared by all rays.

#include <string>
#include <vector>

#include "textile/sim/scenes/acpm_types.h"
#include "textile/sim/solve/static_solver.h"

namespace textile {

struct ShellAcpmSettings {
  // Element length along the push direction [m]; the grid has ⌈L_ref / this⌉ cells over the
  // overhang (at least 8), L_ref the plain elastica's crossing.
  double element_length = 0.002;
  // Cells across the width: plain samples and seams across (nothing varies across the width
  // but the mesh must still be a shell) and seams along (the seam's stiffness profile S(d)
  // must be resolved; the seam line is snapped to a grid line). 10 cells (20 mm) give the
  // C-plain factors of 20 cells to 0.3 % at the seam ray and 1.7 % at the edges, in 60 % of the
  // time.
  int width_cells_plain = 2;
  int width_cells_seam = 10;
  // The bending elements: the curvature tensor per triangle (a free strip as stiff as the law)
  // or the paper's hinges (0.7-0.8 of it on these grids; docs/methods/statics.md).
  BendingDiscretization bending = BendingDiscretization::kTensor;
  // Push twice, with element_length and half of it, and report 2 L(e/2) - L(e) per ray: the
  // tensor model's crossing converges at first order (-4.4 %, -2.2 %, -1.1 % at 2, 1, 0.5 mm on
  // the Fig. 8 fabric), the extrapolation leaves < 0.1 % (docs/methods/acpm.md).
  bool extrapolate = true;
  // Wall-time cap of a whole run [s] (ShellAcpmCrossings: every push; SolveShellCantilever:
  // both continuations), finite and >= 0. Each static solve gets at most the time left; past
  // the cap the run fails with a message (no crossings, no profile). Runs take 0.5-5 s.
  double max_seconds = 300.0;
  // Static solver settings for every push step.
  SolveOptions solve = [] {
    SolveOptions s;
    s.tolerance = 1e-7;
    s.max_iterations = 400;
    return s;
  }();

  bool Check(std::string* why) const;
};

// An AcpmModel (acpm_types.h; RunAcpm of acpm.h calls it through ShellAcpmModel): crossings of every ray at z_i [m].
AcpmCrossings ShellAcpmCrossings(const Material& material, const AcpmOptions& options,
                                 const std::vector<double>& ray_z,
                                 const ShellAcpmSettings& settings = {});

// A plain cantilever at a fixed overhang on the shell model: the scene of the push above (the
// sample held flat on the platform, one cell behind the edge) at overhang L, reached by
// continuation from 0.4 L in warm-started steps (halved where a step fails). The side profile
// is the centre line's; with settings.extrapolate it is 2 P(e/2) - P(e) point by point (the
// fine grid's every other vertex is the coarse grid's material point), as the crossings are.
//
//   textile::ShellCantilever c = textile::SolveShellCantilever(fabric, 0.08, 0.025);
//   // c.x, c.y: the centre line from the edge to the free end [m], y < 0 hanging
struct ShellCantilever {
  bool converged = false;
  std::string message;       // why not, when not converged
  std::vector<double> x,
      y;  // centre line [m], docs/spec/cantilever.md's frame, from the edge (0, 0)
  int solves = 0;            // static solves, both resolutions
  int vertices = 0;          // of the finest grid
  std::string notes;
};

// overhang L [m] in (0, 1], width [m] in (0, 0.2]. Throws InputError for arguments outside
// those ranges or bad settings; a solve that fails is reported in the result.
ShellCantilever SolveShellCantilever(const Material& material, double overhang, double width,
                                     const ShellAcpmSettings& settings = {});

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_ACPM_SHELL_H_
