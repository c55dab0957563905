#include "textile/fit/shape_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/elastica/elastica.h"

namespace textile {
namespace {

// A profile of the Fig. 8 fabric at overhang L [m], n points, starting `flat` [m] of strip
// lying straight on the platform before the edge (counted as overhang by a bad extraction).
Profile Strip(double L, double flat, int n) {
  ElasticaOptions o;
  o.num_samples = n;
  const ElasticaProfile e = SolveHeavyElastica(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2, L, o);
  EXPECT_TRUE(e.converged) << e.message;
  Profile p;
  p.source = "strip";
  for (int i = 0; i < n / 2 && flat > 0.0; ++i) {
    p.s.push_back(flat * i / (n / 2));
    p.x.push_back(flat * i / (n / 2));
    p.y.push_back(0.0);
  }
  for (int i = 0; i < n; ++i) {
    if (flat > 0.0 && i == 0) continue;
    p.s.push_back(flat + e.s[i]);
    p.x.push_back(flat + e.x[i]);
    p.y.push_back(e.y[i]);
  }
  return p;
}

TEST(ShapeCheck, ACantileverPassesAndAFlatPartOnThePlatformDoesNot) {
  const ShapeCheck good = CheckCantileverShape(Strip(0.06, 0.0, 400));
  ASSERT_TRUE(good.converged) << good.message;
  EXPECT_TRUE(good.plausible) << good.message;
  EXPECT_LT(good.rms, 1e-5);
  EXPECT_LE(good.points, 120);  // thinned
  // 50 mm of strip lying on the platform before a 60 mm overhang: a cantilever bends most at
  // its edge, so no law of eq. 1 makes this shape.
  const ShapeCheck flat = CheckCantileverShape(Strip(0.06, 0.05, 400));
  EXPECT_FALSE(flat.plausible) << flat.message;
  EXPECT_NE(flat.message.find("no heavy cantilever"), std::string::npos) << flat.message;
  // A trace that ran on from the tip along a shadow on the background, 30 mm level.
  Profile shadow = Strip(0.06, 0.0, 400);
  for (int i = 1; i <= 60; ++i) {
    shadow.x.push_back(shadow.x.back() + 0.5e-3);
    shadow.y.push_back(shadow.y.back());
    shadow.s.push_back(shadow.s.back() + 0.5e-3);
  }
  const ShapeCheck run_on = CheckCantileverShape(shadow);
  EXPECT_FALSE(run_on.plausible) << run_on.message;
}

}  // namespace
}  // namespace textile
