#include "textile/fit/profile_compare.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

// A quarter circle of radius r [m] hanging from the edge, n points, each moved by normal[k]
// [m] along its outward normal (away from the centre (0, -r)).
Profile Arc(double r, int n, const std::vector<double>& normal = {}) {
  Profile p;
  p.source = "arc";
  for (int k = 0; k < n; ++k) {
    const double phi = 0.5 * std::numbers::pi * k / (n - 1);
    const double d = normal.empty() ? 0.0 : normal[static_cast<size_t>(k)];
    p.s.push_back(r * phi);
    p.x.push_back((r + d) * std::sin(phi));
    p.y.push_back(-r + (r + d) * std::cos(phi));
  }
  return p;
}

TEST(CompareWithCurve, SplineThroughCoarsePointsFollowsACircle) {
  // Simulated points every 2 mm on a 10 mm circle: a polyline through them would miss the
  // circle by up to h²/8R = 0.05 mm; the spline must stay within 5 µm.
  const Profile coarse = Arc(0.01, 9);  // 2.0 mm apart
  const Profile measured = Arc(0.01, 157);
  const ProfileComparison c = CompareWithCurve(measured, coarse.x, coarse.y, 0.0);
  EXPECT_LT(c.max, 5e-6);
  EXPECT_NEAR(c.tip_dx, 0.0, 1e-12);
  EXPECT_NEAR(c.tip_dy, 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(c.clamp_curvature));
  EXPECT_EQ(c.model_x.size(), 8u * 8u + 1u);
}

TEST(CompareWithCurve, DistancesAreNormalAndTheOffsetLiftsTheCurve) {
  // Measured points 0.2 mm off the curve, alternately outside and inside: every distance is
  // 0.2 mm. The tip difference is the curve's end minus the last measured point.
  std::vector<double> normal;
  for (int k = 0; k < 61; ++k) normal.push_back(k % 2 ? 2e-4 : -2e-4);
  const Profile measured = Arc(0.03, 61, normal);
  const Profile curve = Arc(0.03, 25);
  const ProfileComparison c = CompareWithCurve(measured, curve.x, curve.y, 0.0);
  EXPECT_NEAR(c.rms, 2e-4, 2e-6);
  EXPECT_NEAR(c.max, 2e-4, 2e-6);
  EXPECT_NEAR(c.tip_dx, curve.x.back() - measured.x.back(), 1e-12);
  EXPECT_NEAR(c.tip_dy, curve.y.back() - measured.y.back(), 1e-12);
  // Lifted by 1 mm, the simulated curve's first point is at (0, 1 mm).
  const ProfileComparison lifted = CompareWithCurve(measured, curve.x, curve.y, 1e-3);
  EXPECT_NEAR(lifted.model_y.front(), 1e-3, 1e-15);
  EXPECT_GT(lifted.rms, 5e-4);
}

