// B_f(d) fits (seam_fit.h): Table 2 recovered from its own samples, covariance against the
// Monte Carlo spread, poor-fit reports, bad input.

#include "textile/fit/seam_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// The ACPM200's 17 ray distances for a seam along the push direction at the centre of a
// 200 mm sample: rays from 5 to 195 mm (5 mm margins), d = |z - 100|.
std::vector<double> CentreSeamDistances() {
  std::vector<double> d;
  for (int i = 0; i < 17; ++i) d.push_back(std::abs(5.0 + 190.0 * i / 16.0 - 100.0));
  return d;
}

std::vector<SeamSample> Sample(const SeamProfile& truth, const std::vector<double>& d, double sd,
                               std::mt19937* rng, bool give_sd) {
  std::normal_distribution<double> noise(0.0, sd);
  std::vector<SeamSample> out;
  for (double di : d) {
    SeamSample p;
    p.d_mm = di;
    p.factor = truth.StiffnessFactor(di) + (sd > 0.0 ? noise(*rng) : 0.0);
    if (give_sd) p.sd = sd;
    out.push_back(p);
  }
  return out;
}

TEST(SeamFit, RecoversEachTable2PolynomialExactlyWithoutNoise) {
  for (const std::string& type : SeamPresetNames()) {
    const SeamProfile truth = SeamPreset(type);
    std::mt19937 rng(1);
    const SeamFitSummary fit = FitSeamFactor(Sample(truth, CentreSeamDistances(), 0.0, &rng, false));
    for (int k = 0; k < 3; ++k) {
      // Round-off only: the design matrix (d², d, 1) up to d = 95 mm is well conditioned.
      EXPECT_NEAR(fit.coefficients_mm[k], truth.coefficients_mm[k],
                  1e-9 * std::abs(truth.coefficients_mm[2]) / std::pow(100.0, 2 - k))
          << type << " coefficient " << k;
    }
    EXPECT_LT(fit.rms, 1e-12) << type;
    EXPECT_FALSE(fit.poor) << type;
    EXPECT_EQ(fit.profile.type, "fitted");
    EXPECT_DOUBLE_EQ(fit.profile.range_mm[0], 0.0);
    EXPECT_DOUBLE_EQ(fit.profile.range_mm[1], 95.0);
  }
}

TEST(SeamFit, RecoversTable2WithNoiseWithinItsStatedUncertainty) {
  // sd 0.05 on the factor (a few % of B_f): each coefficient within 4σ of the truth (fixed seed,
  // 18 comparisons; 4σ is exceeded with probability 6e-5 each).
  std::mt19937 rng(7);
  for (const std::string& type : SeamPresetNames()) {
    const SeamProfile truth = SeamPreset(type);
    for (bool give_sd : {true, false}) {
      const SeamFitSummary fit =
          FitSeamFactor(Sample(truth, CentreSeamDistances(), 0.05, &rng, give_sd));
      ASSERT_TRUE(fit.covariance_known);
      EXPECT_EQ(fit.weighted, give_sd);
      for (int k = 0; k < 3; ++k) {
        const double sigma = std::sqrt(fit.covariance(k, k));
        EXPECT_LT(std::abs(fit.coefficients_mm[k] - truth.coefficients_mm[k]), 4.0 * sigma)
            << type << " coefficient " << k << " sd given " << give_sd;
      }
      EXPECT_NEAR(fit.rms, 0.05, 0.03) << type;  // 14 dof: the rms scatters by ~20 %
    }
  }
}

