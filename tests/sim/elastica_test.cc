#include "textile/sim/elastica/elastica.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;

// The paper's three fabrics (KES constants as printed) with this project's densities
// (docs/spec/cantilever.md, reference table).
struct Fabric {
  const char* name;
  double b1, b2, c1;  // KES: gf·cm, gf·cm, gf·cm²
  double gsm;         // g/m²
  double tip_x_100mm, tip_y_100mm;  // reference tip at L = 100 mm [mm]
};
const Fabric kFabrics[] = {
    {"Fig8", 0.1, 0.0892, -0.0092, 200.0, 10.2859, -95.8981},
    {"Fig9dress", 0.0973, 0.0973, 0.0453, 130.0, 13.4553, -94.6510},
    {"Fig7interlining", 0.5168, 1.8856, 2.2683, 250.0, 42.1916, -82.5927},
};

BendingLaw LawOf(const Fabric& f) { return BendingLaw::FromKes(f.b1, f.b2, f.c1); }

// A solve that must converge.
ElasticaProfile Solve(const BendingLaw& law, double rho, double length,
                      const ElasticaOptions& options = {}) {
  ElasticaProfile p = SolveHeavyElastica(law, rho, length, options);
  EXPECT_TRUE(p.converged) << p.message;
  return p;
}

TEST(Elastica, SmallLoadTipDeflectionMatchesSeries) {
  // Linear law, load α = ρgL³/B: -y(L) = ρgL⁴/(8B) (1 - α²/80 + O(α⁴)). The solver shows the
  // remainder to be 2.78e-4 α⁴, so 3e-4 α⁴ bounds it, plus rounding (1e-13).
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.1, 0.0);
  const double rho = 0.2, weight = rho * units::kGravity;
  ElasticaOptions options;
  options.rel_tol = 1e-12;
  options.num_samples = 2;
  for (double alpha : {1e-3, 1e-2, 3e-2, 0.1}) {
    const double length = std::cbrt(alpha * law.b1() / weight);
    const ElasticaProfile p = Solve(law, rho, length, options);
    const double linear = weight * std::pow(length, 4) / (8.0 * law.b1());
    const double remainder = -p.tip_y / linear - (1.0 - alpha * alpha / 80.0);
    EXPECT_LE(std::abs(remainder), 3e-4 * std::pow(alpha, 4) + 1e-13) << "alpha = " << alpha;
    // Tip slope of the linear theory, ρgL³/(6B), to first order.
    EXPECT_NEAR(p.tip_angle / (alpha / 6.0), 1.0, 0.02 * alpha * alpha) << "alpha = " << alpha;
  }
}

TEST(Elastica, ArcLengthIsPreserved) {
  // Chords of a dense sampling fall short of the arc by Σ h³κ²/24 ≤ L h² κmax²/24.
  for (const Fabric& f : kFabrics) {
    ElasticaOptions options;
    options.num_samples = 2001;
    const double length = 0.1;
    const ElasticaProfile p = Solve(LawOf(f), units::GsmToSi(f.gsm), length, options);
    double chords = 0.0, kappa_max = 0.0;
    for (size_t i = 1; i < p.s.size(); ++i) {
      chords += std::hypot(p.x[i] - p.x[i - 1], p.y[i] - p.y[i - 1]);
      kappa_max = std::max(kappa_max, std::abs(p.kappa[i]));
    }
    const double h = length / 2000.0;
    const double deficit_bound = length * h * h * kappa_max * kappa_max / 24.0;
    EXPECT_LE(chords, length * (1.0 + 1e-13)) << f.name;
    EXPECT_GE(chords, length - deficit_bound - 1e-13 * length) << f.name;
  }
}

// ∫_a^b f with f and f' known at both ends (Euler-Maclaurin corrected trapezoid, O(h⁴)).
double HermiteIntegral(double h, double fa, double fb, double dfa, double dfb) {
  return 0.5 * h * (fa + fb) + h * h / 12.0 * (dfa - dfb);
}

