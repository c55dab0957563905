#include "textile/sim/bending_law.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "textile/sim/error.h"
#include "textile/sim/units.h"

namespace textile {
namespace {

// The paper's three fabrics, KES constants as printed (Pabst et al. Figs. 7-9).
struct PaperFabric {
  const char* name;
  double b1, b2, c1;
};
const std::vector<PaperFabric> kPaperFabrics = {
    {"fig8", 0.1, 0.0892, -0.0092},
    {"dress", 0.0973, 0.0973, 0.0453},
    {"interlining", 0.5168, 1.8856, 2.2683},
};

std::vector<BendingLaw> TestLaws() {
  std::vector<BendingLaw> laws;
  for (const auto& f : kPaperFabrics) laws.push_back(BendingLaw::FromKes(f.b1, f.b2, f.c1));
  laws.push_back(BendingLaw::FromKes(0.05, 0.2, 0.0));    // c1 = 0: κ0 = ∞, M = b1 κ
  laws.push_back(BendingLaw::FromKes(0.3, 0.01, -0.5));   // strongly softening
  laws.push_back(BendingLaw::FromKes(0.01, 0.5, 20.0));   // strongly stiffening
  return laws;
}

TEST(BendingLaw, PaperFig8Constants) {
  const auto law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  // κ0 = (b2 - b1) / (2 c1) = 0.0108 / 0.0184 /cm.
  EXPECT_NEAR(units::SiCurvatureToKes(law.kappa0()), 0.0108 / 0.0184, 1e-12);
  const double k0 = 0.0108 / 0.0184;
  EXPECT_NEAR(units::SiMomentToKes(law.moment0()), 0.0108 * k0 - 0.0092 * k0 * k0, 1e-12);
}

TEST(BendingLaw, DressFabricIsLinear) {
  // b1 = b2: κ0 = 0 and M = b2 κ whatever c1 says (physics.md, degenerate cases).
  const auto law = BendingLaw::FromKes(0.0973, 0.0973, 0.0453);
  EXPECT_EQ(law.kappa0(), 0.0);
  for (double k : {-300.0, -1.0, 0.0, 0.5, 250.0}) {
    EXPECT_NEAR(law.Moment(k), law.b2() * k, 1e-18 + 1e-14 * std::abs(law.b2() * k));
    EXPECT_DOUBLE_EQ(law.Stiffness(k), law.b2());
  }
}

TEST(BendingLaw, ZeroC1IsLinearInB1) {
  const auto law = BendingLaw::FromKes(0.05, 0.2, 0.0);
  EXPECT_TRUE(std::isinf(law.kappa0()));
  EXPECT_NEAR(law.Moment(1e3), law.b1() * 1e3, 1e-15);
  EXPECT_NEAR(law.Curvature(law.Moment(1e3)), 1e3, 1e-9);
}

TEST(BendingLaw, RejectsNegativeKappa0) {
  // b2 > b1 needs c1 > 0; a negative c1 never reaches slope b2.
  try {
    BendingLaw::FromKes(0.1, 0.2, -0.01);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("kappa0"), std::string::npos) << what;
    EXPECT_NE(what.find("b1 = 0.1"), std::string::npos) << what;
    EXPECT_NE(what.find("c1 = -0.01"), std::string::npos) << what;
  }
}

TEST(BendingLaw, RejectsNonPositiveAndNonFinite) {
  EXPECT_THROW(BendingLaw::FromKes(0.0, 0.1, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(0.1, -0.1, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(NAN, 0.1, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(0.1, INFINITY, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(0.1, 0.1, NAN), InputError);
}

TEST(BendingLaw, IsC1ContinuousAtKappa0) {
  for (const auto& law : TestLaws()) {
    const double k0 = law.kappa0();
    if (!(k0 > 0.0) || std::isinf(k0)) continue;
    // One-sided limits: the branches evaluated just below and above κ0.
    const double h = 1e-7 * k0;
    const double m_lo = law.Moment(k0 - h), m_hi = law.Moment(k0 + h);
    EXPECT_NEAR(m_hi - m_lo, 2.0 * h * law.Stiffness(k0), 1e-6 * std::abs(m_hi - m_lo));
    // B jumps by no more than its slope 2|c1| times the step: no discontinuity.
    EXPECT_NEAR(law.Stiffness(k0 - h), law.Stiffness(k0 + h), 2.5 * std::abs(law.c1()) * h);
    // Branch formulas agree exactly at κ0 (continuity of M and of B).
    EXPECT_NEAR(law.b1() * k0 + law.c1() * k0 * k0, law.moment0() + law.b2() * k0,
                1e-12 * law.moment_at_kappa0());
    EXPECT_NEAR(law.b1() + 2.0 * law.c1() * k0, law.b2(), 1e-12 * law.b2());
  }
}

TEST(BendingLaw, IsOddAndStrictlyIncreasing) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2000.0, 2000.0);  // κ [1/m], up to 20 /cm
  for (const auto& law : TestLaws()) {
    for (int i = 0; i < 200; ++i) {
      const double k = u(rng);
      EXPECT_EQ(law.Moment(-k), -law.Moment(k));
      EXPECT_EQ(law.Stiffness(-k), law.Stiffness(k));
      EXPECT_EQ(law.Energy(-k), law.Energy(k));
      EXPECT_GT(law.Stiffness(k), 0.0);
      const double dk = 1e-3 * (1.0 + std::abs(k));
      EXPECT_LT(law.Moment(k), law.Moment(k + dk));
    }
    EXPECT_EQ(law.Moment(0.0), 0.0);
  }
}

TEST(BendingLaw, InverseRoundTripTo1e12) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (const auto& law : TestLaws()) {
    for (int i = 0; i < 500; ++i) {
      const double k = std::copysign(std::pow(10.0, u(rng)), u(rng));  // 1e-3 .. 1e3 /m
      const double back = law.Curvature(law.Moment(k));
      EXPECT_NEAR(back, k, 1e-12 * std::abs(k)) << "kappa " << k;
      const double m = law.Moment(k);
      EXPECT_NEAR(law.Moment(law.Curvature(m)), m, 1e-12 * std::abs(m));
    }
  }
}

TEST(BendingLaw, StiffnessIsDerivativeOfMomentAndEnergyIntegratesIt) {
  for (const auto& law : TestLaws()) {
    for (double k : {-700.0, -30.0, 1.0, 20.0, 58.0, 61.0, 150.0, 900.0}) {
      const double h = 1e-5 * std::abs(k);
      // Central differences: O(h²) error, relative ~1e-9 here; the kink at κ0 is avoided
      // because it is C1 and the second derivative is bounded.
      EXPECT_NEAR((law.Moment(k + h) - law.Moment(k - h)) / (2 * h), law.Stiffness(k),
                  1e-6 * law.Stiffness(k));
      EXPECT_NEAR((law.Energy(k + h) - law.Energy(k - h)) / (2 * h), law.Moment(k),
                  1e-6 * std::abs(law.Moment(k)));
    }
  }
}

TEST(BendingLaw, MomentGradientMatchesFiniteDifferences) {
  for (const auto& f : kPaperFabrics) {
    if (f.b1 == f.b2) continue;  // not differentiable in the constants at b1 = b2
    const double p[3] = {units::KesStiffnessToSi(f.b1), units::KesStiffnessToSi(f.b2),
                         units::KesQuadraticToSi(f.c1)};
    const auto law = BendingLaw::FromSi(p[0], p[1], p[2]);
    for (double k : {0.3 * law.kappa0(), 3.0 * law.kappa0(), -2.0 * law.kappa0()}) {
      const auto g = law.MomentGradient(k);
      for (int j = 0; j < 3; ++j) {
        double q[3] = {p[0], p[1], p[2]};
        const double h = 1e-6 * std::abs(p[j]);
        q[j] += h;
        const double mp = BendingLaw::FromSi(q[0], q[1], q[2]).Moment(k);
        q[j] -= 2 * h;
        const double mm = BendingLaw::FromSi(q[0], q[1], q[2]).Moment(k);
        const double fd = (mp - mm) / (2 * h);
        EXPECT_NEAR(g[j], fd, 1e-6 * (std::abs(fd) + std::abs(law.Moment(k) / p[j])))
            << f.name << " j=" << j << " k=" << k;
      }
    }
  }
}

TEST(BendingLaw, BetaScalesMomentAndMatchesPrintedAlphaForm) {
  // Pabst section 3.4: α(κ) = β + (β - 1) c1 κ / b1; b1 := α(κ) b1; b2 := β b2 (typo fixed).
  for (const auto& law : TestLaws()) {
    for (double beta : {0.5, 0.8, 1.0, 1.2, 2.0}) {
      const auto scaled = law.Scaled(beta);
      EXPECT_DOUBLE_EQ(scaled.kappa0(), law.kappa0());
      for (double k : {0.1, 10.0, 40.0, 80.0, 500.0}) {
        EXPECT_NEAR(scaled.Moment(k), beta * law.Moment(k), 1e-13 * std::abs(beta * law.Moment(k)));
        if (k <= law.kappa0()) {
          const double alpha = beta + (beta - 1.0) * law.c1() * k / law.b1();
          const double printed = alpha * law.b1() * k + law.c1() * k * k;
          EXPECT_NEAR(scaled.Moment(k), printed, 1e-13 * std::abs(printed));
        } else {
          EXPECT_NEAR(scaled.Stiffness(k), beta * law.b2(), 1e-15 * beta * law.b2());
        }
      }
    }
  }
  EXPECT_THROW(TestLaws()[0].Scaled(0.0), InputError);
  EXPECT_THROW(TestLaws()[0].Scaled(-1.0), InputError);
}

TEST(BlendedLaw, WarpAndWeftAtAngles) {
  const auto warp = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const auto weft = BendingLaw::FromKes(0.08, 0.07, -0.006);
  const double k = 73.0;
  EXPECT_NEAR(BlendedLaw(warp, weft, 0.0).Moment(k), warp.Moment(k), 1e-18);
  EXPECT_NEAR(BlendedLaw(warp, weft, M_PI / 2).Moment(k), weft.Moment(k), 1e-17);
  const BlendedLaw mid(warp, weft, M_PI / 4);
  EXPECT_NEAR(mid.Moment(k), 0.5 * (warp.Moment(k) + weft.Moment(k)), 1e-17);
  for (double m : {-0.002, 1e-5, 0.001, 0.01}) {
    EXPECT_NEAR(mid.Moment(mid.Curvature(m)), m, 1e-13 * std::abs(m));
  }
}

}  // namespace
}  // namespace textile