TEST(SeamFit, CovarianceMatchesTheMonteCarloSpread) {
  // 3000 noisy C-plain runs with known sd: the sample covariance of the fitted coefficients
  // must match (XᵀWX)⁻¹. A variance estimated from N runs has relative sd √(2/N) = 2.6 %;
  // 12 % is 4.6 of those. Correlations: sd ≈ (1 - ρ²)/√N ≤ 0.02; 0.06 allowed.
  const SeamProfile truth = SeamPreset("C-plain");
  const std::vector<double> d = CentreSeamDistances();
  std::mt19937 rng(11);
  constexpr int kRuns = 3000;
  std::vector<Eigen::Vector3d> coefficients;
  Eigen::Matrix3d reported;
  for (int r = 0; r < kRuns; ++r) {
    const SeamFitSummary fit = FitSeamFactor(Sample(truth, d, 0.1, &rng, true));
    coefficients.emplace_back(fit.coefficients_mm[0], fit.coefficients_mm[1],
                              fit.coefficients_mm[2]);
    reported = fit.covariance;  // the same for every run: depends on d and sd only
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& c : coefficients) mean += c / kRuns;
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  for (const auto& c : coefficients) sample += (c - mean) * (c - mean).transpose() / (kRuns - 1);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sample(k, k) / reported(k, k), 1.0, 0.12) << "variance " << k;
    // The estimator is unbiased: the mean lies within 4 standard errors of the truth.
    EXPECT_NEAR(mean(k), truth.coefficients_mm[k], 4.0 * std::sqrt(reported(k, k) / kRuns)) << k;
    for (int l = 0; l < k; ++l) {
      const double rho_sample = sample(k, l) / std::sqrt(sample(k, k) * sample(l, l));
      const double rho_reported = reported(k, l) / std::sqrt(reported(k, k) * reported(l, l));
      EXPECT_NEAR(rho_sample, rho_reported, 0.06) << k << "," << l;
    }
  }
}

TEST(SeamFit, UnweightedCovarianceUsesTheScatter) {
  // Without sd the covariance scales with the residual variance: same data shape, twice the
  // noise realisation amplitude, four times the covariance.
  const SeamProfile truth = SeamPreset("B-plain");
  std::mt19937 rng(3);
  std::vector<SeamSample> a = Sample(truth, CentreSeamDistances(), 0.05, &rng, false);
  std::vector<SeamSample> b = a;
  for (size_t i = 0; i < a.size(); ++i)
    b[i].factor = truth.StiffnessFactor(a[i].d_mm) + 2.0 * (a[i].factor - truth.StiffnessFactor(a[i].d_mm));
  const SeamFitSummary fa = FitSeamFactor(a), fb = FitSeamFactor(b);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(fb.covariance(k, k) / fa.covariance(k, k), 4.0, 1e-9);
}

TEST(SeamFit, ThreePointsWithoutSdHaveNoCovariance) {
  const SeamFitSummary fit = FitSeamFactor({{0, 3.0}, {10, 2.5}, {30, 2.0}});
  EXPECT_EQ(fit.dof, 0);
  EXPECT_FALSE(fit.covariance_known);
  EXPECT_FALSE(fit.profile.covariance.has_value());
  EXPECT_TRUE(fit.Report()["coefficients_sd"][0].is_null());
}

// Factors that do not vary (a seam that changes nothing) are fitted exactly: r² = 1, not NaN
// and a "poor" fit; a factor that varies with no trend the quadratic can follow is still poor.
TEST(SeamFit, ConstantFactorsAreAPerfectFitNotAPoorOne) {
  const SeamFitSummary flat = FitSeamFactor({{0, 1.0}, {10, 1.0}, {20, 1.0}, {40, 1.0}, {60, 1.0}});
  EXPECT_DOUBLE_EQ(flat.r2, 1.0);
  EXPECT_FALSE(flat.poor) << flat.poor_reason;
  EXPECT_NEAR(flat.profile.StiffnessFactor(30.0), 1.0, 1e-9);
  EXPECT_EQ(flat.BriefReport().find("nan"), std::string::npos) << flat.BriefReport();
}