TEST(Elastica, MomentBalanceHoldsAtEverySample) {
  // docs/spec/cantilever.md: m(s) = ρ g ∫_s^L (x(s') - x(s)) ds', by quadrature of the output
  // itself (dx/ds = cos θ). With 2001 samples the quadrature error is ~1e-12 relative; 1e-7 of the
  // clamp moment is the brief's bar.
  for (const Fabric& f : kFabrics) {
    for (double length : {0.03, 0.1}) {
      ElasticaOptions options;
      options.num_samples = 2001;
      const double rho = units::GsmToSi(f.gsm);
      const ElasticaProfile p = Solve(LawOf(f), rho, length, options);
      const int n = static_cast<int>(p.s.size());
      // Suffix integrals of x and of 1 from each sample to the tip.
      std::vector<double> int_x(n, 0.0);
      for (int i = n - 2; i >= 0; --i) {
        const double h = p.s[i + 1] - p.s[i];
        int_x[i] = int_x[i + 1] + HermiteIntegral(h, p.x[i], p.x[i + 1], std::cos(p.theta[i]),
                                                  std::cos(p.theta[i + 1]));
      }
      const double tolerance = 1e-7 * p.clamp_moment;
      for (int i = 0; i < n; i += 50) {
        const double balance =
            rho * units::kGravity * (int_x[i] - (length - p.s[i]) * p.x[i]);
        EXPECT_NEAR(p.moment[i], balance, tolerance) << f.name << " L = " << length
                                                     << " s = " << p.s[i];
      }
      EXPECT_NEAR(p.moment[0], p.clamp_moment, 1e-15 * p.clamp_moment);
      EXPECT_EQ(p.moment[n - 1], 0.0);  // free tip
    }
  }
}

TEST(Elastica, LawHoldsAtEverySample) {
  // M(κ(s)) = m(s): the curvature is the law's inverse of the moment; 1e-13 covers rounding.
  for (const Fabric& f : kFabrics) {
    const BendingLaw law = LawOf(f);
    const ElasticaProfile p = Solve(law, units::GsmToSi(f.gsm), 0.1);
    for (size_t i = 0; i < p.s.size(); ++i) {
      EXPECT_NEAR(law.Moment(p.kappa[i]), p.moment[i], 1e-13 * p.clamp_moment) << f.name;
    }
  }
}

TEST(Elastica, EndsAreClampedAndFree) {
  for (const Fabric& f : kFabrics) {
    const ElasticaProfile p = Solve(LawOf(f), units::GsmToSi(f.gsm), 0.1);
    EXPECT_EQ(p.s.front(), 0.0);
    EXPECT_EQ(p.s.back(), 0.1);
    EXPECT_EQ(p.x.front(), 0.0);
    EXPECT_EQ(p.y.front(), 0.0);
    EXPECT_NEAR(p.theta.front(), 0.0, 1e-14);  // the shooting condition, to rounding
    EXPECT_EQ(p.theta.back(), p.tip_angle);
    EXPECT_EQ(p.x.back(), p.tip_x);
    EXPECT_EQ(p.y.back(), p.tip_y);
    EXPECT_EQ(p.kappa.back(), 0.0);
    EXPECT_NEAR(std::log(kHalfPi - p.tip_angle), p.log_tip_gap, 1e-9);
    // The strip bends one way: θ increases, the profile descends.
    for (size_t i = 1; i < p.s.size(); ++i) {
      EXPECT_GT(p.theta[i], p.theta[i - 1]) << f.name;
      EXPECT_LT(p.y[i], p.y[i - 1]) << f.name;
    }
  }
}

TEST(Elastica, ToleranceRefinementConverges) {
  // rel_tol 1e-8 against 1e-12: the answers agree to ~1e-8 (of L for positions).
  for (const Fabric& f : kFabrics) {
    for (double length : {0.005, 0.035, 0.1, 0.3}) {
      ElasticaOptions coarse, fine;
      coarse.rel_tol = 1e-8;
      fine.rel_tol = 1e-12;
      coarse.num_samples = fine.num_samples = 51;
      const double rho = units::GsmToSi(f.gsm);
      const ElasticaProfile a = Solve(LawOf(f), rho, length, coarse);
      const ElasticaProfile b = Solve(LawOf(f), rho, length, fine);
      for (size_t i = 0; i < a.s.size(); ++i) {
        EXPECT_NEAR(a.x[i], b.x[i], 1e-8 * length) << f.name << " L = " << length;
        EXPECT_NEAR(a.y[i], b.y[i], 1e-8 * length) << f.name << " L = " << length;
        EXPECT_NEAR(a.theta[i], b.theta[i], 1e-8 * b.tip_angle) << f.name << " L = " << length;
      }
      EXPECT_NEAR(a.clamp_curvature, b.clamp_curvature, 1e-8 * b.clamp_curvature) << f.name;
    }
  }
}

