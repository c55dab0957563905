#ifndef TEXTILE_SIM_ELASTICA_CANTILEVER_OUTPUTS_H_
#define TEXTILE_SIM_ELASTICA_CANTILEVER_OUTPUTS_H_

// What a cantilever bending tester reports (ASTM D1388, ISO 9073-7, BS 3356, FAST-2, the
// ACPM200 of Pabst section 4.1), computed from the exact heavy elastica
// (docs/spec/cantilever.md, "Classic outputs").
//
//   // Where does the paper's Fig. 8 fabric (200 g/m²) meet the 41.5° barrier?
//   textile::BendingLaw law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   textile::BarrierCrossing crossing = textile::FindBarrierCrossing(law, 0.2);
//   if (!crossing.converged) throw textile::ComputeError(crossing.message);
//   // crossing.overhang ≈ 0.0335864 m
//   textile::ClassicOutputs out = textile::ComputeClassicOutputs(0.2, crossing.overhang);
//   // out.bending_length = L/2 ≈ 16.79 mm, out.rigidity_micro_nm() ≈ 9.289 µN·m
//
// The lab's numbers are a model too: G = ρ g c³ is exact only for a linear law (and there the
// L/2 rule is off by 0.02 % in c). For a nonlinear law G lies between, or beyond, b1 and b2;
// RelationToLaw() says where.

#include <limits>
#include <numbers>
#include <string>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/elastica/elastica.h"

namespace textile {

// The standard barrier: 41.5° below the horizontal [rad].
inline constexpr double kStandardBarrierAngle = 41.5 * std::numbers::pi / 180.0;

struct CrossingOptions {
  // Barrier inclination below the horizontal [rad], in (0, π/2).
  double barrier_angle = kStandardBarrierAngle;
  // Longest overhang tried [m] (a tester's sample length); beyond it the crossing fails.
  double max_length = 0.3;
  // Relative tolerance on the crossing overhang L*, in [1e-13, 1e-3].
  double rel_tol = 1e-10;
  // Cap on root-finding iterations (bracketing and Brent together).
  int max_iterations = 100;
  // Wall-time cap of the whole search [s], finite, ≥ 0 (0: fail before the first solve). Each
  // elastica solve gets at most the time left (and at most elastica.max_seconds). A crossing
  // takes milliseconds; without it, 100 iterations of 5 s solves could run for minutes.
  double max_seconds = 30.0;
  // Options of each elastica solve; the sampling and sensitivities are ignored.
  ElasticaOptions elastica;

  // False, with the reason in *why, when a field is out of range.
  bool Check(std::string* why) const;
};

// The overhang at which the free tip meets the barrier line through the edge, i.e. the chord
// angle atan2(-y_tip, x_tip) equals the barrier angle.
struct BarrierCrossing {
  bool converged = false;
  std::string message;
  double barrier_angle = 0.0;  // [rad]
  double overhang = std::numeric_limits<double>::quiet_NaN();         // L* [m]
  double tip_x = std::numeric_limits<double>::quiet_NaN();            // at L* [m]
  double tip_y = std::numeric_limits<double>::quiet_NaN();            // at L* [m], < 0
  double tip_angle = std::numeric_limits<double>::quiet_NaN();        // θ(L*) [rad]
  double clamp_curvature = std::numeric_limits<double>::quiet_NaN();  // κ(0) at L* [1/m]
  int elastica_solves = 0;

  // One line: L*, tip, effort, or the reason for failure.
  std::string BriefReport() const;
};

// Finds L* by bracketing (doubling from a linear-law estimate) and Brent's method on the chord
// angle, which increases with L. Throws InputError for invalid options or areal_density (not a
// finite number > 0 kg/m²). A strip too stiff to reach the barrier within max_length returns
// converged = false, "does not reach the barrier within 300 mm".
BarrierCrossing FindBarrierCrossing(const BendingLaw& law, double areal_density,
                                    const CrossingOptions& options = {});

// Bending length by the L/2 rule of the standards, valid at the 41.5° barrier [m].
// @param overhang  L [m]
double HalfRuleBendingLength(double overhang);

// Peirce's (1930) general formula c = L (cos(θc/2) / (8 tan θc))^(1/3) [m].
// @param overhang     L [m], > 0
// @param chord_angle  θc, angle of the edge-to-tip chord below the horizontal [rad], in (0, π/2)
// Throws InputError outside these ranges.
double PeirceBendingLength(double overhang, double chord_angle);

// Flexural rigidity G = ρ g c³ per unit width [N·m].
// @param areal_density   ρ [kg/m²]
// @param bending_length  c [m]
double FlexuralRigidity(double areal_density, double bending_length);

// A lab's report for one overhang reading.
struct ClassicOutputs {
  double areal_density = 0.0;      // ρ [kg/m²]
  double overhang = 0.0;           // L [m]
  double chord_angle = 0.0;        // θc [rad]
  bool half_rule = true;           // c from L/2 (standard angle) or Peirce's formula
  double bending_length = 0.0;     // c [m]
  double flexural_rigidity = 0.0;  // G [N·m per unit width]

  double rigidity_micro_nm() const;  // G [µN·m]
  double rigidity_mg_cm() const;     // G [mg·cm]
  double rigidity_gf_cm() const;     // G [gf·cm]

  // "G = 0.947 b1 = 1.062 b2 (b1 = ..., b2 = ... gf·cm)": how the lab number relates to a law
  // (a spline law: to B(0) and the slope past its last knot).
  std::string RelationToLaw(const BendingLaw& law) const;
  // One line: c, G in µN·m, mg·cm and gf·cm, and the rule used.
  std::string BriefReport() const;
};

// c and G from an overhang reading at a chord angle: the L/2 rule at the standard 41.5°
// (within 1e-9 rad), Peirce's general formula at any other angle. Throws InputError for
// non-positive or non-finite inputs or an angle outside (0, π/2).
ClassicOutputs ComputeClassicOutputs(double areal_density, double overhang,
                                     double chord_angle = kStandardBarrierAngle);

}  // namespace textile

#endif  // TEXTILE_SIM_ELASTICA_CANTILEVER_OUTPUTS_H_
