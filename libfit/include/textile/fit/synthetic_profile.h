#ifndef TEXTILE_FIT_SYNTHETIC_PROFILE_H_
#define TEXTILE_FIT_SYNTHETIC_PROFILE_H_

// Cantilever profiles as a photo extractor would deliver them, made from the exact heavy
// elastica of a known law: for samples, tests and the fit-accuracy benchmark.
//
//   textile::BendingLaw law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
//   textile::SyntheticOptions o;
//   o.noise_sigma = 1e-4;               // 0.1 mm of pixel noise on x and y
//   o.vertical_offset = 0.25e-3;        // mid-line of a 0.5 mm thick strip
//   textile::Profile p = textile::SyntheticProfile(law, 0.2, 0.06, o);
//   std::string csv = textile::ProfileToCsv(p);   // s_mm,x_mm,y_mm
//
// Order of the distortions (each off by default): sample the exact elastica at N arc lengths
// (uniform, optionally jittered) -> lift by the vertical offset (the strip rests on the platform,
// so its mid-line starts at (0, t/2); docs/spec/cantilever.md "Photo protocol") -> rotate about the
// edge by the rig rotation -> add Gaussian noise to x and y -> optionally recompute s as the
// cumulative chord length of the distorted points. Deterministic for a given seed.

#include <cstdint>
#include <string>

#include "textile/fit/profile.h"
#include "textile/sim/law/bending_law.h"

namespace textile {

struct SyntheticOptions {
  // Points along the strip, from the edge (s = 0) to the tip (s = L) inclusive [-];
  // ≥ kMinProfilePoints.
  int num_points = 100;
  // Random shift of the interior sample arc lengths, uniform in ±arc_jitter × spacing [-], in
  // [0, 0.5) so that the order is kept. 0: exactly uniform in arc length.
  double arc_jitter = 0.0;
  // Standard deviation of independent Gaussian noise on x and on y [m], ≥ 0.
  double noise_sigma = 0.0;
  // Seed of the std::mt19937_64 behind the jitter and the noise.
  std::uint64_t seed = 1990;
  // Vertical offset of the whole profile [m], added to y (t/2 for a strip of thickness t).
  double vertical_offset = 0.0;
  // Rig rotation [rad]: the profile is rotated counter-clockwise by this angle about the edge,
  // as a camera rolled by -rotation would see it. |rotation| ≤ 0.2 (a few degrees is realistic).
  double rotation = 0.0;
  // True: s is the cumulative chord length of the final points from the first (what a photo
  // extractor computes; noise lengthens it). False: the exact arc lengths of the samples.
  bool chord_arc_length = false;
  // Relative accuracy of the elastica (ElasticaOptions::rel_tol).
  double elastica_rel_tol = 1e-10;

  // False, with the reason in *why (if non-null), when a field is out of range.
  bool Check(std::string* why) const;
};

// A synthetic profile of a strip with law `law` [SI], areal density [kg/m²] > 0 and overhang
// length [m] > 0, in the frame of docs/spec/cantilever.md (origin at the edge, y up, metres).
// @return #num_points profile; source describes the law, density, length, noise and seed.
// Throws InputError for bad options or inputs, ComputeError when the elastica does not converge.
Profile SyntheticProfile(const BendingLaw& law, double areal_density, double overhang,
                         const SyntheticOptions& options = {});

}  // namespace textile

#endif  // TEXTILE_FIT_SYNTHETIC_PROFILE_H_