TEST(Elastica, ReproducesReferenceTipsAt100mm) {
  // docs/spec/cantilever.md's table prints the tip to 1e-4 mm; agreement to that rounding (half a
  // unit in the last digit) is ~1e-6 relative. The crossing columns are tested with the outputs.
  for (const Fabric& f : kFabrics) {
    const ElasticaProfile p = Solve(LawOf(f), units::GsmToSi(f.gsm), 0.1);
    EXPECT_NEAR(units::MToMm(p.tip_x), f.tip_x_100mm, 0.5e-4 + 1e-9) << f.name;
    EXPECT_NEAR(units::MToMm(p.tip_y), f.tip_y_100mm, 0.5e-4 + 1e-9) << f.name;
  }
}

TEST(Elastica, KinkInsideTheRangeIsAnEvent) {
  // Fig. 7 interlining at 100 mm: κ0 = 0.30 /cm lies between the tip (0) and the clamp
  // (0.49 /cm). The reported kink arc length is where κ = κ0: sampling there must give κ0 to
  // the solver's accuracy (1e-9 relative), and the moment M(κ0).
  const Fabric& f = kFabrics[2];
  const BendingLaw law = LawOf(f);
  const double rho = units::GsmToSi(f.gsm);
  const ElasticaProfile p = Solve(law, rho, 0.1);
  ASSERT_FALSE(std::isnan(p.kink_arc_length));
  EXPECT_GT(p.clamp_curvature, law.kappa0());
  ElasticaOptions at_kink;
  at_kink.arc_lengths = {p.kink_arc_length};
  const ElasticaProfile q = Solve(law, rho, 0.1, at_kink);
  EXPECT_NEAR(q.kappa[0], law.kappa0(), 1e-9 * law.kappa0());
  EXPECT_NEAR(q.moment[0], law.moment_at_kappa0(), 1e-9 * law.moment_at_kappa0());
  // A strip too short to reach κ0 has no kink.
  const ElasticaProfile short_strip = Solve(law, rho, 0.02);
  EXPECT_LT(short_strip.clamp_curvature, law.kappa0());
  EXPECT_TRUE(std::isnan(short_strip.kink_arc_length));
}

TEST(Elastica, KinkBeyondTheRangeChangesNothing) {
  // Two laws with the same b1, c1 but κ0 = 5 and 10 /cm agree wherever κ < 5 /cm: the strips
  // must be identical (to rounding and solver noise, 1e-12 of L), with no kink crossed.
  const BendingLaw a = BendingLaw::FromKes(0.1, 0.2, 0.01);
  const BendingLaw b = BendingLaw::FromKes(0.1, 0.3, 0.01);
  ASSERT_NEAR(units::SiCurvatureToKes(a.kappa0()), 5.0, 1e-12);
  const ElasticaProfile pa = Solve(a, 0.2, 0.1), pb = Solve(b, 0.2, 0.1);
  ASSERT_LT(units::SiCurvatureToKes(pa.clamp_curvature), 5.0);
  EXPECT_TRUE(std::isnan(pa.kink_arc_length));
  for (size_t i = 0; i < pa.s.size(); ++i) {
    EXPECT_NEAR(pa.x[i], pb.x[i], 1e-12 * 0.1);
    EXPECT_NEAR(pa.y[i], pb.y[i], 1e-12 * 0.1);
  }
}

TEST(Elastica, DegenerateLawsAreLinear) {
  // b1 = b2 (κ0 = 0, any c1) and c1 = 0 (κ0 = ∞) are both M = b κ (docs/spec/physics.md): same
  // strip as the plain linear law, to 1e-12 of L.
  const BendingLaw linear = BendingLaw::FromKes(0.1, 0.1, 0.0);
  const BendingLaw equal_b = BendingLaw::FromKes(0.1, 0.1, 0.05);
  const BendingLaw no_c1 = BendingLaw::FromKes(0.1, 0.3, 0.0);
  for (double length : {0.01, 0.05, 0.2}) {
    const ElasticaProfile p = Solve(linear, 0.2, length);
    for (const BendingLaw& law : {equal_b, no_c1}) {
      const ElasticaProfile q = Solve(law, 0.2, length);
      EXPECT_TRUE(std::isnan(q.kink_arc_length));
      for (size_t i = 0; i < p.s.size(); ++i) {
        EXPECT_NEAR(p.x[i], q.x[i], 1e-12 * length);
        EXPECT_NEAR(p.y[i], q.y[i], 1e-12 * length);
      }
    }
  }
}

