#include "textile/fit/fit_report.h"

#include <cmath>

#include "textile/sim/elastica/cantilever_outputs.h"
#include "textile/sim/core/join_text.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using nlohmann::json;

// JSON null for a value that is not available (an undetermined constant's σ).
json OrNull(double v) { return std::isfinite(v) ? json(v) : json(); }

// The 3×3 covariance of (b1, b2, c1) in gf·cm, gf·cm, gf·cm² (rows and columns in that order).
json CovarianceKesJson(const Eigen::Matrix3d& si) {
  const double f[3] = {units::SiStiffnessToKes(1.0), units::SiStiffnessToKes(1.0),
                       units::SiQuadraticToKes(1.0)};
  json rows = json::array();
  for (int i = 0; i < 3; ++i) {
    json row = json::array();
    for (int j = 0; j < 3; ++j) row.push_back(OrNull(si(i, j) * f[i] * f[j]));
    rows.push_back(row);
  }
  return rows;
}

json ProfilesJson(const std::vector<ProfileFitReport>& profiles) {
  json per = json::array();
  for (const ProfileFitReport& r : profiles) {
    per.push_back({{"source", r.source},
                   {"overhang_mm", units::MToMm(r.overhang)},
                   {"data_length_mm", units::MToMm(r.data_length)},
                   {"rms_mm", units::MToMm(r.rms)},
                   {"max_mm", units::MToMm(r.max)},
                   {"clamp_curvature_per_cm", units::SiCurvatureToKes(r.clamp_curvature)}});
  }
  return per;
}

}  // namespace

std::optional<Material> FittedLawMaterial(const BendingLaw& law, double areal_density,
                                          std::string* why) {
  Material m = LawOnlyMaterial(law, areal_density);
  std::string problem;
  if (!m.Check(&problem)) {
    if (why) *why = "fitted law: " + problem;
    return std::nullopt;
  }
  if (why) why->clear();
  return m;
}

nlohmann::json FitReportJson(const DirectFitSummary& fit, const DirectFitOptions& options,
                             double areal_density, const std::vector<std::string>& notes,
                             const FitReportOptions& report) {
  const std::string note = JoinText(notes, "; ");
  json j = {
      {"method", "direct"},
      {"b1_sd", OrNull(units::SiStiffnessToKes(fit.b1_sd))},
      {"b2_sd", OrNull(units::SiStiffnessToKes(fit.b2_sd))},
      {"c1_sd", OrNull(units::SiQuadraticToKes(fit.c1_sd))},
      {"sd_units", "kes"},
      {"rms_mm", units::MToMm(fit.rms)},
      {"b1_observed", fit.b1_observed},
      {"b2_observed", fit.b2_observed},
      {"c1_observed", fit.c1_observed},
      {"observability", fit.observability},
      {"kappa_max_per_cm", units::SiCurvatureToKes(fit.kappa_max)},
      {"offset_mm", units::MToMm(fit.offset)},
      {"offset_fitted", options.fit_offset},
      {"rotation_deg", fit.rotation * 180.0 / M_PI},
      {"rotation_fitted", options.fit_rotation},
      {"note", note.empty() ? json() : json(note)},
      {"robust_scale_mm", std::isnan(report.robust_scale_mm) ? units::MToMm(options.robust_scale)
                                                             : report.robust_scale_mm},
      {"iterations", fit.iterations},
      {"seconds", fit.seconds},
      {"profiles", ProfilesJson(fit.profiles)}};
  if (report.diagnostics) {
    j["covariance_kes"] = CovarianceKesJson(fit.covariance);
    j["start"] = fit.start;
    j["point_scatter_mm"] = units::MToMm(fit.point_scatter);
    j["fit_pattern"] = fit.fit_pattern.empty() ? json() : json(fit.fit_pattern);
  }
  AddClassicOutputs(*fit.law, areal_density, &j);
  return j;
}

std::vector<ProfileComparison> GradeClappFit(const ClappResult& fit,
                                             const std::vector<Profile>& profiles,
                                             double areal_density) {
  std::vector<ProfileComparison> graded;
  for (size_t i = 0; i < profiles.size(); ++i) {
    graded.push_back(CompareWithElastica(*fit.law, areal_density, profiles[i],
                                         fit.profiles[i].curve_length, 0.0));
  }
  return graded;
}

nlohmann::json FitReportJson(const ClappResult& fit, const std::vector<Profile>& profiles,
                             const std::vector<ProfileComparison>& graded, double areal_density) {
  json per = json::array();
  double s2 = 0.0;
  int n = 0;
  for (size_t i = 0; i < profiles.size(); ++i) {
    const ProfileComparison& c = graded[i];
    s2 += c.rms * c.rms * profiles[i].size();
    n += static_cast<int>(profiles[i].size());
    per.push_back({{"source", profiles[i].source},
                   {"overhang_mm", units::MToMm(fit.profiles[i].curve_length)},
                   {"data_length_mm", units::MToMm(profiles[i].s.back())},
                   {"rms_mm", units::MToMm(c.rms)},
                   {"max_mm", units::MToMm(c.max)},
                   {"polynomial_rms_mm", units::MToMm(fit.profiles[i].residual_rms)}});
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool sd = fit.covariance_available;
  json j = {{"method", "clapp"},
            {"b1_sd", OrNull(sd ? units::SiStiffnessToKes(fit.sd_b1) : nan)},
            {"b2_sd", OrNull(sd ? units::SiStiffnessToKes(fit.sd_b2) : nan)},
            {"c1_sd", OrNull(sd ? units::SiQuadraticToKes(fit.sd_c1) : nan)},
            {"sd_units", "kes"},
            {"rms_mm", units::MToMm(std::sqrt(s2 / n))},
            {"b2_observed", fit.b2_observed},
            {"kappa_max_per_cm", units::SiCurvatureToKes(fit.kappa_max)},
            {"moment_rms_gfcm_per_cm", units::SiMomentToKes(fit.moment_rms)},
            {"profiles", per}};
  AddClassicOutputs(*fit.law, areal_density, &j);
  return j;
}

void AddClassicOutputs(const BendingLaw& law, double areal_density, nlohmann::json* report) {
  const BarrierCrossing x = FindBarrierCrossing(law, areal_density);
  if (!x.converged) {
    (*report)["classic_note"] = "no 41.5° crossing: " + x.message;
    return;
  }
  const ClassicOutputs c = ComputeClassicOutputs(areal_density, x.overhang);
  (*report)["crossing_overhang_mm"] = units::MToMm(x.overhang);
  (*report)["bending_length_mm"] = units::MToMm(c.bending_length);
  (*report)["flexural_rigidity_uNm"] = c.rigidity_micro_nm();
  (*report)["flexural_rigidity_mgcm"] = c.rigidity_mg_cm();
  (*report)["flexural_rigidity_gfcm"] = c.rigidity_gf_cm();
  (*report)["G_over_b1"] = c.flexural_rigidity / law.b1();
  (*report)["G_over_b2"] = c.flexural_rigidity / law.b2();
  (*report)["classic_note"] = c.RelationToLaw(law);
}

}  // namespace textile