TEST(SeamFit, ReportsAPoorFit) {
  // A step in the factor is no quadratic: r² well below 0.9 without sd ...
  std::vector<SeamSample> step;
  for (double d : CentreSeamDistances()) step.push_back({d, d < 20 ? 4.0 : 1.5 + 0.3 * std::sin(d)});
  const SeamFitSummary unweighted = FitSeamFactor(step);
  EXPECT_TRUE(unweighted.poor);
  EXPECT_NE(unweighted.poor_reason.find("r2"), std::string::npos) << unweighted.poor_reason;
  // ... and with an sd far below the misfit, χ² rejects it.
  for (auto& p : step) p.sd = 0.01;
  const SeamFitSummary weighted = FitSeamFactor(step);
  EXPECT_TRUE(weighted.poor);
  EXPECT_LT(weighted.chi2_probability, 1e-3);
  EXPECT_NE(weighted.poor_reason.find("chi2/dof"), std::string::npos);
  EXPECT_TRUE(weighted.Report()["poor"].get<bool>());
  // An honest sd on good data is not poor.
  std::mt19937 rng(5);
  const SeamFitSummary good =
      FitSeamFactor(Sample(SeamPreset("A-plain"), CentreSeamDistances(), 0.05, &rng, true));
  EXPECT_FALSE(good.poor) << good.poor_reason;
  EXPECT_GT(good.chi2_probability, 1e-3);
}

TEST(SeamFit, RefusesBadInput) {
  auto expect_refused = [](const std::vector<SeamSample>& s, const std::string& fragment) {
    try {
      FitSeamFactor(s);
      ADD_FAILURE() << "accepted; expected '" << fragment << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expect_refused({}, "at least 3 points");
  expect_refused({{0, 3}, {10, 2}}, "at least 3 points");
  expect_refused({{0, 3}, {10, 2}, {10, 2.1}, {0, 3.1}}, "2 distinct distance");
  expect_refused({{0, 3}, {10, 2}, {nan, 2}}, "finite");
  expect_refused({{0, 3}, {10, inf}, {20, 2}}, "finite");
  expect_refused({{0, 3}, {-1, 2}, {20, 2}}, "negative");
  expect_refused({{0, 3}, {10, 0}, {20, 2}}, "factor");
  expect_refused({{0, 3, 0.1}, {10, 2, 0.0}, {20, 2, 0.1}}, "sd = 0");
  expect_refused({{0, 3, 0.1}, {10, 2, -0.1}, {20, 2, 0.1}}, "must be > 0");
  expect_refused({{0, 3, 0.1}, {10, 2}, {20, 2, 0.1}}, "all or none");
  SeamFitOptions bad;
  bad.layers = 0;
  EXPECT_THROW(FitSeamFactor({{0, 3}, {10, 2}, {20, 1.5}}, bad), InputError);
}

TEST(SeamFit, AFitThatCannotBeASeamProfileIsAComputeError) {
  // Factors falling on a line that reaches 0 at 60 mm, before d_max = 100 mm (given: by
  // default d_max is the data's 30 mm, and the line is a fine profile there).
  SeamFitOptions o;
  o.influence_mm = 100.0;
  try {
    FitSeamFactor({{0, 3.0}, {10, 2.5}, {20, 2.0}, {30, 1.5}}, o);
    ADD_FAILURE() << "accepted";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot serve as a seam profile"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(FitSeamFactor({{0, 3.0}, {10, 2.5}, {20, 2.0}, {30, 1.5}}));
}

TEST(SeamFitCsv, ParsesWithAndWithoutSd) {
  const auto a = ParseSeamSamplesCsv("# a comment\nd_mm,factor\n0,3.5\n 10 , 3.2\n\n20,3.0\n", "a.csv");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_DOUBLE_EQ(a[1].d_mm, 10.0);
  EXPECT_DOUBLE_EQ(a[1].factor, 3.2);
  EXPECT_TRUE(std::isnan(a[1].sd));
  const auto b = ParseSeamSamplesCsv("d_mm,factor,sd\n0,3.5,0.1\n10,3.2,0.2\n", "b.csv");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_DOUBLE_EQ(b[1].sd, 0.2);
}

TEST(SeamFitCsv, RefusesMalformedRowsNamingFileAndLine) {
  struct Case {
    const char* text;
    const char* fragment;
  };
  for (const Case& c : {Case{"", "empty"}, Case{"d,factor\n0,1\n", "header"},
                        Case{"d_mm,factor\n0,abc\n", "x.csv:2: 'abc' is not a number"},
                        Case{"d_mm,factor\n0,1,2\n", "x.csv:2: expected 2 values"},
                        Case{"d_mm,factor\n0\n", "expected 2 values"},
                        Case{"d_mm,factor\n0,nan\n", "x.csv:2"},
                        Case{"d_mm,factor\n-3,1\n", "x.csv:2: d_mm = -3 is negative"},
                        Case{"d_mm,factor,sd\n3,1,0\n", "sd = 0"},
                        Case{"d_mm,factor\n3,-1\n", "factor = -1"}}) {
    try {
      ParseSeamSamplesCsv(c.text, "x.csv");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.fragment), std::string::npos) << e.what();
    }
  }
}

TEST(SeamFitAcpm, ReadsRaysAndRefusesAPlainSample) {
  nlohmann::json r = {{"model", "elastica"},
                      {"rays", {{{"z_mm", 5}, {"d_mm", 95}, {"factor", 1.9}},
                                {{"z_mm", 100}, {"d_mm", 0}, {"factor", 3.4}, {"factor_sd", 0.1}}}}};
  const auto s = SeamSamplesFromAcpmJson(r, "r.json");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_DOUBLE_EQ(s[0].d_mm, 95.0);
  EXPECT_DOUBLE_EQ(s[1].factor, 3.4);
  EXPECT_DOUBLE_EQ(s[1].sd, 0.1);
  r["rays"][0]["d_mm"] = nullptr;
  EXPECT_THROW(
      {
        try {
          SeamSamplesFromAcpmJson(r, "r.json");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("r.json: rays[0].d_mm: no seam distance"),
                    std::string::npos)
              << e.what();
          throw;
        }
      },
      InputError);
  EXPECT_THROW(SeamSamplesFromAcpmJson({{"model", "elastica"}}, "r.json"), InputError);
  EXPECT_THROW(SeamSamplesFromAcpmJson({{"rays", {{{"d_mm", "5"}, {"factor", 1}}}}}, "r.json"),
               InputError);
}

