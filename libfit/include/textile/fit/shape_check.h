#ifndef TEXTILE_FIT_SHAPE_CHECK_H_
#define TEXTILE_FIT_SHAPE_CHECK_H_

// The physics check of an extracted profile: is it the shape of a heavy cantilever at all? The
// best single-overhang heavy elastica (direct_fit.h, any monotone law of Pabst eq. 1) is fitted
// to the profile alone; its residual exposes what no bending law makes: a flat part lying on a
// platform counted as overhang (a cantilever bends most at its edge), a tip cut short or run on
// into the background, a trace that jumped onto a shadow.
//
//   textile::ShapeCheck c = textile::CheckCantileverShape(extraction.profile);
//   if (!c.plausible) std::cerr << c.message << "\n";   // e.g. "rms 2.4 mm from ..."
//
// Only the shape counts: M/ρ is all a shape determines, so no areal density is needed.

#include <string>

#include "textile/fit/profile.h"

namespace textile {

// RMS distance above which a profile is no heavy cantilever within the extraction's stated
// accuracy [m] (docs/methods/extraction.md: an exit-0 profile is within 1 mm RMS of the strip).
inline constexpr double kShapeCheckMaxRms = 1e-3;

struct ShapeCheck {
  bool converged = false;  // the elastica fit converged (else the profile is not plausible)
  bool plausible = false;  // converged and rms <= kShapeCheckMaxRms
  double rms = 0.0;        // RMS normal distance of the points from the best elastica [m]
  double max = 0.0;        // the largest [m]
  int points = 0;          // points fitted (the profile thinned to at most 120)
  std::string pattern;     // where the law misses (DirectFitSummary::fit_pattern), may be empty
  std::string message;     // one line for people: what the check found
};

// Fits the profile alone (thinned evenly to at most 120 points, a fit of 10-40 ms). Never
// throws for a profile that passes CheckProfile; throws InputError (from CheckProfile) otherwise.
ShapeCheck CheckCantileverShape(const Profile& profile);

}  // namespace textile

#endif  // TEXTILE_FIT_SHAPE_CHECK_H_