TEST(Elastica, ShapeDependsOnlyOnMomentOverDensity) {
  // docs/spec/cantilever.md: only M/ρ is identifiable. Scaling the law and the density by β leaves
  // the strip unchanged (to solver accuracy, 1e-9 of L).
  const BendingLaw law = LawOf(kFabrics[0]);
  const ElasticaProfile p = Solve(law, 0.2, 0.07);
  for (double beta : {0.1, 7.0}) {
    const ElasticaProfile q = Solve(law.Scaled(beta), 0.2 * beta, 0.07);
    for (size_t i = 0; i < p.s.size(); ++i) {
      EXPECT_NEAR(p.x[i], q.x[i], 1e-9 * 0.07);
      EXPECT_NEAR(p.y[i], q.y[i], 1e-9 * 0.07);
    }
  }
}

TEST(Elastica, RequestedArcLengthsMatchUniformSamples) {
  // Sampling at given s gives the same values as the uniform grid there (to the solver's
  // accuracy, 1e-10 of L at the default rel_tol: the two runs take different steps).
  const BendingLaw law = LawOf(kFabrics[2]);
  const ElasticaProfile uniform = Solve(law, 0.25, 0.1);
  ElasticaOptions options;
  options.arc_lengths = {0.0, uniform.s[17], uniform.s[17], uniform.s[150], 0.1};
  const ElasticaProfile q = Solve(law, 0.25, 0.1, options);
  ASSERT_EQ(q.s.size(), 5u);
  const int index[] = {0, 17, 17, 150, 200};
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(q.x[k], uniform.x[index[k]], 1e-10 * 0.1);
    EXPECT_NEAR(q.y[k], uniform.y[index[k]], 1e-10 * 0.1);
    EXPECT_NEAR(q.theta[k], uniform.theta[index[k]], 1e-10);
  }
}

TEST(Elastica, LongSoftStripHangsVertically) {
  // 500 mm of a 0.001 gf·cm, 400 g/m² strip is ~200 bending lengths: π/2 - θ(L) ≈
  // exp(-(2/3)(L/ℓ)^{3/2}) underflows, the log form must carry it.
  const BendingLaw law = BendingLaw::FromKes(0.001, 0.001, 0.0);
  const double rho = 0.4, length = 0.5;
  ElasticaOptions options;
  options.sensitivities = true;
  const ElasticaProfile p = Solve(law, rho, length, options);
  ASSERT_TRUE(p.converged);
  EXPECT_EQ(p.tip_angle, kHalfPi);  // to double precision
  EXPECT_LT(p.log_tip_gap, -745.0);  // exp() of it underflows
  EXPECT_TRUE(std::isfinite(p.log_tip_gap));
  const double bending_length = std::cbrt(law.b1() / (rho * units::kGravity));
  EXPECT_NEAR(p.log_tip_gap, -(2.0 / 3.0) * std::pow(length / bending_length, 1.5),
              0.05 * std::pow(length / bending_length, 1.5));
  for (size_t i = 0; i < p.s.size(); ++i) {
    ASSERT_TRUE(std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.theta[i]));
    ASSERT_TRUE(std::isfinite(p.kappa[i]) && std::isfinite(p.moment[i]));
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(p.dx_dp(i, k)) && std::isfinite(p.dy_dp(i, k)) &&
                  std::isfinite(p.dtheta_dp(i, k)));
    }
  }
  // The strip leaves the edge within a few bending lengths and then hangs straight down.
  EXPECT_GT(p.tip_x, 0.0);
  EXPECT_LT(p.tip_x, 3.0 * bending_length);
  EXPECT_LT(p.tip_y, -length + 3.0 * bending_length);
}

TEST(Elastica, ConvergesAcrossTheParameterRange) {
  // The brief's corners: ρ 20-2000 g/m², L 1-500 mm, B 0.001-10 gf·cm, with a softening, a
  // stiffening and a linear law; each converges to a clamped, monotone, finite strip.
  for (double b : {0.001, 10.0}) {
    const BendingLaw laws[] = {BendingLaw::FromKes(b, b, 0.0),
                               BendingLaw::FromKes(b, 0.5 * b, -0.25 * b),   // κ0 = 1 /cm
                               BendingLaw::FromKes(b, 3.0 * b, 1.0 * b)};    // κ0 = 1 /cm
    for (const BendingLaw& law : laws) {
      for (double gsm : {20.0, 2000.0}) {
        for (double mm : {1.0, 30.0, 500.0}) {
          ElasticaOptions options;
          options.num_samples = 21;
          const ElasticaProfile p =
              SolveHeavyElastica(law, units::GsmToSi(gsm), units::MmToM(mm), options);
          ASSERT_TRUE(p.converged) << p.BriefReport();
          EXPECT_NEAR(p.theta.front(), 0.0, 1e-12) << p.BriefReport();
          for (size_t i = 1; i < p.s.size(); ++i) {
            ASSERT_TRUE(std::isfinite(p.x[i]) && std::isfinite(p.y[i]));
            EXPECT_GE(p.theta[i], p.theta[i - 1]) << p.BriefReport();
            EXPECT_LE(p.theta[i], kHalfPi);
          }
          EXPECT_LE(p.shooting_iterations, 12) << p.BriefReport();
        }
      }
    }
  }
}

