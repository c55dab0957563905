#ifndef TEXTILE_SIM_ELASTICA_ELASTICA_H_
#define TEXTILE_SIM_ELASTICA_ELASTICA_H_

// The heavy elastica: a strip clamped flat at a table edge, bending under its own weight with a
// nonlinear moment-curvature law (docs/spec/cantilever.md, "Heavy elastica"). It is the
// reference forward model of the project: the classic cantilever outputs, the Clapp baseline,
// the direct fit and the validation of the shell model all rest on it.
//
//   // The paper's Fig. 8 fabric at 200 g/m², 100 mm overhang.
//   textile::BendingLaw law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   textile::ElasticaOptions options;
//   options.sensitivities = true;                    // d(x, y, θ)/d(b1, b2, c1) for a fit
//   textile::ElasticaProfile p = textile::SolveHeavyElastica(law, 0.2, 0.1, options);
//   if (!p.converged) throw textile::ComputeError(p.message);
//   // p.x, p.y [m]: 201 points from the edge (0, 0) to the tip (≈ 0.0103, -0.0959).
//
// Frame (docs/spec/cantilever.md, "Frame"): origin at the edge, x towards the overhang, y up, so a
// hanging strip has y < 0; arc length s from the edge (0) to the free tip (L); θ is the angle below
// the horizontal. Per unit width the bending moment m(s) = ρ g ∫_s^L (x(s') - x(s)) ds' satisfies
//
//   dm/ds = -ρ g (L - s) cos θ,  m(L) = 0,   dθ/ds = κ = M⁻¹(m),  θ(0) = 0,
//
// a two-point boundary value problem solved by shooting on the tip angle θ(L) from the tip back to
// the edge (GSL rk8pd with error control). See docs/methods/cantilever-facts.md for the method and its
// accuracy. Everything here is SI.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "textile/sim/law/bending_law.h"

namespace textile {

// A strip whose bending stiffness or weight varies along its length, such as a seam across it
// (Pabst et al. section 4.2). Both are functions of the distance u = L - s from the free tip
// [m], so that a seam at a fixed distance from the sample's front stays at that point of the
// strip whatever the overhang. With S(u) the law becomes M_S(κ) = S(u) M(κ) (the multiplier of
// eq. 6 on the moment), so κ = M⁻¹(m / S), and the moment balance of docs/spec/cantilever.md
// becomes dm/ds = -ρ g W(u) cos θ with W(u) = ∫_0^u ρ(u')/ρ du' the weight beyond s in strip
// lengths.
//
//   // A C-plain seam across the strip, 20 mm from the front (docs/methods/acpm.md):
//   textile::StripVariation v;
//   v.stiffness_multiplier = [&](double u) { return seam.Multiplier(std::abs(u - 0.02) * 1e3); };
//   v.breakpoints = {0.02};  // S has a corner at the seam line
//   options.variation = v;
struct StripVariation {
  // S(u) > 0 [-]; empty: 1 everywhere.
  std::function<double(double u)> stiffness_multiplier;
  // W(u) [m], continuous, increasing, W(0) = 0; empty: W(u) = u (a uniform strip).
  std::function<double(double u)> weight_from_tip;
  // Distances from the tip [m] where S or W is not smooth (a seam line, band edges, the ends of
  // a fade): the integration stops there, so each step sees a smooth right-hand side.
  std::vector<double> breakpoints;

