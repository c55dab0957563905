#ifndef TEXTILE_FIT_FIT_REPORT_H_
#define TEXTILE_FIT_FIT_REPORT_H_

// The fit report a fitted material carries in its `fit` (docs/spec/cli.md): the constants'
// σ, the residuals per profile, the rig, and what the classic 41.5° test would report for the
// law. `textile fit` and `textile validate` write it alike.
//
//   std::vector<std::string> notes;
//   textile::DirectFitOptions used;
//   const textile::DirectFitSummary fit =
//       textile::FitDirectCheckingTilt(profiles, rho, options, &notes, &used);
//   textile::Material m = ...;
//   m.fit = textile::FitReportJson(fit, used, rho, notes);
//   m.fit["inputs"] = paths;  // the caller adds what it knows of the inputs

#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/fit/clapp.h"
#include "textile/fit/direct_fit.h"
#include "textile/fit/profile.h"
#include "textile/fit/profile_compare.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/law/material.h"

namespace textile {

// A fitted law as the material every simulation of it takes (areal density [kg/m²], other
// fields the defaults: LawOnlyMaterial, whose membrane is listed as defaulted), if a material
// file would take it (Material::Check): a fit to a straight
// or vertical strip, or Clapp's regression on a poor polynomial, can run to constants no fabric
// has. Else none, and *why (if non-null) says, as a file named "fitted law" is refused:
// "fitted law: bending.b1: suspicious magnitude ...".
std::optional<Material> FittedLawMaterial(const BendingLaw& law, double areal_density,
                                          std::string* why);

struct FitReportOptions {
  // The solve's diagnostics: covariance_kes, start, point_scatter_mm and fit_pattern. `textile
  // fit` writes them; the fitted.json of `textile validate` has always left them out.
  bool diagnostics = true;
  // robust_scale_mm as the user gave it [mm] (mm → m → mm need not give the same double);
  // NaN: the fit options' robust_scale.
  double robust_scale_mm = std::numeric_limits<double>::quiet_NaN();
};

// The report of a direct fit, with `options` the options it ran with (FitDirectCheckingTilt's
// `used`: a tilt found sets fit_rotation), areal density [kg/m²] and the fit's notes ("note":
// "; "-joined, null for none); the classic outputs added (AddClassicOutputs). Lengths in mm,
// constants' σ in KES. Needs fit.law.
nlohmann::json FitReportJson(const DirectFitSummary& fit, const DirectFitOptions& options,
                             double areal_density, const std::vector<std::string>& notes,
                             const FitReportOptions& report = {});

// Clapp's fit graded as the direct fit is: each profile against the strip re-simulated with the
// fitted law at the length of Clapp's smooth curve, through the edge (Clapp's method has no
// offset). One comparison per profile, in order. Needs fit.law.
std::vector<ProfileComparison> GradeClappFit(const ClappResult& fit,
                                             const std::vector<Profile>& profiles,
                                             double areal_density);

// The report of Clapp's fit of `profiles`, `graded` by GradeClappFit; the classic outputs added.
nlohmann::json FitReportJson(const ClappResult& fit, const std::vector<Profile>& profiles,
                             const std::vector<ProfileComparison>& graded, double areal_density);

// What the 41.5° test would report for `law` at areal density [kg/m²] (docs/spec/cantilever.md),
// and how that G relates to b1 and b2: crossing_overhang_mm, bending_length_mm,
// flexural_rigidity_{uNm,mgcm,gfcm}, G_over_b1, G_over_b2 and classic_note; only classic_note
// (why) when the law never crosses 41.5°.
void AddClassicOutputs(const BendingLaw& law, double areal_density, nlohmann::json* report);

}  // namespace textile

#endif  // TEXTILE_FIT_FIT_REPORT_H_
