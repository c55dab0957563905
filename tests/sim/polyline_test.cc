#include "textile/sim/core/polyline.h"

#include <gtest/gtest.h>

#include <cmath>

namespace textile {
namespace {

// An L: (0,0) → (2,0) → (2,2), with a repeated vertex that must be skipped.
const std::vector<double> kX = {0.0, 2.0, 2.0, 2.0}, kY = {0.0, 0.0, 0.0, 2.0};

TEST(Polyline, DistanceIsToTheNearestSegment) {
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 1.0, 0.5), 0.5);   // over the first leg
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 2.5, 1.0), 0.5);   // beside the second
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 3.0, -1.0), std::sqrt(2.0));  // the corner
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 1.5, 1.0), 0.5);   // inside the L: the second leg
}

TEST(Polyline, BeyondAnEndTheExtendedDistanceIsToTheEndsTangentLine) {
  // Past the free end (2,2) going up: 1 above and 0.5 aside.
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 2.5, 3.0), std::hypot(0.5, 1.0));
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 2.5, 3.0, /*extend_ends=*/true), 0.5);
  // Before the start (0,0) going right: the tangent line is y = 0.
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, -1.0, 0.25, true), 0.25);
  // A point beside the curve is unchanged by the flag.
  EXPECT_DOUBLE_EQ(DistanceToPolyline(kX, kY, 1.0, 0.5, true), 0.5);
}

TEST(Polyline, DegenerateCurvesAreInfinitelyFar) {
  EXPECT_TRUE(std::isinf(DistanceToPolyline({}, {}, 0.0, 0.0)));
  EXPECT_TRUE(std::isinf(DistanceToPolyline({1.0, 1.0}, {2.0, 2.0}, 0.0, 0.0)));
}

TEST(Polyline, MaxDistanceIsTheWorstPoint) {
  EXPECT_DOUBLE_EQ(MaxDistanceToPolyline(kX, kY, {1.0, 2.5, 1.0}, {0.5, 1.0, -0.25}), 0.5);
  EXPECT_DOUBLE_EQ(MaxDistanceToPolyline(kX, kY, {}, {}), 0.0);
}

}  // namespace
}  // namespace textile