TEST(SeamFit, WrittenProfileReadsBack) {
  std::mt19937 rng(2);
  SeamFitOptions o;
  o.layers = 4;
  o.name = "test seam";
  const SeamFitSummary fit =
      FitSeamFactor(Sample(SeamPreset("C-twill"), CentreSeamDistances(), 0.05, &rng, true), o);
  const nlohmann::json j = SeamProfileToJson(fit.profile);
  const SeamProfile back = ParseSeamJson(j.dump(), "fitted.json");
  EXPECT_EQ(back.layers, 4);
  EXPECT_EQ(back.type, "fitted");
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_NEAR((*back.covariance - fit.covariance).norm(), 0.0, 1e-12 * fit.covariance.norm());
  EXPECT_EQ(back.fit["dof"].get<int>(), 14);
  EXPECT_DOUBLE_EQ(back.coefficients_mm[1], fit.coefficients_mm[1]);
}

// tests/bad_inputs/files/seam-ok.csv: d = 0-30 mm, falling from 3 to 1.8. The quadratic
// through it has its minimum at 42 mm and climbs to 4.17 at 100 mm.
std::vector<SeamSample> FallingTo30() { return {{0, 3.0}, {10, 2.5}, {20, 2.0}, {30, 1.8}}; }

TEST(SeamFitInfluence, DefaultsToTheDataAndNeverRisesBeyondThem) {
  const SeamFitSummary fit = FitSeamFactor(FallingTo30());
  EXPECT_TRUE(fit.influence_from_data);
  EXPECT_DOUBLE_EQ(fit.profile.influence_mm, 30.0);
  EXPECT_TRUE(fit.notes.empty()) << JoinNoteTexts(fit.notes, "; ");
  // Beyond the data S only falls, from B_f(30) to 1 at the end of the fade (0.01 mm sweep).
  const SeamProfile& p = fit.profile;
  double previous = p.Multiplier(30.0);
  EXPECT_DOUBLE_EQ(previous, p.StiffnessFactor(30.0));
  for (double d = 30.01; d <= 200.0; d += 0.01) {
    EXPECT_LE(p.Multiplier(d), previous + 1e-12) << d;
    previous = p.Multiplier(d);
  }
  EXPECT_EQ(p.Multiplier(30.0 + p.fade_mm), 1.0);
  EXPECT_EQ(fit.Report()["influence_from"], "data");
}

