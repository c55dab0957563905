#include "textile/fit/fit_material.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "textile/fit/clapp.h"
#include "textile/fit/direct_fit.h"
#include "textile/fit/fit_report.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

std::string Number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A fit can only hand out a law that a material file accepts: Clapp's regression, for one,
// can wander to constants no fabric has when the polynomial is poor.
void CheckFittedLaw(const BendingLaw& law, double rho, const std::string& method) {
  if (std::string why; !FittedLawMaterial(law, rho, &why))
    throw ComputeError("fit (" + method + ") gave an implausible law: " + why);
}

FittedMaterial FitDirect(const std::vector<Profile>& profiles, const FitMaterialOptions& a) {
  const double rho = a.areal_density;
  DirectFitOptions o;
  o.fit_offset = !a.thickness && !a.no_offset;
  o.offset = a.thickness ? *a.thickness / 2.0 : 0.0;
  o.fit_rotation = a.fit_rotation;
  o.robust_scale = units::MmToM(a.robust_scale_mm);
  std::vector<std::string> notes;
  const DirectFitSummary fit = FitDirectCheckingTilt(profiles, rho, o, &notes, &o);
  if (!fit.converged) throw ComputeError("fit: " + fit.message);
  FittedMaterial out;
  const BendingLaw law = *fit.law;
  out.notes = notes;
  out.kappa_max = fit.kappa_max;
  out.brief = fit.BriefReport();
  for (size_t i = 0; i < profiles.size(); ++i) {
    out.comparisons.push_back(CompareWithElastica(law, rho, profiles[i],
                                                  fit.profiles[i].overhang, fit.offset,
                                                  fit.rotation));
  }
  CheckFittedLaw(law, rho, "direct");
  out.material = LawOnlyMaterial(law, rho);
  out.material.fit =
      FitReportJson(fit, o, rho, notes, {.robust_scale_mm = a.robust_scale_mm});
  return out;
}

FittedMaterial FitByClapp(const std::vector<Profile>& profiles, double rho) {
  const ClappResult fit = FitClapp(profiles, rho);
  if (!fit.success || !fit.law) throw ComputeError("fit (clapp): " + fit.message);
  FittedMaterial out;
  out.kappa_max = fit.kappa_max;
  out.brief = fit.BriefReport();
  out.comparisons = GradeClappFit(fit, profiles, rho);
  CheckFittedLaw(*fit.law, rho, "clapp");
  out.material = LawOnlyMaterial(*fit.law, rho);
  out.material.fit = FitReportJson(fit, profiles, out.comparisons, rho);
  return out;
}

}  // namespace

void CheckFitMaterialOptions(const FitMaterialOptions& a) {
  const double gsm = units::SiToGsm(a.areal_density);
  if (!std::isfinite(gsm) || gsm <= 0.0) throw InputError("--gsm must be a number > 0 (g/m²)");
  if (gsm < 1.0 || gsm > 1e4)
    throw InputError("--gsm " + Number(gsm) + " g/m² is implausible (1 .. 10000)");
  const double r = a.robust_scale_mm;
  if (!(r == 0.0 || (r >= 0.001 && r <= 100.0)))
    throw InputError("--robust-mm must be 0 (off) or in [0.001, 100] mm");
  const double t_mm = a.thickness ? units::MToMm(*a.thickness) : 0.0;
  if (a.thickness && !(t_mm > 0.0 && t_mm <= 6.0))
    throw InputError(
        "--thickness-mm must lie in (0, 6] mm (a thicker strip's mid-line starts above what a "
        "profile may rise), got " +
        Number(t_mm));
  if (a.thickness && a.no_offset)
    throw InputError("--thickness-mm and --no-offset contradict each other (offset t/2 vs 0)");
  if (a.method != FitMethod::kClapp) return;
  // Clapp's polynomial takes the profiles as they are: no offset, rotation or robust loss.
  for (const auto& [given, flag] :
       {std::pair{a.thickness.has_value(), "--thickness-mm"}, std::pair{a.no_offset, "--no-offset"},
        std::pair{a.fit_rotation, "--fit-rotation"}, std::pair{a.robust_given, "--robust-mm"}})
    if (given)
      throw InputError(std::string(flag) +
                       ": an option of the direct fit; --method clapp fits the profiles as they are");
}

FittedMaterial FitMaterial(const std::vector<Profile>& profiles, const FitMaterialOptions& options) {
  CheckFitMaterialOptions(options);
  if (profiles.empty()) throw InputError("fit: no profiles given");
  FittedMaterial out = options.method == FitMethod::kDirect
                           ? FitDirect(profiles, options)
                           : FitByClapp(profiles, options.areal_density);
  out.material.name = options.name.empty()
                          ? "fitted from " + ProfileInputStem(profiles.front().source)
                          : options.name;
  return out;
}

std::string ProfileInputStem(const std::string& path) {
  std::string stem = std::filesystem::path(path).stem().string();
  const std::string suffix = ".profile";
  if (stem.size() > suffix.size() && stem.ends_with(suffix)) stem.resize(stem.size() - suffix.size());
  return stem;
}

}  // namespace textile