// Central finite differences of x, y, θ at the samples w.r.t. each law constant, relative step
// 1e-4 (c1 against b1 × 1 cm). At a degenerate law b1 = b2 the law is not differentiable in b1
// and b2 separately (only b1 ≤ b2 is valid there, and the one-sided quotients carry
// non-analytic O(h) terms from the vanishing quadratic branch); the smooth directions are
// b1 + b2 together and c1, so there column 0 holds d/db1 + d/db2 and column 1 is unused.
struct Derivatives {
  Eigen::MatrixX3d dx, dy, dtheta;
};
Derivatives FiniteDifferences(const BendingLaw& law, double rho, double length) {
  ElasticaOptions options;
  options.rel_tol = 1e-13;
  options.num_samples = 21;
  const bool degenerate = law.b1() == law.b2();
  const std::array<double, 3> p0 = {law.b1(), law.b2(), law.c1()};
  const std::array<double, 3> scale = {law.b1(), law.b2(), law.b1() * 0.01};
  Derivatives d{Eigen::MatrixX3d::Zero(21, 3), Eigen::MatrixX3d::Zero(21, 3),
                Eigen::MatrixX3d::Zero(21, 3)};
  auto solve = [&](int k, double delta) {
    std::array<double, 3> p = p0;
    p[k] += delta;
    if (degenerate && k == 0) p[1] += delta;
    return Solve(BendingLaw::FromSi(p[0], p[1], p[2]), rho, length, options);
  };
  for (int k = 0; k < 3; ++k) {
    if (degenerate && k == 1) continue;
    const double h = 1e-4 * scale[k];
    const ElasticaProfile plus = solve(k, h), minus = solve(k, -h);
    for (int i = 0; i < 21; ++i) {
      d.dx(i, k) = (plus.x[i] - minus.x[i]) / (2 * h);
      d.dy(i, k) = (plus.y[i] - minus.y[i]) / (2 * h);
      d.dtheta(i, k) = (plus.theta[i] - minus.theta[i]) / (2 * h);
    }
  }
  return d;
}

void ExpectSensitivitiesMatch(const BendingLaw& law, double rho, double length,
                              const std::string& name) {
  ElasticaOptions options;
  options.sensitivities = true;
  options.rel_tol = 1e-12;
  options.num_samples = 21;
  ElasticaProfile p = Solve(law, rho, length, options);
  ASSERT_EQ(p.dx_dp.rows(), 21);
  const Derivatives fd = FiniteDifferences(law, rho, length);
  if (law.b1() == law.b2()) {
    // The returned one-sided derivatives (b1 from below, b2 from above) sum to the smooth one;
    // d/db1 is the envelope's exact 0 (∂M/∂b1 = κ0 = 0 above κ0).
    EXPECT_TRUE(p.dx_dp.col(0).isZero(0.0) && p.dy_dp.col(0).isZero(0.0)) << name;
    for (Eigen::MatrixX3d* m : {&p.dx_dp, &p.dy_dp, &p.dtheta_dp}) {
      m->col(0) += m->col(1);
      m->col(1).setZero();
    }
  }
  // Compare relative sensitivities p ∂f/∂p (c1 against b1 × 1 cm); the tolerance is 1e-5 of
  // the largest one: finite-difference truncation (1e-8) and noise (1e-13/1e-4) are far below.
  const Eigen::RowVector3d scale(law.b1(), law.b2(), law.b1() * 0.01);
  auto check = [&](const Eigen::MatrixX3d& analytic, const Eigen::MatrixX3d& numeric,
                   const char* what) {
    const Eigen::MatrixX3d a = analytic.array().rowwise() * scale.array();
    const Eigen::MatrixX3d n = numeric.array().rowwise() * scale.array();
    const double tolerance = 1e-5 * n.cwiseAbs().maxCoeff();
    for (int i = 0; i < a.rows(); ++i)
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(a(i, k), n(i, k), tolerance) << name << " " << what << " sample " << i
                                                 << " constant " << k;
  };
  check(p.dx_dp, fd.dx, "x");
  check(p.dy_dp, fd.dy, "y");
  check(p.dtheta_dp, fd.dtheta, "theta");
}

