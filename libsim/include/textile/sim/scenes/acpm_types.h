#ifndef TEXTILE_SIM_SCENES_ACPM_TYPES_H_
#define TEXTILE_SIM_SCENES_ACPM_TYPES_H_

// The scene of the virtual ACPM200 (acpm.h) and what a model answers for it: the types that
// the runner (acpm.h, RunAcpm) and the shell model (acpm_shell.h) share, so that neither
// header needs the other.
//
//   textile::AcpmOptions options;                  // 200 × 300 mm, 17 rays, auto model
//   options.seam.direction = textile::AcpmSeamDirection::kAlong;
//   std::vector<double> z = options.RayPositions();
//   textile::AcpmCrossings c = textile::ShellAcpmCrossings(fabric, options, z);  // acpm_shell.h

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "textile/sim/elastica/cantilever_outputs.h"
#include "textile/sim/law/material.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/law/seam.h"

namespace textile {

enum class AcpmModelKind { kAuto, kElastica, kShell };
enum class AcpmSeamDirection {
  kNone,    // a plain sample
  kAlong,   // a seam line along the push direction, at width position z_s
  kAcross,  // a seam line across the push direction, at a distance behind the sample's front
};

// "auto", "elastica", "shell"; "none", "along", "across". Parse* throw InputError otherwise.
std::string AcpmModelName(AcpmModelKind kind);
AcpmModelKind ParseAcpmModel(const std::string& name);
std::string AcpmSeamDirectionName(AcpmSeamDirection direction);
AcpmSeamDirection ParseAcpmSeamDirection(const std::string& name);

struct AcpmSeam {
  AcpmSeamDirection direction = AcpmSeamDirection::kNone;
  SeamProfile profile;  // Table 2 preset (SeamPreset) or a fitted seam file (ReadSeamProfile)
  // kAlong: z_s [m] from the sample's left edge (ray 0 side), in [0, width]; NaN: the centre.
  // kAcross: distance [m] of the seam line behind the sample's front edge, in [0, length].
  double position = std::numeric_limits<double>::quiet_NaN();
};

struct AcpmOptions;

// What a model answers for a scene: per ray, the overhang at which the front crosses the
// barrier, plus the side profile (mid-line in the bending plane, docs/spec/cantilever.md's frame)
// at the crossing of one ray.
struct AcpmCrossings {
  bool converged = false;
  std::string message;            // why not, when not converged
  std::vector<double> overhang;   // #rays, L_i [m]
  int profile_ray = 0;            // the ray whose side profile is given
  std::vector<double> profile_x;  // side profile at that crossing [m], from the edge to the
  std::vector<double> profile_y;  // front, x towards the overhang, y up (y < 0 hanging)
  // The model's own crossing for the same fabric without seams [m], if it ran one (at the same
  // resolution, so that its error cancels in the factor); NaN: the exact elastica's is used.
  double plain_overhang = std::numeric_limits<double>::quiet_NaN();
  int solves = 0;     // static solves (elastica solves, or shell push steps)
  std::string notes;  // anything the model wants in the result
  // The sample's overhanging part at the profile ray's crossing [m] (x along the push from the
  // edge, y across the width, z up): the shell's solved mesh, or the elastica's profile swept
  // across the width.
  TriangleMesh shape;
};

// The plug-in point of the shell model (issue 6): given the material, the scene (options:
// sample size, barrier, push speed, crossing refinement, seam) and the ray positions z_i [m]
// (#rays, from the left edge), return every ray's crossing. A shell implementation pushes the
// sample in quasi-static steps (each warm-started from the last) and refines each ray's
// crossing to options.crossing_tolerance. Report non-convergence in the result; throw
// InputError only for input the model cannot take.
using AcpmModel = std::function<AcpmCrossings(const Material& material, const AcpmOptions& options,
                                              const std::vector<double>& ray_z)>;

struct AcpmOptions {
  double width = 0.2;         // sample width W [m], in (0, 0.2] (the ACPM200's maximum)
  double length = 0.3;        // sample length [m], the longest overhang, in (0, 1]
  int num_rays = 17;          // sampling rays, evenly spaced across the width, ≥ 1
  double ray_margin = 0.005;  // first and last ray this far inside the edges [m]
  double barrier_angle = kStandardBarrierAngle;  // below the horizontal [rad], in (0, π/2)
  double push_speed = 0.12 / 60.0;               // [m/s] (12 cm/min)
  double crossing_tolerance = 5e-5;              // crossing refinement [m] for stepping models (the
                                                 // elastica solves the crossing to 1e-10 relative)
  AcpmModelKind model = AcpmModelKind::kAuto;
  AcpmSeam seam;
  AcpmModel shell_model;  // empty: ShellAcpmModel()
  // The crossing length's sensitivities (docs/methods/sensitivity.md, "ACPM"): for each of
  // sensitivity_parameters (empty: every parameter the model takes: the elastica the `bending`
  // law's constants, beta and areal_density_gsm; the shell every parameter of the material),
  // by central differences of whole runs; with none named, the scene's and the seam's inputs
  // too (AcpmResult::scene_sensitivities, seam_sensitivities; a seam too near its bounds for
  // the differences is refused before any work).
  bool sensitivity = false;
  std::vector<std::string> sensitivity_parameters;
  // Monte Carlo check of the σ (law/monte_carlo.h): this many materials drawn from the fit's
  // covariance of b1, b2, c1 (0: none; else 2..100000), each pushed through the run's model.
  // Implies sensitivity (the linear σ beside it). Needs a material with a fit covariance.
  int monte_carlo_samples = 0;
  unsigned monte_carlo_seed = 1;

  // False with "<field>: <problem>" in *why (names as the CLI flags say them, in mm).
  bool Check(std::string* why) const;
  // Ray positions z_i [m] from the left edge: evenly from margin to width - margin (one ray:
  // the centre).
  std::vector<double> RayPositions() const;
};

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_ACPM_TYPES_H_
