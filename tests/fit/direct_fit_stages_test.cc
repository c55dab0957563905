// The decision stages of one direct-fit solve (direct_fit_stages.h), without a Ceres problem.

#include "direct_fit_stages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/law/textile_range.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

// Logarithms of products of exact powers of ten: equal to rounding.
constexpr double kLogTol = 1e-12;

TEST(DirectFitStages, LogStiffnessBoundsAreAFactor100AroundTheStart) {
  const double b0 = units::KesStiffnessToSi(0.1);  // a shirting's 0.1 gf·cm
  const auto bounds = internal::LogStiffnessBounds(b0);
  ASSERT_TRUE(bounds.has_value());
  EXPECT_NEAR((*bounds)[0], std::log(b0 / 100.0), kLogTol);
  EXPECT_NEAR((*bounds)[1], std::log(b0 * 100.0), kLogTol);
}

TEST(DirectFitStages, LogStiffnessBoundsStayInsideTheTextileRange) {
  const double top = units::KesStiffnessToSi(range::kMaxStiffnessKes);
  const auto near_top = internal::LogStiffnessBounds(top / 10.0);
  ASSERT_TRUE(near_top.has_value());
  EXPECT_NEAR((*near_top)[1], std::log(top), kLogTol);
  // A start 1000× stiffer than any textile leaves no bounds at all.
  EXPECT_FALSE(internal::LogStiffnessBounds(1000.0 * top).has_value());
  EXPECT_FALSE(
      internal::LogStiffnessBounds(units::KesStiffnessToSi(range::kMinStiffnessKes) / 1000.0)
          .has_value());
}

TEST(DirectFitStages, RescaledPriorWeightFollowsTheRmsBeyondAFactor125) {
  // 0.1 mm rms: the weight it was set for, 1e-2 mm.
  EXPECT_FALSE(internal::RescaledPriorWeight(0.1, 1e-2).has_value());
  EXPECT_FALSE(internal::RescaledPriorWeight(0.12, 1e-2).has_value());  // ×1.2
  const auto noisy = internal::RescaledPriorWeight(0.5, 1e-2);
  ASSERT_TRUE(noisy.has_value());
  EXPECT_DOUBLE_EQ(*noisy, 0.05);
  // Noise-free data: the floor, not zero.
  const auto exact = internal::RescaledPriorWeight(0.0, 1e-2);
  ASSERT_TRUE(exact.has_value());
  EXPECT_DOUBLE_EQ(*exact, 1e-3);
}

Profile Named(const std::string& source) {
  Profile p;
  p.source = source;
  return p;
}

DirectFitSummary JointFit(double rms, const std::vector<double>& rms_each) {
  DirectFitSummary fit;
  fit.rms = rms;
  for (double r : rms_each) {
    ProfileFitReport report;
    report.rms = r;
    fit.profiles.push_back(report);
  }
  return fit;
}

TEST(DirectFitStages, RefuseMixedStripsWhenEachAloneFitsThreeTimesBetter) {
  const std::vector<Profile> profiles = {Named("a.csv"), Named("b.csv")};
  const DirectFitSummary fit = JointFit(1e-3, {0.4e-3, 1.3e-3});
  try {
    internal::RefuseMixedStrips(profiles, fit, 0.5e-3, [](const Profile&) { return 0.1e-3; });
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "b.csv: the profiles do not fit one law (rms 1.000 mm together, at most 0.100 mm "
              "each alone): profiles of different strips, or a bad extraction?");
  }
  // Alone hardly better (or failing: infinite): one strip that the law fits badly.
  EXPECT_NO_THROW(
      internal::RefuseMixedStrips(profiles, fit, 0.5e-3, [](const Profile&) { return 0.4e-3; }));
  EXPECT_NO_THROW(internal::RefuseMixedStrips(profiles, fit, 0.5e-3, [&](const Profile& p) {
    return p.source == "a.csv" ? 0.1e-3 : std::numeric_limits<double>::infinity();
  }));
}

TEST(DirectFitStages, RefuseMixedStripsFitsAloneOnlyWhenTheJointFitIsBad) {
  int calls = 0;
  const auto count = [&](const Profile&) { return ++calls, 0.0; };
  internal::RefuseMixedStrips({Named("a.csv"), Named("b.csv")}, JointFit(0.4e-3, {0.4e-3, 0.4e-3}),
                              0.5e-3, count);
  internal::RefuseMixedStrips({Named("a.csv")}, JointFit(1e-3, {1e-3}), 0.5e-3, count);
  EXPECT_EQ(calls, 0);
}