TEST(Elastica, SensitivitiesMatchFiniteDifferencesForPaperFabrics) {
  for (const Fabric& f : kFabrics) {
    for (double length : {0.035, 0.1}) {
      ExpectSensitivitiesMatch(LawOf(f), units::GsmToSi(f.gsm), length,
                               std::string(f.name) + " L = " + std::to_string(length));
    }
  }
}

TEST(Elastica, SensitivitiesMatchFiniteDifferencesAcrossTheKink) {
  // κ0 = 1 /cm inside the curvature range, softening and stiffening; and a long strip in the
  // log form (θ(L) within 1e-7 of π/2).
  const BendingLaw softening = BendingLaw::FromKes(0.1, 0.05, -0.025);
  const BendingLaw stiffening = BendingLaw::FromKes(0.1, 0.3, 0.1);
  for (const auto& [law, length] : {std::pair{softening, 0.05}, std::pair{stiffening, 0.15},
                                    std::pair{softening, 0.25}}) {
    ASSERT_GT(Solve(law, 0.2, length).kink_arc_length, 0.0);  // κ0 is crossed
  }
  ExpectSensitivitiesMatch(softening, 0.2, 0.05, "softening");
  ExpectSensitivitiesMatch(stiffening, 0.2, 0.15, "stiffening");
  ExpectSensitivitiesMatch(softening, 0.2, 0.25, "softening, long");
}

TEST(Elastica, SensitivitiesDoNotChangeTheSolution) {
  const BendingLaw law = LawOf(kFabrics[0]);
  ElasticaOptions with;
  with.sensitivities = true;
  const ElasticaProfile a = Solve(law, 0.2, 0.1), b = Solve(law, 0.2, 0.1, with);
  EXPECT_EQ(a.dx_dp.rows(), 0);
  for (size_t i = 0; i < a.s.size(); ++i) EXPECT_NEAR(a.y[i], b.y[i], 1e-11);
}

TEST(Elastica, WarmStartGivesTheSameStrip) {
  const BendingLaw law = LawOf(kFabrics[1]);
  const ElasticaProfile cold = Solve(law, 0.13, 0.04);
  ElasticaOptions options;
  options.tip_angle_guess = cold.tip_angle * 1.01;
  const ElasticaProfile warm = Solve(law, 0.13, 0.04, options);
  EXPECT_NEAR(warm.tip_x, cold.tip_x, 1e-12);
  EXPECT_NEAR(warm.tip_y, cold.tip_y, 1e-12);
}

// A strip so long that θ(L) rounds to π/2 (not a tip_angle_guess the solver takes) warm-starts
// from its log gap instead; a fit's continuation over a 250 mm strip relies on it.
TEST(Elastica, WarmStartFromTheLogTipGapOfAStripHangingVertically) {
  const BendingLaw law = LawOf(kFabrics[0]);
  const ElasticaProfile cold = Solve(law, 0.2, 0.4);
  ASSERT_TRUE(cold.converged) << cold.message;
  ASSERT_EQ(cold.tip_angle, kHalfPi);  // the angle has lost what the log gap keeps
  ASSERT_LT(cold.log_tip_gap, -40.0);
  ElasticaOptions options;
  options.log_tip_gap_guess = cold.log_tip_gap + 0.5;
  const ElasticaProfile warm = Solve(law, 0.2, 0.4, options);
  ASSERT_TRUE(warm.converged) << warm.message;
  EXPECT_NEAR(warm.log_tip_gap, cold.log_tip_gap, 1e-6 * std::abs(cold.log_tip_gap));
  EXPECT_NEAR(warm.tip_x, cold.tip_x, 1e-9);
  EXPECT_NEAR(warm.tip_y, cold.tip_y, 1e-9);
}

TEST(Elastica, NonConvergenceIsReportedNotReturned) {
  // Two integrations cannot converge from a far guess: the result says so and carries no data.
  const BendingLaw law = LawOf(kFabrics[0]);
  ElasticaOptions options;
  options.max_shooting_iterations = 2;
  options.tip_angle_guess = 1e-3;
  const ElasticaProfile p = SolveHeavyElastica(law, 0.2, 0.3, options);
  EXPECT_FALSE(p.converged);
  EXPECT_NE(p.message.find("did not converge in 2 integrations"), std::string::npos)
      << p.message;
  EXPECT_TRUE(p.x.empty());
  EXPECT_NE(p.BriefReport().find("FAILED"), std::string::npos);
}