  bool empty() const { return !stiffness_multiplier && !weight_from_tip; }
};

struct ElasticaOptions {
  // Error tolerance per integration step, relative and absolute on the scaled variables (θ,
  // m/(ρgL²), x/L, y/L); the solution is accurate to about this, relative to L. In [1e-14, 1e-3].
  double rel_tol = 1e-10;
  // Number of samples, uniform in arc length including s = 0 and s = L (≥ 2). Ignored when
  // arc_lengths is given.
  int num_samples = 201;
  // Arc lengths to sample at instead [m]: ascending, finite, each in [0, L].
  std::vector<double> arc_lengths;
  // Also compute the derivatives of x, y and θ at the samples w.r.t. the law constants
  // {b1, b2, c1} (variational equations, no finite differences). About 2.5× the cost.
  // Pabst laws only: SolveHeavyElastica refuses it for a spline law (InputError).
  bool sensitivities = false;
  // Cap on integrations of the strip during shooting (each one is an initial value problem).
  int max_shooting_iterations = 60;
  // Wall-clock cap on the whole solve [s], finite and >= 0. A solve takes about a millisecond;
  // the two caps above bound its work (60 integrations of up to 400 000 steps) but not its time
  // on a slow or loaded machine. The clock is read at the first step of every integration and
  // every 1024 steps after, so a solve stops within a few milliseconds of the cap with
  // converged = false and a "time cap" message; 0 stops at the first step (for tests).
  double max_seconds = 5.0;
  // θ(L) [rad] to start the shooting from, in [0, π/2), e.g. from the previous solve of a
  // continuation in L; NaN lets the solver estimate it (small-load or hanging-chain limit).
  double tip_angle_guess = std::numeric_limits<double>::quiet_NaN();
  // The same guess as log(π/2 − θ(L)) (ElasticaProfile::log_tip_gap), finite; it takes
  // precedence over tip_angle_guess. A strip hanging nearly vertically has θ(L) == π/2 in
  // double precision, which tip_angle_guess cannot take but its log gap can (a fit's
  // continuation over long strips; NaN: not given).
  double log_tip_gap_guess = std::numeric_limits<double>::quiet_NaN();
  // Stiffness and weight varying along the strip (default: a uniform strip). The law's kink
  // is then not located as an event (m/S may cross M(κ0) several times); the error control
  // takes the corner of κ(m) in its stride.
  StripVariation variation;

  // False, with the reason in *why, when a field is out of range.
  bool Check(std::string* why) const;
};

// A solved strip. When converged is false, message says why and the arrays are empty.
struct ElasticaProfile {
  bool converged = false;
  std::string message;

  double length = 0.0;         // overhang L [m]
  double areal_density = 0.0;  // ρ [kg/m²]

  double tip_angle = std::numeric_limits<double>::quiet_NaN();  // θ(L) [rad], in (0, π/2)
  // log(π/2 - θ(L)): stays finite and accurate for strips that hang so nearly vertically that
  // π/2 - θ(L) underflows (long, soft strips).
  double log_tip_gap = std::numeric_limits<double>::quiet_NaN();
  double tip_x = std::numeric_limits<double>::quiet_NaN();  // x(L) [m]
  double tip_y = std::numeric_limits<double>::quiet_NaN();  // y(L) [m], < 0
  double clamp_curvature = std::numeric_limits<double>::quiet_NaN();  // κ(0) [1/m]
  double clamp_moment = std::numeric_limits<double>::quiet_NaN();     // m(0) [N]
  // Arc length where κ passes the law's kink κ0 [m]; NaN when κ0 is not reached (or is 0).
  // For a spline law κ0 is its last knot, where it turns linear.
  double kink_arc_length = std::numeric_limits<double>::quiet_NaN();

  int shooting_iterations = 0;  // integrations of the strip
  int integration_steps = 0;    // accepted rk8pd steps over all of them

  // Samples, each #samples long: arc length s [m], position x, y [m], angle below the
  // horizontal θ [rad], curvature κ [1/m], moment per unit width m [N].
  std::vector<double> s, x, y, theta, kappa, moment;

  // #samples×3 derivatives w.r.t. the law constants (b1 [N·m], b2 [N·m], c1 [N·m²]) in SI:
  // [m/(N·m)], [m/(N·m)], [m/(N·m²)] for x and y, [1/(N·m)], ... for θ. Filled only when
  // ElasticaOptions::sensitivities is set, else 0×3.
  Eigen::MatrixX3d dx_dp, dy_dp, dtheta_dp;

  // One line for logs: convergence, tip, clamp curvature, effort.
  std::string BriefReport() const;
};

// Solves the heavy elastica for a strip of areal density areal_density [kg/m²] with overhang
// length [m]. Throws InputError when the options fail Check, when areal_density or length is not
// a finite number > 0, when an arc length lies outside [0, length], or when sensitivities are
// asked of a spline law. Never returns garbage: a solve that does not converge returns
// converged = false and a message.
ElasticaProfile SolveHeavyElastica(const BendingLaw& law, double areal_density, double length,
                                   const ElasticaOptions& options = {});

}  // namespace textile

#endif  // TEXTILE_SIM_ELASTICA_ELASTICA_H_
