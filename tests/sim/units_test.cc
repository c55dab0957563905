#include "textile/sim/core/units.h"

#include <gtest/gtest.h>

namespace textile::units {
namespace {

// Conversions are exact scalings; 1e-15 relative covers one rounding.
constexpr double kRel = 1e-15;

TEST(Units, KesConstantsMatchPhysicsMd) {
  EXPECT_NEAR(KesStiffnessToSi(1.0), 9.80665e-5, 9.80665e-5 * kRel);
  EXPECT_NEAR(KesQuadraticToSi(1.0), 9.80665e-7, 9.80665e-7 * kRel);
  EXPECT_NEAR(KesMomentToSi(1.0), 9.80665e-3, 9.80665e-3 * kRel);
  EXPECT_DOUBLE_EQ(KesCurvatureToSi(1.0), 100.0);
  EXPECT_DOUBLE_EQ(GsmToSi(200.0), 0.2);
}

TEST(Units, KesLawIsConsistent) {
  // b = M/κ and c1 = M/κ² must follow from the moment and curvature units.
  EXPECT_NEAR(KesStiffnessToSi(1.0), KesMomentToSi(1.0) / KesCurvatureToSi(1.0), 1e-20);
  EXPECT_NEAR(KesQuadraticToSi(1.0),
              KesMomentToSi(1.0) / (KesCurvatureToSi(1.0) * KesCurvatureToSi(1.0)), 1e-22);
}

TEST(Units, RoundTrips) {
  for (double v : {1e-6, 0.0892, 1.0, 123.456}) {
    EXPECT_NEAR(SiStiffnessToKes(KesStiffnessToSi(v)), v, v * kRel * 4);
    EXPECT_NEAR(SiQuadraticToKes(KesQuadraticToSi(v)), v, v * kRel * 4);
    EXPECT_NEAR(SiMomentToKes(KesMomentToSi(v)), v, v * kRel * 4);
    EXPECT_NEAR(SiCurvatureToKes(KesCurvatureToSi(v)), v, v * kRel * 4);
    EXPECT_NEAR(SiToGsm(GsmToSi(v)), v, v * kRel * 4);
    EXPECT_NEAR(MToMm(MmToM(v)), v, v * kRel * 4);
  }
}

TEST(Units, RigidityInLabUnits) {
  // 1 gf·cm of rigidity is 98.0665 µN·m and 1000 mg·cm.
  const double g = KesStiffnessToSi(1.0);
  EXPECT_NEAR(SiRigidityToMicroNm(g), 98.0665, 1e-10);
  EXPECT_NEAR(SiRigidityToMgCm(g), 1000.0, 1e-9);
  EXPECT_NEAR(SiRigidityToGfCm(g), 1.0, 1e-14);
}

}  // namespace
}  // namespace textile::units
