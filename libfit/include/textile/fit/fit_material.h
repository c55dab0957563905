#ifndef TEXTILE_FIT_FIT_MATERIAL_H_
#define TEXTILE_FIT_FIT_MATERIAL_H_

// One strip's profiles -> a fitted material: the bending law {b1, b2, c1} by the direct
// elastica fit (default) or Clapp et al.'s method, checked as a material file would be, with the
// `fit` report every fitted material carries (fit_report.h). What `textile fit` and `textile
// batch` run for a specimen.
//
//   textile::FitMaterialOptions o;
//   o.areal_density = textile::units::GsmToSi(200.0);
//   const textile::FittedMaterial f = textile::FitMaterial(profiles, o);   // throws
//   WriteText(path, textile::MaterialToJson(f.material).dump(2));

#include <optional>
#include <string>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/fit/profile_compare.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/law/material.h"

namespace textile {

enum class FitMethod { kDirect, kClapp };

struct FitMaterialOptions {
  double areal_density = 0.0;  // ρ [kg/m²], > 0
  FitMethod method = FitMethod::kDirect;
  // Direct fit only (Clapp's polynomial takes the profiles as they are; any of these set with
  // kClapp is an InputError naming the flag):
  std::optional<double> thickness;  // measured strip thickness [m]: fixes the offset to t/2
  bool no_offset = false;      // force the curve through the edge (offset 0)
  bool fit_rotation = false;   // always fit a small rig rotation
  double robust_scale_mm = 0.5;  // Cauchy loss scale per point [mm]; 0 = plain least squares
  bool robust_given = false;     // the caller set robust_scale_mm (refused with kClapp)
  std::string name;  // the material's name; empty: "fitted from <first profile's stem>"
};

struct FittedMaterial {
  // The law as the material every simulation takes (LawOnlyMaterial: the membrane defaults
  // listed), `fit` the report (fit_report.h), name as asked.
  Material material;
  std::vector<ProfileComparison> comparisons;  // per profile, measured vs fitted elastica
  double kappa_max = 0.0;                      // the largest curvature the data reach [1/m]
  std::string brief;                           // the solver's one-line summary
  std::vector<std::string> notes;              // what a user should know of a fit that worked
};

// Checks the options: InputError naming the flag as `textile fit` spells it ("--gsm",
// "--robust-mm", "--thickness-mm", ...).
void CheckFitMaterialOptions(const FitMaterialOptions& options);

// Fits `profiles` (one strip, any number of overhangs). Throws InputError for bad options and
// ComputeError when the fit does not converge or gives a law no material file would take
// ("fit (clapp) gave an implausible law: ..."). The report's `seconds` is the solver's time;
// callers that need the same bytes for the same inputs erase it.
FittedMaterial FitMaterial(const std::vector<Profile>& profiles, const FitMaterialOptions& options);

// "pabst-fig8_L040mm" for .../pabst-fig8_L040mm.profile.csv and for a photo
// .../pabst-fig8_L040mm.jpg: the name a fitted material takes from its first input.
std::string ProfileInputStem(const std::string& path);

}  // namespace textile

#endif  // TEXTILE_FIT_FIT_MATERIAL_H_
