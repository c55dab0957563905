// Numerical guards of the heavy elastica (issue 9, point 4): the shooting cap ends in a clear
// failure, NaN/inf never get in, and a solve that did not converge hands out no numbers
// (elastica.h: "When converged is false, message says why and the arrays are empty").

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const BendingLaw kFig8 = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
const double kRho = units::GsmToSi(200.0);

// The contract of a failed solve: a reason and no numbers.
void ExpectNoResult(const ElasticaProfile& p) {
  EXPECT_FALSE(p.converged);
  EXPECT_FALSE(p.message.empty());
  EXPECT_TRUE(p.s.empty() && p.x.empty() && p.y.empty() && p.theta.empty() && p.kappa.empty() &&
              p.moment.empty());
  EXPECT_TRUE(std::isnan(p.tip_x) && std::isnan(p.tip_y) && std::isnan(p.tip_angle));
}

// The contract of a converged solve: every number finite, the strip hangs below the edge.
void ExpectFiniteResult(const ElasticaProfile& p, size_t samples) {
  ASSERT_TRUE(p.converged) << p.message;
  ASSERT_EQ(p.s.size(), samples);
  ASSERT_EQ(p.x.size(), samples);
  ASSERT_EQ(p.y.size(), samples);
  for (size_t i = 0; i < samples; ++i) {
    ASSERT_TRUE(std::isfinite(p.s[i]) && std::isfinite(p.x[i]) && std::isfinite(p.y[i]) &&
                std::isfinite(p.theta[i]) && std::isfinite(p.kappa[i]) && std::isfinite(p.moment[i]))
        << "sample " << i;
  }
  EXPECT_TRUE(std::isfinite(p.tip_x) && std::isfinite(p.tip_y) && std::isfinite(p.clamp_curvature));
  EXPECT_LT(p.tip_y, 0.0);
  // θ(L) rounds to π/2 for strips hanging almost vertically; log(π/2 - θ(L)) stays finite.
  EXPECT_GT(p.tip_angle, 0.0);
  EXPECT_LE(p.tip_angle, M_PI / 2);
  EXPECT_TRUE(std::isfinite(p.log_tip_gap));
}

TEST(ElasticaGuards, ShootingCapEndsInFailureWithoutNumbers) {
  ElasticaOptions o;
  o.max_shooting_iterations = 2;  // the smallest cap Check accepts; shooting needs more
  const ElasticaProfile p = SolveHeavyElastica(kFig8, kRho, 0.1, o);
  ExpectNoResult(p);
  EXPECT_NE(p.message.find("did not converge in 2"), std::string::npos) << p.message;
  EXPECT_LE(p.shooting_iterations, 2);
  // The same strip with the default cap converges: the failure above is the cap's.
  ExpectFiniteResult(SolveHeavyElastica(kFig8, kRho, 0.1), 201);
}

TEST(ElasticaGuards, NonFiniteOrNonPositiveInputsAreRefused) {
  for (const double bad : {kNaN, kInf, -kInf, 0.0, -1.0}) {
    EXPECT_THROW(SolveHeavyElastica(kFig8, bad, 0.1), InputError) << bad;
    EXPECT_THROW(SolveHeavyElastica(kFig8, kRho, bad), InputError) << bad;
  }
  // A law cannot even be made from non-finite constants.
  EXPECT_THROW(BendingLaw::FromKes(kNaN, 0.1, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(0.1, kInf, 0.0), InputError);
  EXPECT_THROW(BendingLaw::FromKes(0.1, 0.1, kNaN), InputError);
}

TEST(ElasticaGuards, UnusableOptionsAreRefused) {
  const auto refused = [](const ElasticaOptions& o, const char* what) {
    std::string why;
    EXPECT_FALSE(o.Check(&why)) << what;
    EXPECT_FALSE(why.empty()) << what;
    EXPECT_THROW(SolveHeavyElastica(kFig8, kRho, 0.1, o), InputError) << what;
  };
  ElasticaOptions o;
  o.rel_tol = kNaN;
  refused(o, "rel_tol NaN");
  o.rel_tol = 0.0;
  refused(o, "rel_tol 0");
  o.rel_tol = kInf;
  refused(o, "rel_tol inf");
  o = {};
  o.num_samples = 1;
  refused(o, "one sample");
  o = {};
  o.max_shooting_iterations = 1;
  refused(o, "shooting cap 1");
  o = {};
  o.arc_lengths = {0.0, kNaN, 0.05};
  refused(o, "NaN arc length");
  o.arc_lengths = {0.0, kInf};
  refused(o, "infinite arc length");
  o.arc_lengths = {-0.01, 0.05};
  refused(o, "negative arc length");
  o.arc_lengths = {0.02, 0.01};
  refused(o, "descending arc lengths");
  // Beyond the strip's length: checked against L when solving.
  o.arc_lengths = {0.0, 0.2};
  EXPECT_THROW(SolveHeavyElastica(kFig8, kRho, 0.1, o), InputError);
}

TEST(ElasticaGuards, ExtremeStripsEitherConvergeFinitelyOrSayWhy) {
  // The corners of what material files accept (b 1e-5 .. 1e5 gf·cm) and of plausible
  // overhangs: each solve is either finite throughout or a failure with a reason and no
  // numbers, never garbage.
  int converged = 0;
  for (const double b : {1e-4, 0.1, 1e3, 1e5}) {
    for (const double L : {0.001, 0.1, 1.0}) {
      SCOPED_TRACE("b = " + std::to_string(b) + " gf·cm, L = " + std::to_string(L) + " m");
      ElasticaOptions o;
      o.num_samples = 21;
      const ElasticaProfile p = SolveHeavyElastica(BendingLaw::FromKes(b, 0.8 * b, -0.1 * b), kRho, L, o);
      if (p.converged) {
        ExpectFiniteResult(p, 21);
        ++converged;
      } else {
        ExpectNoResult(p);
      }
    }
  }
  // Most of them are ordinary strips: the guard must not be refusing everything.
  EXPECT_GE(converged, 8);
}

}  // namespace
}  // namespace textile
