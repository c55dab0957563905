#ifndef TEXTILE_SIM_SRC_ELASTICA_STAGES_H_
#define TEXTILE_SIM_SRC_ELASTICA_STAGES_H_

// The decisions inside SolveHeavyElastica, as stages of their own so that they can be tested
// apart from the integration (elastica.cc runs them in order). Not public API.
//
//   ElasticaSamples samples = SampleArcLengths(length, options);
//   ShootingState state{.z = z0};
//   while (!state.done) { shot = Shoot(state.z); UpdateShooting(shot, ..., &state); }

#include <limits>
#include <vector>

#include "textile/sim/elastica/elastica.h"

namespace textile::sim_internal {

// Where the profile is sampled.
struct ElasticaSamples {
  std::vector<double> arc;      // s [m], ascending from the edge (0) to the tip (L)
  std::vector<double> targets;  // t = (L - s)/L [-], ascending: targets[n-1-j] belongs to arc[j]
};

// options.arc_lengths when given, else options.num_samples uniform arc lengths over [0, L]
// (the last exactly L, and their t exact fractions).
ElasticaSamples SampleArcLengths(double length, const ElasticaOptions& options);

// Phases of the shooting. kCoarse: Newton at a loose tolerance until its step is small.
// kFine: one shot at the requested tolerance (only with sensitivities). kFinal: the sampled
// pass, whose own Newton step is applied linearly if small enough.
enum class ShootingPhase { kCoarse, kFine, kFinal };

// What one shot tells the Newton iteration.
struct ShotOutcome {
  bool reached_clamp = false;  // false: the trial undershot (stopped early)
  double residual = std::numeric_limits<double>::quiet_NaN();  // increasing in z
  double slope = std::numeric_limits<double>::quiet_NaN();     // d residual / dz
};

// The safeguarded Newton on the shooting unknown z, with a bracket [lo, hi] around the root.
struct ShootingState {
  double z = 0.0;                                       // the next trial
  double lo = 0.0;                                      // the residual is < 0 at z = 0
  double hi = std::numeric_limits<double>::infinity();  // until a trial overshoots
  ShootingPhase phase = ShootingPhase::kCoarse;
  bool done = false;        // the final pass is accepted
  double correction = 0.0;  // once done: the Newton step to apply linearly to the final pass
};

// Newton steps below this (relative to z) have settled: the next error is ~step².
inline constexpr double kCloseStep = 1e-4;

// Updates the bracket from the shot at state->z, then either accepts the final pass (done,
// correction) or picks the next z and phase: a Newton step inside the bracket, else doubling
// (no upper bound yet) or bisection. accept_step: the largest relative Newton step the final
// pass may take linearly.
void UpdateShooting(const ShotOutcome& shot, bool sensitivities, double accept_step,
                    ShootingState* state);

}  // namespace textile::sim_internal

#endif  // TEXTILE_SIM_SRC_ELASTICA_STAGES_H_