TEST(SeamFitInfluence, AGivenRangeBeyondTheDataWhereTheFitRisesIsRefused) {
  SeamFitOptions o;
  o.influence_mm = 100.0;  // the old default: S(75) = 2.47 and S(100) = 4.17 were written
  try {
    FitSeamFactor(FallingTo30(), o);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("rises from 1.671 at 42.33 mm to 4.165 at 100 mm"), std::string::npos)
        << what;
    EXPECT_NE(what.find("end it by 42.33 mm"), std::string::npos) << what;
  }
  // Up to the polynomial's minimum it only falls: an extrapolation, said in a note.
  o.influence_mm = 40.0;
  const SeamFitSummary fit = FitSeamFactor(FallingTo30(), o);
  EXPECT_FALSE(fit.influence_from_data);
  ASSERT_EQ(fit.notes.size(), 1u);
  EXPECT_EQ(fit.notes[0].code, "influence_beyond_data");
  EXPECT_NE(fit.notes[0].text.find("reaches beyond the data (d up to 30 mm)"), std::string::npos)
      << fit.notes[0].text;
  // A rise within rise_tolerance (round-off of a flat fit) is no reason to refuse.
  o.influence_mm = 43.0;
  EXPECT_NO_THROW(FitSeamFactor(FallingTo30(), o));
}

TEST(SeamFitInfluence, AGivenRangeInsideTheDataSaysWhatItCuts) {
  SeamFitOptions o;
  o.influence_mm = 10.0;
  std::vector<SeamSample> data = FallingTo30();
  data.push_back({40, 1.6});
  const SeamFitSummary fit = FitSeamFactor(data, o);
  EXPECT_EQ(fit.profile.Multiplier(30.0), 1.0);  // the data say 1.8
  ASSERT_EQ(fit.notes.size(), 1u);
  EXPECT_EQ(fit.notes[0].code, "influence_inside_data");
  EXPECT_NE(fit.notes[0].text.find("ends inside the data (d up to 40 mm)"), std::string::npos)
      << fit.notes[0].text;
  EXPECT_NE(fit.notes[0].text.find("3 point(s) beyond it"), std::string::npos) << fit.notes[0].text;
  EXPECT_NE(fit.notes[0].text.find("by up to 0.8 (S = 1 where the data say 1.8 at 30 mm)"),
            std::string::npos)
      << fit.notes[0].text;
  EXPECT_EQ(fit.Report()["notes"], nlohmann::json::array({fit.notes[0].text}));
}

TEST(SeamFitInfluence, AFadeThatOvershootsAFitRisingAtTheEndOfTheDataIsNoted) {
  // Factors with a minimum inside the data: B_f rises at 60 mm, the fade starts with that
  // slope and first climbs.
  const SeamFitSummary fit = FitSeamFactor({{0, 3.0}, {20, 2.0}, {40, 1.8}, {60, 2.2}});
  ASSERT_EQ(fit.notes.size(), 1u);
  EXPECT_EQ(fit.notes[0].code, "fade_overshoot");
  EXPECT_NE(fit.notes[0].text.find("still rises at d_max = 60 mm"), std::string::npos)
      << fit.notes[0].text;
}

