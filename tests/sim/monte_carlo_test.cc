#include "textile/sim/law/monte_carlo.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"

namespace textile {
namespace {

Material Fitted(const nlohmann::json& covariance_kes) {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  m.fit["covariance_kes"] = covariance_kes;
  return m;
}

Eigen::Vector3d Constants(const Material& m) {
  return {m.bending.b1(), m.bending.b2(), m.bending.c1()};
}

// The draws' mean and covariance are the material's and the fit's (20000 draws: within a few
// of their sampling errors), only the law changes, and a seed repeats its draws.
TEST(MonteCarlo, DrawsFollowTheFitsCovariance) {
  const Material m = Fitted({{4e-6, 1e-6, -2e-6}, {1e-6, 1e-6, 0.0}, {-2e-6, 0.0, 4e-6}});
  const CovarianceSamples s = SampleFitCovariance(m, 20000, 7);
  ASSERT_EQ(s.materials.size(), 20000u);
  EXPECT_EQ(s.rejected, 0);  // sds of 1-2 % of b: every draw is a valid law
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Material& d : s.materials) mean += Constants(d) / 20000.0;
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (const Material& d : s.materials) {
    const Eigen::Vector3d e = Constants(d) - mean;
    c += e * e.transpose() / 19999.0;
  }
  const Eigen::Matrix3d expected = *MaterialFitCovariance(m);
  for (int i = 0; i < 3; ++i) {
    const double sd = std::sqrt(expected(i, i));
    EXPECT_NEAR(mean(i), Constants(m)(i), 4.0 * sd / std::sqrt(20000.0)) << i;
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(c(i, j), expected(i, j), 0.05 * sd * std::sqrt(expected(j, j))) << i << j;
  }
  EXPECT_EQ(s.materials[5].areal_density, m.areal_density);
  const CovarianceSamples again = SampleFitCovariance(m, 3, 7);
  EXPECT_EQ(Constants(again.materials[2]), Constants(s.materials[2]));
  EXPECT_NE(Constants(SampleFitCovariance(m, 3, 8).materials[2]), Constants(s.materials[2]));
}

// A covariance reaching past the valid laws (c1 ≥ 0 or κ0 < 0) is truncated and says so; one
// reaching mostly past them is refused.
TEST(MonteCarlo, DrawsOutsideTheValidLawsAreRedrawnAndCounted) {
  const CovarianceSamples s = SampleFitCovariance(Fitted({{0, 0, 0}, {0, 0, 0}, {0, 0, 1e-4}}), 200, 1);
  EXPECT_GT(s.rejected, 20);  // c1 = -0.0092 ± 0.01 gf·cm² crosses 0 a fifth of the time
  for (const Material& d : s.materials) EXPECT_LT(d.bending.c1(), 0.0);
  // b1 and b2 moving against each other by ±10 gf·cm: one of them is almost always negative.
  EXPECT_THROW(SampleFitCovariance(Fitted({{100, -100, 0}, {-100, 100, 0}, {0, 0, 1e-6}}), 50, 1),
               ComputeError);
}

TEST(MonteCarlo, NeedsACovarianceAndTwoSamples) {
  Material m = Fitted({{1e-6, 0, 0}, {0, 1e-6, 0}, {0, 0, 1e-8}});
  EXPECT_THROW(SampleFitCovariance(m, 1, 1), InputError);
  m.fit = nlohmann::json::object();
  try {
    SampleFitCovariance(m, 10, 1);
    FAIL() << "drew without a covariance";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no fit covariance"), std::string::npos) << e.what();
  }
}

TEST(MonteCarlo, SummaryLeavesFailuresOutAndComparesWithTheLinearSigma) {
  const double nan = std::nan("");
  const MonteCarloSpread s = SummariseMonteCarlo({1.0, 2.0, nan, 3.0}, 2, 1.0);
  EXPECT_EQ(s.samples, 4);
  EXPECT_EQ(s.failed, 1);
  EXPECT_EQ(s.rejected_draws, 2);
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_DOUBLE_EQ(s.sigma, 1.0);
  EXPECT_DOUBLE_EQ(s.ratio, 1.0);
  EXPECT_DOUBLE_EQ(s.sigma_relative_error, 0.5);
  EXPECT_NE(s.note.find("inconclusive: 3 samples"), std::string::npos) << s.note;
  EXPECT_NE(s.note.find("1 of 4 samples failed"), std::string::npos) << s.note;
  EXPECT_NE(s.note.find("truncated"), std::string::npos) << s.note;
  std::vector<double> many;
  for (int i = 0; i < 200; ++i) many.push_back(i % 2 ? 1.0 : -1.0);
  const MonteCarloSpread wide = SummariseMonteCarlo(many, 0, 0.5);
  EXPECT_NEAR(wide.ratio, 2.0, 0.01);
  EXPECT_NE(wide.note.find("not linear"), std::string::npos) << wide.note;
  std::vector<double> near;  // ratio 1.1 over 200 samples (±5 %): within 20 %
  for (int i = 0; i < 200; ++i) near.push_back(i % 2 ? 1.0 : -1.0);
  EXPECT_NE(SummariseMonteCarlo(near, 0, 1.0 / 1.1).note.find("the linear σ holds"), std::string::npos);
  const MonteCarloSpread none = SummariseMonteCarlo({nan, 1.0}, 0, 1.0);
  EXPECT_FALSE(std::isfinite(none.sigma));
  EXPECT_NE(none.note.find("fewer than 2"), std::string::npos) << none.note;
  const nlohmann::json j = MonteCarloJson(none, 1e3, "mm");
  EXPECT_TRUE(j["sigma"].is_null());
  EXPECT_EQ(j["unit"], "mm");
  EXPECT_EQ(j["failed"], 1);
}

}  // namespace
}  // namespace textile
