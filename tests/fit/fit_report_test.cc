#include "textile/fit/fit_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "textile/fit/synthetic_profile.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kRho = 0.2;  // 200 g/m² [kg/m²]
const BendingLaw kFig8 = BendingLaw::FromKes(0.1, 0.0892, -0.0092);

std::vector<Profile> Strip(const std::vector<double>& overhangs) {
  std::vector<Profile> out;
  for (size_t i = 0; i < overhangs.size(); ++i) {
    SyntheticOptions o;
    o.noise_sigma = 0.1e-3;
    o.vertical_offset = 0.2e-3;
    o.chord_arc_length = true;
    o.seed = 7 + i;
    out.push_back(SyntheticProfile(kFig8, kRho, overhangs[i], o));
    out.back().source = "L" + std::to_string(static_cast<int>(std::lround(overhangs[i] * 1e3)));
  }
  return out;
}

struct DirectFit {
  DirectFitSummary fit;
  DirectFitOptions used;
};

DirectFit FitFig8() {
  DirectFit d;
  d.fit = FitDirectCheckingTilt(Strip({0.04, 0.07}), kRho, {}, nullptr, &d.used);
  return d;
}

TEST(FitReportJson, DirectFitCarriesItsFiguresInMillimetresAndKes) {
  const DirectFit d = FitFig8();
  ASSERT_TRUE(d.fit.converged) << d.fit.message;
  const nlohmann::json j = FitReportJson(d.fit, d.used, kRho, {});
  EXPECT_EQ(j["method"], "direct");
  EXPECT_EQ(j["sd_units"], "kes");
  EXPECT_EQ(j["rms_mm"].get<double>(), units::MToMm(d.fit.rms));
  EXPECT_EQ(j["offset_mm"].get<double>(), units::MToMm(d.fit.offset));
  EXPECT_EQ(j["offset_fitted"].get<bool>(), d.used.fit_offset);
  EXPECT_EQ(j["robust_scale_mm"].get<double>(), units::MToMm(d.used.robust_scale));
  EXPECT_TRUE(j["note"].is_null());  // no notes
  ASSERT_EQ(j["profiles"].size(), 2u);
  EXPECT_EQ(j["profiles"][1]["source"], "L70");
  EXPECT_EQ(j["profiles"][1]["overhang_mm"].get<double>(),
            units::MToMm(d.fit.profiles[1].overhang));
  // The diagnostics, by default.
  ASSERT_EQ(j["covariance_kes"].size(), 3u);
  EXPECT_EQ(j["covariance_kes"][0].size(), 3u);
  EXPECT_EQ(j["start"], d.fit.start);
  // The classic outputs: fig. 8's fabric crosses 41.5° (its G relates to b1 as a number near 1).
  ASSERT_TRUE(j.contains("bending_length_mm"));
  EXPECT_GT(j["bending_length_mm"].get<double>(), 0.0);
  EXPECT_GT(j["G_over_b1"].get<double>(), 0.5);
  EXPECT_LT(j["G_over_b1"].get<double>(), 2.0);
  EXPECT_TRUE(j["classic_note"].is_string());
}

TEST(FitReportJson, NotesJoinAndOptionsShapeTheReport) {
  const DirectFit d = FitFig8();
  ASSERT_TRUE(d.fit.converged) << d.fit.message;
  const nlohmann::json j = FitReportJson(d.fit, d.used, kRho, {"first", "second"},
                                         {.diagnostics = false, .robust_scale_mm = 0.017});
  EXPECT_EQ(j["note"], "first; second");
  EXPECT_EQ(j["robust_scale_mm"].get<double>(), 0.017);  // as given, not mm → m → mm
  for (const char* key : {"covariance_kes", "start", "point_scatter_mm", "fit_pattern"})
    EXPECT_FALSE(j.contains(key)) << key;
  EXPECT_TRUE(j.contains("b1_sd"));
}

TEST(FitReportJson, ClappFitIsGradedByTheElasticaAtItsCurveLength) {
  const std::vector<Profile> profiles = Strip({0.04, 0.07});
  const ClappResult fit = FitClapp(profiles, kRho);
  ASSERT_TRUE(fit.success && fit.law) << fit.message;
  const std::vector<ProfileComparison> graded = GradeClappFit(fit, profiles, kRho);
  ASSERT_EQ(graded.size(), 2u);
  const nlohmann::json j = FitReportJson(fit, profiles, graded, kRho);
  EXPECT_EQ(j["method"], "clapp");
  ASSERT_EQ(j["profiles"].size(), 2u);
  EXPECT_EQ(j["profiles"][0]["rms_mm"].get<double>(), units::MToMm(graded[0].rms));
  EXPECT_EQ(j["profiles"][0]["overhang_mm"].get<double>(),
            units::MToMm(fit.profiles[0].curve_length));
  // The overall rms pools every point: between the two profiles' own.
  const double lo = std::min(graded[0].rms, graded[1].rms);
  const double hi = std::max(graded[0].rms, graded[1].rms);
  EXPECT_GE(j["rms_mm"].get<double>(), units::MToMm(lo) * (1 - 1e-12));
  EXPECT_LE(j["rms_mm"].get<double>(), units::MToMm(hi) * (1 + 1e-12));
  // The grading is the elastica through the edge at Clapp's curve length (no offset).
  const ProfileComparison direct =
      CompareWithElastica(*fit.law, kRho, profiles[1], fit.profiles[1].curve_length, 0.0);
  EXPECT_EQ(graded[1].rms, direct.rms);
  EXPECT_EQ(graded[1].max, direct.max);
  EXPECT_TRUE(j.contains("classic_note"));
}

TEST(AddClassicOutputs, AddsTheFortyOnePointFiveDegreeFigures) {
  nlohmann::json j = nlohmann::json::object();
  AddClassicOutputs(kFig8, kRho, &j);
  for (const char* key : {"crossing_overhang_mm", "bending_length_mm", "flexural_rigidity_uNm",
                          "flexural_rigidity_mgcm", "flexural_rigidity_gfcm", "G_over_b1",
                          "G_over_b2", "classic_note"})
    EXPECT_TRUE(j.contains(key)) << key;
  // G/b1 and G in µN·m describe the same G (relative round-off only).
  const double g_uNm = j["flexural_rigidity_uNm"].get<double>();
  EXPECT_GT(g_uNm, 0.0);
  EXPECT_NEAR(j["G_over_b1"].get<double>() * kFig8.b1() * 1e6, g_uNm, 1e-12 * g_uNm);
  EXPECT_GT(j["crossing_overhang_mm"].get<double>(), j["bending_length_mm"].get<double>());
}

TEST(FittedLawMaterial, RefusesALawNoMaterialFileTakesInTheFilesWords) {
  std::string why;
  const auto m = FittedLawMaterial(BendingLaw::FromKes(2e5, 100, -1e7), kRho, &why);
  EXPECT_FALSE(m.has_value());
  EXPECT_EQ(why,
            "fitted law: bending.b1: suspicious magnitude 200000 gf·cm, outside the textile range "
            "1e-05 .. 100000 gf·cm (units: kes)");
  const auto fig8 = FittedLawMaterial(kFig8, kRho, &why);
  ASSERT_TRUE(fig8.has_value()) << why;
  EXPECT_EQ(why, "");
  EXPECT_EQ(fig8->areal_density, kRho);
  EXPECT_EQ(fig8->bending.b1(), kFig8.b1());
}

}  // namespace
}  // namespace textile