TEST(CompareWithCurve, AgreesWithTheElasticaComparison) {
  // The elastica's own curve given as points 2 mm apart grades a noisy profile as the
  // elastica comparison does (the same law, overhang and offset): the spline through 2 mm
  // points is within 6 µm of the curve where the curvature changes fastest (at the clamp).
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const double rho = 0.2, overhang = 0.08;
  ElasticaOptions eo;
  eo.num_samples = 41;
  const ElasticaProfile e = SolveHeavyElastica(law, rho, overhang, eo);
  ASSERT_TRUE(e.converged) << e.message;
  ElasticaOptions fine;
  fine.num_samples = 161;
  const ElasticaProfile f = SolveHeavyElastica(law, rho, overhang, fine);
  Profile measured;
  measured.source = "elastica";
  for (size_t k = 0; k < f.s.size(); ++k) {
    const double d = (k % 3 == 0 ? 1.0 : -0.5) * 1e-4;  // ±0.1 mm along the normal
    measured.s.push_back(f.s[k]);
    measured.x.push_back(f.x[k] + d * std::sin(f.theta[k]));
    measured.y.push_back(f.y[k] + d * std::cos(f.theta[k]) + 2e-4);
  }
  const ProfileComparison a = CompareWithElastica(law, rho, measured, overhang, 2e-4);
  const ProfileComparison b = CompareWithCurve(measured, e.x, e.y, 2e-4);
  EXPECT_NEAR(a.rms, b.rms, 1e-6);
  EXPECT_NEAR(a.max, b.max, 1e-5);
  EXPECT_NEAR(a.tip_dx, b.tip_dx, 1e-6);
  EXPECT_NEAR(a.tip_dy, b.tip_dy, 1e-6);
  // Both carry each point's distance, the numbers the rms and max were taken over (what
  // validate's held-out panel plots).
  for (const ProfileComparison* c : {&a, &b}) {
    ASSERT_EQ(c->distances.size(), measured.size());
    double s2 = 0.0, worst = 0.0;
    for (const double d : c->distances) s2 += d * d, worst = std::max(worst, d);
    EXPECT_NEAR(std::sqrt(s2 / measured.size()), c->rms, 1e-12);
    EXPECT_DOUBLE_EQ(worst, c->max);
  }
  for (size_t j = 0; j < measured.size(); ++j)
    EXPECT_NEAR(a.distances[j], b.distances[j], 1e-5) << j;
}

TEST(CompareWithCurve, RefusesBadCurves) {
  const Profile measured = Arc(0.03, 30);
  EXPECT_THROW(CompareWithCurve(measured, {0.0}, {0.0}, 0.0), InputError);
  EXPECT_THROW(CompareWithCurve(measured, {0.0, 0.01}, {0.0}, 0.0), InputError);
  EXPECT_THROW(CompareWithCurve(measured, {0.0, std::nan("")}, {0.0, -0.01}, 0.0), InputError);
  EXPECT_THROW(CompareWithCurve(measured, {0.0, 0.01}, {0.0, -0.01}, INFINITY), InputError);
}

// Noise-free points on the curve of `law` at `overhang`, offset and rotation 0.
Profile OnTheCurve(const BendingLaw& law, double rho, double overhang) {
  ElasticaOptions eo;
  eo.num_samples = 81;
  const ElasticaProfile e = SolveHeavyElastica(law, rho, overhang, eo);
  EXPECT_TRUE(e.converged) << e.message;
  Profile p;
  p.source = "on the curve";
  p.s = e.s;
  p.x = e.x;
  p.y = e.y;
  return p;
}

// The spread is the curve's motion: with points on the curve of a law and a covariance h² in one
// constant alone, moving that constant by h moves the curve by as much as the spread says: the
// comparison of the points with the moved law's curve has rms ≈ spread.rms, max ≈ spread.max,
// tip distance ≈ spread.tip. h is 0.1 % of the constant: the second-order term is then ~0.3 %
// of the motion (3.4 % at h = 1 %), inside the 0.5 % allowed.
TEST(ElasticaSpread, IsTheCurvesMotionUnderAOneSigmaStep) {
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const double rho = 0.2, overhang = 0.08;
  const Profile measured = OnTheCurve(law, rho, overhang);
  const double constants[3] = {law.b1(), law.b2(), law.c1()};
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-3 * std::abs(constants[k]);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    cov(k, k) = h * h;
    const CurveSpread spread = ElasticaSpread(law, rho, measured, overhang, 0.0, 0.0, cov);
    double moved[3] = {law.b1(), law.b2(), law.c1()};
    moved[k] += h;
    const ProfileComparison c = CompareWithElastica(
        BendingLaw::FromSi(moved[0], moved[1], moved[2]), rho, measured, overhang, 0.0);
    EXPECT_GT(spread.rms, 1e-7) << k;  // each constant moves an 80 mm strip measurably
    EXPECT_NEAR(spread.rms, c.rms, 0.005 * c.rms + 1e-9) << k;
    EXPECT_NEAR(spread.max, c.max, 0.005 * c.max + 1e-9) << k;
    EXPECT_NEAR(spread.tip, std::hypot(c.tip_dx, c.tip_dy), 0.005 * spread.tip + 1e-9) << k;
    // Linear in σ: four times the variance, twice the spread.
    const CurveSpread twice = ElasticaSpread(law, rho, measured, overhang, 0.0, 0.0, 4.0 * cov);
    EXPECT_NEAR(twice.rms, 2.0 * spread.rms, 1e-9 * spread.rms) << k;
  }
  // No uncertainty, no spread.
  const CurveSpread none =
      ElasticaSpread(law, rho, measured, overhang, 0.0, 0.0, Eigen::Matrix3d::Zero());
  EXPECT_EQ(none.rms, 0.0);
  EXPECT_EQ(none.tip, 0.0);
}

