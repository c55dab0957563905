#ifndef TEXTILE_FIT_PROFILE_COMPARE_H_
#define TEXTILE_FIT_PROFILE_COMPARE_H_

// Measured profile against a simulated one: how far apart, in mm, as a technician would judge
// (cantilever.md, "Closing the loop"). Used by fit reports (for every method alike, so Clapp
// and the direct fit are graded the same way) and by validation.
//
//   textile::ProfileComparison c = textile::CompareWithElastica(law, 0.2, measured, 0.06, 0.0);
//   // c.rms, c.max [m]: normal distances of the measured points to the simulated curve

#include <vector>

#include "textile/fit/profile.h"
#include "textile/sim/bending_law.h"

namespace textile {

struct ProfileComparison {
  double rms = 0.0;       // RMS normal distance of the measured points to the curve [m]
  double max = 0.0;       // largest normal distance [m]
  double tip_dx = 0.0;    // simulated minus measured tip, x [m]
  double tip_dy = 0.0;    // simulated minus measured tip, y [m]
  double clamp_curvature = 0.0;  // κ(0) of the simulated strip [1/m]
  std::vector<double> model_x, model_y;  // the simulated curve, measurement frame [m]
};

// Simulates the strip (law [SI], areal density [kg/m²], overhang [m]) and compares it with
// the measured profile, the simulation lifted by `offset` [m] (the mid-line's height at the
// edge). Throws ComputeError if the elastica fails, InputError for bad arguments.
ProfileComparison CompareWithElastica(const BendingLaw& law, double areal_density,
                                      const Profile& measured, double overhang, double offset,
                                      int curve_samples = 201);

}  // namespace textile

#endif  // TEXTILE_FIT_PROFILE_COMPARE_H_
