#include "textile/sim/law/input_influence.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// A scene input's row: shown in its unit, per ln of its SI value, its change over Δp.
TEST(InputInfluence, SceneRowsShowTheValueInTheirUnit) {
  const ParameterInfluence r =
      SceneInfluence("specimen_radius", 0.15, 1e3, "mm", -10.0, 1e-3, "a template");
  EXPECT_EQ(r.parameter, "specimen_radius");
  EXPECT_DOUBLE_EQ(r.value, 150.0);
  EXPECT_EQ(r.unit, "mm");
  EXPECT_FALSE(r.defaulted);
  EXPECT_DOUBLE_EQ(r.d_q_d_ln_p, -1.5);
  EXPECT_DOUBLE_EQ(r.uncertainty_ln, 1e-3 / 0.15);
  EXPECT_DOUBLE_EQ(r.change, 0.01);
  EXPECT_TRUE(std::isnan(SceneInfluence("x", 0.0, 1.0, "-", 1.0, 1.0, "").uncertainty_ln));
}

// A coefficient's step moves B_f by `relative` of B_f(0) at d_max; the stepped profile is a
// fitted one (a preset's coefficients are Table 2's) with only that coefficient moved.
TEST(InputInfluence, SeamStepsMoveOneCoefficient) {
  const SeamProfile c = SeamPreset("C-plain");  // B_f(0) = 9.07, d_max 100 mm
  for (int k = 0; k < kSeamCoefficients; ++k) {
    const double h = SeamCoefficientStep(c, k, 1e-3);
    const SeamProfile up = SteppedSeamProfile(c, k, h);
    EXPECT_EQ(up.type, "fitted");
    EXPECT_NEAR(up.StiffnessFactor(100.0) - c.StiffnessFactor(100.0), 1e-3 * 9.07, 1e-12) << k;
    std::string why;
    EXPECT_TRUE(up.Check(&why)) << why;
  }
  EXPECT_THROW(SteppedSeamProfile(c, 3, 1.0), std::out_of_range);
  EXPECT_NO_THROW(CheckSeamCoefficientSteps(c, 1e-6));
  // A fitted seam of coefficients `a` is refused for steps of `relative`, saying `why`.
  const auto expect_refused = [](const std::array<double, 3>& a, double relative,
                                 const std::string& fragment) {
    SeamProfile p = SeamPreset("C-plain");
    p.type = "fitted";
    p.coefficients_mm = a;
    std::string why;
    ASSERT_TRUE(p.Check(&why)) << why;
    try {
      CheckSeamCoefficientSteps(p, relative);
      ADD_FAILURE() << "let through: " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--sensitivity-params"), std::string::npos);
    }
  };
  // B_f just reaching 0 at d_max: a step down leaves its bounds.
  expect_refused({0.0, -0.09, 9.0 + 1e-9}, 1e-6, "leaves their bounds");
  // The fade beyond d_max at its switch (3 e0 + g = 0: e0 = 0.2, g = 20 × −0.03): a step either
  // way changes the fade, and S jumps there.
  expect_refused({0.0, -0.03, 4.2}, 1e-2, "switches the fade");
  // Let through: far from the switch (3 e0 + g = 0.9), and an exponential fade that a step
  // turns into none (B_f(100 mm) = 1.01 falling 0.05 a mm: S shrinks to 1 continuously).
  SeamProfile fitted = c;
  fitted.type = "fitted";
  fitted.coefficients_mm = {0.0, -0.03, 4.5};
  EXPECT_NO_THROW(CheckSeamCoefficientSteps(fitted, 1e-2));
  fitted.coefficients_mm = {0.0, -0.05, 6.01};
  EXPECT_NO_THROW(CheckSeamCoefficientSteps(fitted, 1e-2));
}

// The seam's rows: without a covariance ±10 % of each coefficient (of a zero one, 10 % of
// B_f(0) at d_max) and of the scale; with one, its sds, and for the scale √(gᵀ C g).
TEST(InputInfluence, SeamRowsTakeTheCovarianceOrTenPercent) {
  SeamProfile p = SeamPreset("A-plain");
  p.type = "fitted";
  p.coefficients_mm = {0.0, -0.0211, 3.46};
  const std::vector<double> g = {100.0, -2.0, 0.01};
  const std::vector<ParameterInfluence> rows = SeamInfluences(p, g);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].parameter, "seam.a2");
  EXPECT_EQ(rows[0].unit, "1/mm²");
  EXPECT_NEAR(rows[0].change, 100.0 * 0.1 * 3.46 / 1e4, 1e-15);  // a2 = 0
  EXPECT_NE(rows[0].uncertainty_source.find("of B_f(0) at d_max"), std::string::npos);
  EXPECT_NEAR(rows[1].change, 2.0 * 0.00211, 1e-15);
  const double scale = -0.0211 * -2.0 + 3.46 * 0.01;
  EXPECT_EQ(rows[3].parameter, "seam.scale");
  EXPECT_NEAR(rows[3].d_q_d_ln_p, scale, 1e-15);
  EXPECT_NEAR(rows[3].change, 0.1 * scale, 1e-15);

  p.covariance = Eigen::Matrix3d{{1e-10, 0.0, 0.0}, {0.0, 4e-6, -1e-4}, {0.0, -1e-4, 0.25}};
  const std::vector<ParameterInfluence> fitted = SeamInfluences(p, g);
  EXPECT_NEAR(fitted[1].change, 2.0 * 2e-3, 1e-15);
  EXPECT_NEAR(fitted[2].change, 0.01 * 0.5, 1e-15);
  const Eigen::Vector3d v(g[0], g[1], g[2]);
  EXPECT_NEAR(fitted[3].change, std::sqrt(v.dot(*p.covariance * v)), 1e-15);
  EXPECT_NE(fitted[3].uncertainty_source.find("covariance"), std::string::npos);
  EXPECT_THROW(SeamInfluences(p, {1.0, 2.0}), InputError);
}

}  // namespace
}  // namespace textile