// Factors of 2 ± 0.001 (a flat profile, as the shell ACPM gives an along seam) leave almost no
// variance to explain: r² is 0.03, yet the fit is as good as the data. It is poor only when the
// residuals are also large against the factors.
TEST(SeamFit, AFlatProfileFittedToItsScatterIsNotPoor) {
  std::vector<SeamSample> flat;
  for (int i = 0; i <= 12; ++i) flat.push_back({5.0 * i, i % 2 == 0 ? 2.001 : 1.999});
  const SeamFitSummary fit = FitSeamFactor(flat);
  EXPECT_LT(fit.r2, 0.9);
  EXPECT_LT(fit.rms_relative, 1e-3);
  EXPECT_FALSE(fit.poor) << fit.poor_reason;
  // The same pattern at ±0.2 (10 % of the factor) is poor.
  for (auto& p : flat) p.factor = 2.0 + 200.0 * (p.factor - 2.0);
  const SeamFitSummary noisy = FitSeamFactor(flat);
  EXPECT_TRUE(noisy.poor);
  EXPECT_NE(noisy.poor_reason.find("% of the mean factor"), std::string::npos) << noisy.poor_reason;
}

TEST(SeamFitCsv, SkipsAUtf8ByteOrderMark) {
  const std::string bom = "\xEF\xBB\xBF";
  const auto s = ParseSeamSamplesCsv(bom + "d_mm,factor\n0,3\n10,2.5\n", "excel.csv");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_DOUBLE_EQ(s[1].factor, 2.5);
  // Only at the start: a mark elsewhere is not a number.
  EXPECT_THROW(ParseSeamSamplesCsv("d_mm,factor\n" + bom + "0,3\n", "x.csv"), InputError);
}

TEST(SeamFit, RefusesFactorsThatAreAllBelowOne) {
  // 0.5-0.8: S = max(1, B_f) would be 1 everywhere; the inverse ratio is what was meant.
  try {
    FitSeamFactor({{0, 0.5}, {10, 0.6}, {20, 0.7}, {40, 0.8}});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("every factor is below 1 (0.5 to 0.8)"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("inverse is 1.25 to 2"), std::string::npos) << e.what();
  }
  // Factors that reach 1 (a seam with no effect far out, with scatter) are fine.
  EXPECT_NO_THROW(FitSeamFactor({{0, 1.5}, {10, 1.2}, {20, 0.98}, {40, 1.01}}));
}

TEST(SeamFitAcpm, LayersOfTheResultsSeam) {
  nlohmann::json r = {{"model", "shell"}, {"rays", nlohmann::json::array()}};
  EXPECT_EQ(SeamLayersFromAcpmJson(r, "r.json"), 0);  // no seam recorded
  r["seam"] = {{"direction", "none"}};
  EXPECT_EQ(SeamLayersFromAcpmJson(r, "r.json"), 0);
  r["seam"] = {{"direction", "along"}, {"profile", {{"layers", 4}}}};
  EXPECT_EQ(SeamLayersFromAcpmJson(r, "r.json"), 4);
  r["seam"]["profile"]["layers"] = 3.0;
  EXPECT_EQ(SeamLayersFromAcpmJson(r, "r.json"), 3);
  for (const nlohmann::json& bad : {nlohmann::json(3.5), nlohmann::json("4"), nlohmann::json()}) {
    r["seam"]["profile"]["layers"] = bad;
    try {
      SeamLayersFromAcpmJson(r, "r.json");
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("r.json: seam.profile.layers must be a whole number"),
                std::string::npos)
          << e.what();
    }
  }
  r["seam"]["profile"]["layers"] = 4294967298ull;  // would wrap to 2 as an int
  EXPECT_THROW(SeamLayersFromAcpmJson(r, "r.json"), InputError);
  r["seam"]["profile"]["layers"] = -2;
  EXPECT_THROW(SeamLayersFromAcpmJson(r, "r.json"), InputError);
}

}  // namespace
}  // namespace textile