TEST(Elastica, TimeCapEndsInFailureWithoutNumbers) {
  // A cap of 0 s has passed at the first clock reading (the first step of the first
  // integration), whatever the machine's speed: the failure path without timing luck.
  const BendingLaw law = LawOf(kFabrics[0]);
  for (const bool sensitivities : {false, true}) {
    SCOPED_TRACE(sensitivities ? "with sensitivities" : "plain");
    ElasticaOptions options;
    options.max_seconds = 0.0;
    options.sensitivities = sensitivities;
    const ElasticaProfile p = SolveHeavyElastica(law, 0.2, 0.1, options);
    EXPECT_FALSE(p.converged);
    EXPECT_NE(p.message.find("time cap"), std::string::npos) << p.message;
    EXPECT_NE(p.message.find("max_seconds = 0 s"), std::string::npos) << p.message;
    EXPECT_EQ(p.shooting_iterations, 1);
    EXPECT_TRUE(p.s.empty() && p.x.empty() && p.y.empty() && p.theta.empty() &&
                p.kappa.empty() && p.moment.empty());
    EXPECT_EQ(p.dx_dp.rows(), 0);
    EXPECT_TRUE(std::isnan(p.tip_x) && std::isnan(p.tip_y) && std::isnan(p.tip_angle));
    EXPECT_NE(p.BriefReport().find("FAILED: time cap"), std::string::npos) << p.BriefReport();
  }
  // The same strip under the default cap converges: the failure above is the cap's.
  const ElasticaProfile ok = Solve(law, 0.2, 0.1);
  EXPECT_GT(ElasticaOptions{}.max_seconds, 0.0);
  EXPECT_TRUE(ok.converged);
}

TEST(Elastica, OptionsCheckRejectsBadValues) {
  std::string why;
  EXPECT_TRUE(ElasticaOptions{}.Check(&why)) << why;
  auto rejects = [](ElasticaOptions o, const std::string& expected) {
    std::string reason;
    EXPECT_FALSE(o.Check(&reason));
    EXPECT_NE(reason.find(expected), std::string::npos) << reason;
  };
  ElasticaOptions o;
  o.rel_tol = 0.0;
  rejects(o, "rel_tol");
  o = {};
  o.num_samples = 1;
  rejects(o, "num_samples");
  o = {};
  o.max_shooting_iterations = 1;
  rejects(o, "max_shooting_iterations");
  o = {};
  o.tip_angle_guess = kHalfPi;
  rejects(o, "tip_angle_guess");
  o = {};
  o.log_tip_gap_guess = std::log(kHalfPi);
  rejects(o, "log_tip_gap_guess");
  o = {};
  o.log_tip_gap_guess = -std::numeric_limits<double>::infinity();
  rejects(o, "log_tip_gap_guess");
  o = {};
  o.arc_lengths = {0.0, 0.02, 0.01};
  rejects(o, "ascending");
  o = {};
  o.arc_lengths = {-0.01};
  rejects(o, "arc_lengths[0]");
  for (const double bad : {-1.0, std::nan(""), HUGE_VAL}) {
    o = {};
    o.max_seconds = bad;
    rejects(o, "max_seconds");
  }
  o = {};
  o.max_seconds = 0.0;  // allowed: fails at once (TimeCapEndsInFailureWithoutNumbers)
  EXPECT_TRUE(o.Check(&why)) << why;
}