TEST(DirectFitStages, PinnedBoundMessageNamesTheConstantOnItsBound) {
  const std::array<double, 2> lower = {-12.0, -12.0}, upper = {-6.0, -6.0};
  EXPECT_EQ(internal::PinnedBoundMessage({-9.0, -8.0, 3.0}, lower, upper), "");
  const std::string pinned = internal::PinnedBoundMessage({-9.0, -6.0 - 1e-8, 3.0}, lower, upper);
  EXPECT_EQ(pinned.rfind("the fit ran into the bound b2 = ", 0), 0u) << pinned;
  EXPECT_NE(pinned.find("the profiles do not determine a textile law"), std::string::npos);
  EXPECT_EQ(internal::PinnedBoundMessage({-12.0, -8.0, 3.0}, lower, upper)
                .rfind("the fit ran into the bound b1", 0),
            0u);
}

TEST(DirectFitStages, CovarianceFromJacobianPropagatesToTheConstants) {
  // J = I over (ln b1, ln b2, ln κ0): cov_p = σ² I, so cov(b1) = σ² b1², cov(b2) = σ² b2².
  const BendingLaw law = BendingLaw::FromSi(1e-5, 2e-5, 1e-7);
  const double log_k0 = std::log(law.kappa0());
  DirectFitSummary fit;
  internal::CovarianceFromJacobian(Eigen::MatrixXd::Identity(3, 3), 4.0, law, log_k0, &fit);
  constexpr double kRel = 1e-12;  // a 3×3 SVD of the identity: exact to rounding
  EXPECT_NEAR(fit.b1_sd, 2.0 * law.b1(), kRel * law.b1());
  EXPECT_NEAR(fit.b2_sd, 2.0 * law.b2(), kRel * law.b2());
  EXPECT_NEAR(fit.covariance(0, 1), 0.0, kRel * law.b1() * law.b2());
  // ∂c1 = (-b1 dln b1 + b2 dln b2) / (2 κ0) - c1 dln κ0.
  const double k0 = law.kappa0();
  const double c1_var = 4.0 * (std::pow(law.b1() / (2 * k0), 2) + std::pow(law.b2() / (2 * k0), 2) +
                               std::pow(law.c1(), 2));
  EXPECT_NEAR(fit.c1_sd, std::sqrt(c1_var), kRel * std::sqrt(c1_var));
}

TEST(DirectFitStages, CovarianceFromJacobianSaysUndeterminedForANullDirection) {
  const BendingLaw law = BendingLaw::FromSi(1e-5, 2e-5, 1e-7);
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(4, 3);
  J(2, 2) = 0.0;  // no residual moves with ln κ0
  DirectFitSummary fit;
  internal::CovarianceFromJacobian(J, 1.0, law, std::log(law.kappa0()), &fit);
  EXPECT_TRUE(std::isfinite(fit.b1_sd));
  EXPECT_TRUE(std::isfinite(fit.b2_sd));
  EXPECT_TRUE(std::isnan(fit.c1_sd));
}

TEST(DirectFitStages, ObserveConstantsCapsB2BeyondTheDataAndSaysSo) {
  BendingLaw law = BendingLaw::FromSi(1e-5, 2e-5, 1e-7);  // κ0 = 50 /m
  DirectFitSummary fit;
  fit.kappa_max = 20.0;  // the data stop short of κ0
  fit.b1_sd = 1e-7, fit.b2_sd = 1e-7, fit.c1_sd = 1e-9;
  internal::ObserveConstants(&law, &fit);
  EXPECT_FALSE(fit.b2_observed);
  EXPECT_TRUE(fit.b1_observed);
  EXPECT_TRUE(fit.c1_observed);
  EXPECT_TRUE(std::isnan(fit.b2_sd));
  // b2 is now the slope at κ_max: b1 + 2 c1 κ_max.
  EXPECT_NEAR(law.b2(), 1e-5 + 2.0 * 1e-7 * 20.0, 1e-18);
  EXPECT_EQ(fit.observability.rfind("b2 is not observed: kappa0 (0.5 /cm)", 0), 0u)
      << fit.observability;
}

TEST(DirectFitStages, ObserveConstantsNamesWhatTheSdsLeaveOpen) {
  BendingLaw law = BendingLaw::FromSi(1e-5, 2e-5, 1e-7);  // κ0 = 50 /m
  DirectFitSummary fit;
  fit.kappa_max = 100.0;
  fit.b1_sd = 1e-7, fit.b2_sd = 1e-7, fit.c1_sd = 1e-9;
  BendingLaw determined = law;
  internal::ObserveConstants(&determined, &fit);
  EXPECT_TRUE(fit.b1_observed && fit.b2_observed && fit.c1_observed);
  EXPECT_EQ(fit.observability,
            "All three constants are determined by the data (curvatures up to 1 /cm). The "
            "moment curve M(κ) is determined for 0 ≤ κ ≤ 1 /cm.");
  fit.c1_sd = std::numeric_limits<double>::quiet_NaN();
  internal::ObserveConstants(&law, &fit);
  EXPECT_FALSE(fit.c1_observed);
  EXPECT_TRUE(fit.b1_observed);
  EXPECT_EQ(fit.observability.rfind("c1 is poorly determined (undetermined)", 0), 0u)
      << fit.observability;
}

}  // namespace
}  // namespace textile
