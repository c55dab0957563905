#include "photo/calibrate_stages.h"

#include <gtest/gtest.h>

#include <vector>

namespace textile::fit_internal {
namespace {

// Six views of a 9 x 6 board.
constexpr int kBoards = 6;
constexpr int kCorners = 54;

std::vector<LensModelFit> Nested(double none, double k1, double k2, double p12, double k3) {
  return {{"none", 0, none},
          {"k1", 1, k1},
          {"k1, k2", 2, k2},
          {"k1, k2, p1, p2", 4, p12},
          {"k1, k2, p1, p2, k3", 5, k3}};
}

TEST(SelectLensModel, NoGainKeepsNoTerm) {
  const auto c = SelectLensModel(Nested(0.3, 0.3, 0.3, 0.3, 0.3), kBoards, kCorners);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].terms, "none");
  EXPECT_EQ(c[0].p_next, 1.0);  // no F statistic > 0
  EXPECT_EQ(c[0].p_value, 1.0);
  EXPECT_EQ(c[0].significance, 0.01);  // k1's level
}

TEST(SelectLensModel, StopsAfterTheLastSignificantTerm) {
  const auto c = SelectLensModel(Nested(1.0, 0.5, 0.5, 0.5, 0.5), kBoards, kCorners);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[1].terms, "k1");
  EXPECT_LT(c[0].p_next, 1e-6);
  EXPECT_EQ(c[1].p_next, 1.0);
  EXPECT_EQ(c[1].significance, 0.001);  // the stricter level after k1
  EXPECT_EQ(c[1].rms_px, 0.5);
}

TEST(SelectLensModel, GainOfTheFullModelCarriesPastAFlatStep) {
  // k2 alone gains nothing, but the full model does: the selection goes on through k2.
  const auto c = SelectLensModel(Nested(1.0, 0.5, 0.5, 0.5, 0.25), kBoards, kCorners);
  ASSERT_EQ(c.size(), 5u);
  EXPECT_EQ(c.back().terms, "k1, k2, p1, p2, k3");
  EXPECT_EQ(c.back().p_next, 1.0);  // nothing beyond the full model
  EXPECT_EQ(c.back().significance, 0.0);
}

}  // namespace
}  // namespace textile::fit_internal