TEST(Elastica, BadInputThrowsWithMessage) {
  const BendingLaw law = LawOf(kFabrics[0]);
  auto message_of = [&](double rho, double length, const ElasticaOptions& options) {
    try {
      SolveHeavyElastica(law, rho, length, options);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  EXPECT_NE(message_of(0.0, 0.1, {}).find("areal density"), std::string::npos);
  EXPECT_NE(message_of(0.2, -1.0, {}).find("overhang length"), std::string::npos);
  EXPECT_NE(message_of(0.2, std::nan(""), {}).find("overhang length"), std::string::npos);
  ElasticaOptions beyond;
  beyond.arc_lengths = {0.05, 0.2};
  EXPECT_NE(message_of(0.2, 0.1, beyond).find("beyond the overhang"), std::string::npos);
  ElasticaOptions bad;
  bad.rel_tol = 1.0;
  EXPECT_THROW(SolveHeavyElastica(law, 0.2, 0.1, bad), InputError);
}

TEST(Elastica, BriefReportSummarises) {
  const ElasticaProfile p = Solve(LawOf(kFabrics[2]), 0.25, 0.1);
  const std::string report = p.BriefReport();
  EXPECT_NE(report.find("tip (42.19"), std::string::npos) << report;
  EXPECT_NE(report.find("kink"), std::string::npos) << report;
  EXPECT_NE(report.find("integrations"), std::string::npos) << report;
}

// ---- Spline laws ----

// The Pabst law sampled at 41 knots, 0 .. 4 /cm (every strip below stays under 4 /cm).
BendingLaw SampledSpline(const BendingLaw& law) {
  std::vector<double> kappa, moment;
  for (int i = 0; i <= 40; ++i) {
    kappa.push_back(10.0 * i);
    moment.push_back(law.Moment(10.0 * i));
  }
  return BendingLaw::FromSpline(kappa, moment);
}

TEST(Elastica, SplineOfAPabstLawGivesItsStrip) {
  // Largest |Δx|, |Δy| over the samples, relative to L, at L = 50, 100, 200 mm. The spline
  // differs from the law only on the pieces around κ0 (bending_law_test.cc): the dress fabric
  // (linear) is exact, Fig. 8 (κ0 = 0.59 /cm, small B corner) is within 5e-7 L measured, the
  // interlining (κ0 = 0.30 /cm, a 4.5 gf·cm² jump in B', strips whose whole curvature range is
  // 0 .. 0.26 /cm at 50 mm) within 3.3e-4 L measured. Tolerances 2× that.
  const double kTolerance[] = {1e-6, 1e-13, 7e-4};
  for (size_t n = 0; n < std::size(kFabrics); ++n) {
    const Fabric& f = kFabrics[n];
    const BendingLaw pabst = LawOf(f), spline = SampledSpline(pabst);
    const double rho = units::GsmToSi(f.gsm);
    for (double length : {0.05, 0.1, 0.2}) {
      const ElasticaProfile a = Solve(pabst, rho, length), b = Solve(spline, rho, length);
      ASSERT_EQ(a.s.size(), b.s.size());
      for (size_t i = 0; i < a.s.size(); ++i) {
        EXPECT_NEAR(b.x[i], a.x[i], kTolerance[n] * length) << f.name << " L " << length;
        EXPECT_NEAR(b.y[i], a.y[i], kTolerance[n] * length) << f.name << " L " << length;
      }
    }
  }
}

TEST(Elastica, SplineKnotsAreEvents) {
  // The knee law: each knot's moment is crossed as an event; the reported kink is the last
  // knot (κ0 of a spline, where it turns linear), and sampling there gives that curvature.
  const BendingLaw knee =
      BendingLaw::FromSpline({0.0, 0.3, 2.0, 10.0, 20.0}, {0.0, 0.23, 0.25, 0.30, 0.39});
  // From barely bent (clamp 0.003 /m) to hanging past the knee (clamp 121 /m).
  for (double rho : {0.2, 2.0, 20.0}) {
    for (double length : {0.05, 0.2, 0.4}) {
      const ElasticaProfile p = Solve(knee, rho, length);
      ASSERT_TRUE(p.converged) << rho << " " << length << ": " << p.message;
      for (size_t i = 0; i < p.s.size(); ++i) {
        EXPECT_NEAR(knee.Moment(p.kappa[i]), p.moment[i], 1e-13 * p.clamp_moment);
      }
      if (p.clamp_curvature > knee.kappa0()) {
        ASSERT_FALSE(std::isnan(p.kink_arc_length));
        ElasticaOptions at_kink;
        at_kink.arc_lengths = {p.kink_arc_length};
        const ElasticaProfile q = Solve(knee, rho, length, at_kink);
        // The kink's arc length is the last shot's, before the final Newton correction of
        // the shooting unknown (≤ 1e-6 relative): good to ~1e-7 in the moment, amplified
        // 40-fold in κ by the knee's small B past the last knot (measured 6e-8 in κ).
        EXPECT_NEAR(q.moment[0], knee.moment_at_kappa0(), 1e-6 * knee.moment_at_kappa0());
        EXPECT_NEAR(q.kappa[0], knee.kappa0(), 1e-6 * knee.kappa0());
      } else {
        EXPECT_TRUE(std::isnan(p.kink_arc_length));
      }
    }
  }
}

TEST(Elastica, SensitivitiesRefuseASplineLaw) {
  ElasticaOptions o;
  o.sensitivities = true;
  const BendingLaw spline = SampledSpline(LawOf(kFabrics[0]));
  try {
    SolveHeavyElastica(spline, 0.2, 0.1, o);
    FAIL() << "sensitivities of a spline law were computed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a spline law has none"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace textile
