#include "textile/fit/moment_curve.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include <nlohmann/json.hpp>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

TEST(MomentCurve, ReadsSiAndLabUnitsAndIgnoresOtherColumns) {
  const MomentCurvePairs si =
      ParseMomentCurvatureCsv("\xEF\xBB\xBF" "kappa_per_m,M_N\n# peer\n20.2,0.39\n\n0,0\n", "si.csv");
  ASSERT_EQ(si.kappa.size(), 2u);
  EXPECT_EQ(si.kappa[0], 20.2);
  EXPECT_EQ(si.moment[0], 0.39);
  const MomentCurvePairs lab = ParseMomentCurvatureCsv(
      "x_mm,y_mm,M_gfcm_per_cm,kappa_per_cm\n1,2,10,0.5\n3,4,20,1.5\n", "lab.csv");
  ASSERT_EQ(lab.kappa.size(), 2u);
  EXPECT_DOUBLE_EQ(lab.kappa[1], units::KesCurvatureToSi(1.5));
  EXPECT_DOUBLE_EQ(lab.moment[1], units::KesMomentToSi(20.0));
}

TEST(MomentCurve, RefusesWhatIsNotAMomentCurve) {
  for (const char* text : {"", "kappa_per_m,M\n1,2\n2,3\n", "kappa_per_m,M_N\n1\n2,3\n",
                           "kappa_per_m,M_N\n1,x\n2,3\n", "kappa_per_m,M_N\n1,inf\n2,3\n",
                           "kappa_per_m,M_N\n-1,2\n2,3\n", "kappa_per_m,M_N\n1,2\n"}) {
    EXPECT_THROW(ParseMomentCurvatureCsv(text, "bad.csv"), InputError) << text;
  }
}

TEST(MomentCurve, SigmaIsTheLinearPropagationOfTheLawsCovariance) {
  // Fig. 8's law; a covariance with correlations. The band's σ must match the spread of M(κ)
  // over laws moved a little along the covariance's principal axes, on both branches.
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  Eigen::Matrix3d c;
  const double sb = units::KesStiffnessToSi(0.004), sc = units::KesQuadraticToSi(0.002);
  c << sb * sb, 0.5 * sb * sb, 0.3 * sb * sc, 0.5 * sb * sb, sb * sb, 0.2 * sb * sc,
      0.3 * sb * sc, 0.2 * sb * sc, sc * sc;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
  for (const double k_cm : {0.2, 0.58, 1.5}) {
    const double k = units::KesCurvatureToSi(k_cm);
    double var = 0.0;
    for (int a = 0; a < 3; ++a) {
      // A small step along each axis, scaled back: the linear propagation's own definition.
      constexpr double kStep = 1e-4;
      const Eigen::Vector3d d = kStep * std::sqrt(eig.eigenvalues()(a)) * eig.eigenvectors().col(a);
      const BendingLaw moved = BendingLaw::FromSi(law.b1() + d(0), law.b2() + d(1), law.c1() + d(2));
      var += std::pow((moved.Moment(k) - law.Moment(k)) / kStep, 2);
    }
    EXPECT_NEAR(MomentSigma(law, c, k), std::sqrt(var), 1e-3 * std::sqrt(var)) << k_cm;
  }
  EXPECT_EQ(MomentSigma(law, Eigen::Matrix3d::Zero(), 50.0), 0.0);
}

TEST(MomentCurve, FitCovarianceComesFromTheReportWhenEverySdIsKnown) {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  std::string why;
  EXPECT_FALSE(FitCovariance(m, "m.json", &why));
  EXPECT_NE(why.find("no fit covariance"), std::string::npos) << why;
  m.fit = nlohmann::json::parse(R"({"b1_sd": 0.002, "b2_sd": 0.001, "c1_sd": 0.003,
      "covariance_kes": [[4e-6, 1e-7, 0], [1e-7, 1e-6, 0], [0, 0, 9e-6]]})");
  const auto c = FitCovariance(m, "m.json", &why);
  ASSERT_TRUE(c);
  EXPECT_NEAR((*c)(0, 0), 4e-6 * std::pow(units::KesStiffnessToSi(1.0), 2), 1e-24);
  EXPECT_NEAR((*c)(2, 2), 9e-6 * std::pow(units::KesQuadraticToSi(1.0), 2), 1e-30);
  m.fit["b2_sd"] = nullptr;
  EXPECT_FALSE(FitCovariance(m, "m.json", &why));
  EXPECT_NE(why.find("b2_sd"), std::string::npos) << why;
  m.fit["b2_sd"] = 0.001;
  m.fit["covariance_kes"] = nlohmann::json::array({1, 2, 3});
  EXPECT_THROW(FitCovariance(m, "m.json", &why), InputError);
}

TEST(MomentCurve, FitCurvatureReachIsTheReportsKappaMax) {
  Material m;
  EXPECT_FALSE(FitCurvatureReach(m).has_value());  // no fit report
  m.fit = {{"method", "direct"}};
  EXPECT_FALSE(FitCurvatureReach(m).has_value());  // a report without the number
  m.fit["kappa_max_per_cm"] = "2";
  EXPECT_FALSE(FitCurvatureReach(m).has_value());  // not a number
  m.fit["kappa_max_per_cm"] = 2.0;
  ASSERT_TRUE(FitCurvatureReach(m).has_value());
  EXPECT_DOUBLE_EQ(*FitCurvatureReach(m), 200.0);  // 2 /cm = 200 /m
}

}  // namespace
}  // namespace textile
