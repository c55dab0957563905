#include "textile/sim/law/membrane_law.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// W' = F and F' = K by central differences at strains across the knots and past the last one.
void ExpectConsistent(const TensileCurve& c, double max_strain) {
  for (int i = 1; i <= 40; ++i) {
    const double e = max_strain * i / 32.0, h = 1e-7 * max_strain;
    EXPECT_NEAR((c.Energy(e + h) - c.Energy(e - h)) / (2 * h), c.Force(e), 1e-6 * c.Force(e))
        << "strain " << e;
    EXPECT_NEAR((c.Force(e + h) - c.Force(e - h)) / (2 * h), c.Stiffness(e),
                1e-5 * c.Stiffness(e) + 1e-6)
        << "strain " << e;
    EXPECT_GT(c.Force(e + h), c.Force(e)) << "monotone at " << e;
  }
}

TEST(TensileCurve, LinearIsHookesLaw) {
  const TensileCurve c = TensileCurve::Linear(1200.0);
  EXPECT_DOUBLE_EQ(c.Force(0.02), 24.0);
  EXPECT_DOUBLE_EQ(c.Energy(0.02), 0.5 * 1200.0 * 0.02 * 0.02);
  EXPECT_DOUBLE_EQ(c.Stiffness(0.3), 1200.0);
  EXPECT_THROW(TensileCurve::Linear(0.0), InputError);
  EXPECT_THROW(TensileCurve::Linear(-5.0), InputError);
}

TEST(TensileCurve, PointsGiveAMonotoneC1CurveThroughThem) {
  const std::vector<double> e{0.01, 0.02, 0.04, 0.05}, f{5.0, 20.0, 150.0, 490.0};
  const TensileCurve c = TensileCurve::FromPoints(e, f);
  for (size_t i = 0; i < e.size(); ++i) EXPECT_NEAR(c.Force(e[i]), f[i], 1e-12 * f[i]);
  EXPECT_GE(c.SmallStrainModulus(), 0.1 * 5.0 / 0.01);
  ExpectConsistent(c, 0.05);
  EXPECT_THROW(TensileCurve::FromPoints({0.01, 0.02}, {5.0, 4.0}), InputError);
  EXPECT_THROW(TensileCurve::FromPoints({0.02, 0.01}, {5.0, 6.0}), InputError);
  EXPECT_THROW(TensileCurve::FromPoints({0.01}, {5.0, 6.0}), InputError);
}

TEST(TensileCurve, KesCurveMeetsTheMaximumLoadAtEmtWithTheEnergyLtSays) {
  for (double lt : {0.3, 0.55, 0.65, 0.9, 1.1}) {
    const double emt = 5.0;
    const TensileCurve c = TensileCurveFromKes(emt, lt);
    EXPECT_NEAR(c.Force(emt / 100), kKesMaxLoad, 1e-9 * kKesMaxLoad) << "LT " << lt;
    const double wt = lt * 0.5 * kKesMaxLoad * emt / 100;
    EXPECT_NEAR(c.Energy(emt / 100), wt, 1e-3 * wt) << "LT " << lt;
    EXPECT_GT(c.SmallStrainModulus(), 0.0);
    ExpectConsistent(c, emt / 100);
  }
  EXPECT_THROW(TensileCurveFromKes(0.0, 0.6), InputError);
  EXPECT_THROW(TensileCurveFromKes(120.0, 0.6), InputError);
  EXPECT_THROW(TensileCurveFromKes(5.0, 0.05), InputError);
  EXPECT_THROW(TensileCurveFromKes(5.0, 1.3), InputError);
}

TEST(TensileCurve, CompressionFollowsTheModulusThenTheRatio) {
  const TensileCurve c = TensileCurve::Linear(1000.0);
  const MembraneCompression soft{0.01, 0.002};
  EXPECT_DOUBLE_EQ(YarnForce(c, soft, -0.001), -1.0);
  EXPECT_DOUBLE_EQ(YarnStiffness(c, soft, -0.001), 1000.0);
  EXPECT_DOUBLE_EQ(YarnStiffness(c, soft, -0.01), 10.0);
  EXPECT_NEAR(YarnForce(c, soft, -0.012), -2.0 - 0.1, 1e-12);
  for (double e : {-0.0015, -0.003, -0.02, 0.004}) {
    const double h = 1e-8;
    EXPECT_NEAR((YarnEnergy(c, soft, e + h) - YarnEnergy(c, soft, e - h)) / (2 * h),
                YarnForce(c, soft, e), 1e-6)
        << e;
  }
  EXPECT_NEAR(KesShearToNewtonPerMetre(1.0), 56.19, 0.01);
  EXPECT_NEAR(TensileCurveFromFastE100(2.0).SmallStrainModulus(), 4903.3, 0.1);
}

}  // namespace
}  // namespace textile