TEST(ElasticaSpread, LinearLawsAndBadCovariancesAreNotSpread) {
  const double rho = 0.2, overhang = 0.06;
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const Profile measured = OnTheCurve(law, rho, overhang);
  const Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 1e-16;
  // κ0 = ∞ (c1 = 0) and κ0 = 0 (b1 = b2): the fit's parameters do not reach them smoothly.
  for (const BendingLaw& linear :
       {BendingLaw::FromKes(0.1, 0.09, 0.0), BendingLaw::FromKes(0.1, 0.1, 0.01)}) {
    const CurveSpread s = ElasticaSpread(linear, rho, measured, overhang, 0.0, 0.0, cov);
    EXPECT_TRUE(std::isnan(s.rms) && std::isnan(s.max) && std::isnan(s.tip));
  }
  Eigen::Matrix3d bad = cov;
  bad(1, 2) = std::nan("");
  EXPECT_THROW(ElasticaSpread(law, rho, measured, overhang, 0.0, 0.0, bad), InputError);
  EXPECT_THROW(ElasticaSpread(law, rho, measured, -1.0, 0.0, 0.0, cov), InputError);
}

TEST(CompareWithElastica, TakesASplineLaw) {
  // The Fig. 8 law sampled as a 41-knot spline (0 .. 4 /cm) grades a profile of the law itself
  // as the law does: its strip is within 5e-7 L of the law's (elastica_test.cc), and the
  // curve path's own error is ~6 µm at 2 mm spacing, far less at 201 points. A rotation and an
  // offset are applied as for a Pabst law.
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  std::vector<double> kappa, moment;
  for (int i = 0; i <= 40; ++i) {
    kappa.push_back(10.0 * i);
    moment.push_back(law.Moment(10.0 * i));
  }
  const BendingLaw spline = BendingLaw::FromSpline(kappa, moment);
  const double rho = 0.2, overhang = 0.08, offset = 2e-4, rotation = 0.01;
  ElasticaOptions fine;
  fine.num_samples = 161;
  const ElasticaProfile f = SolveHeavyElastica(law, rho, overhang, fine);
  ASSERT_TRUE(f.converged) << f.message;
  Profile measured;
  measured.source = "elastica";
  const double c = std::cos(rotation), s = std::sin(rotation);
  for (size_t k = 0; k < f.s.size(); ++k) {
    const double d = (k % 3 == 0 ? 1.0 : -0.5) * 1e-4;  // ±0.1 mm along the normal
    const double x = f.x[k] + d * std::sin(f.theta[k]), y = f.y[k] + d * std::cos(f.theta[k]);
    measured.s.push_back(f.s[k]);
    measured.x.push_back(c * x - s * y);
    measured.y.push_back(s * x + c * y + offset);
  }
  const ProfileComparison a = CompareWithElastica(law, rho, measured, overhang, offset, rotation);
  const ProfileComparison b =
      CompareWithElastica(spline, rho, measured, overhang, offset, rotation);
  EXPECT_NEAR(b.rms, a.rms, 1e-6);
  EXPECT_NEAR(b.max, a.max, 1e-6);
  EXPECT_NEAR(b.tip_dx, a.tip_dx, 1e-6);
  EXPECT_NEAR(b.tip_dy, a.tip_dy, 1e-6);
  EXPECT_NEAR(b.clamp_curvature, a.clamp_curvature, 1e-4 * a.clamp_curvature);
}

}  // namespace
}  // namespace textile
