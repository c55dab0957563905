#include "textile/sim/scenes/acpm_shell.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "textile/sim/scenes/acpm.h"
#include "textile/sim/elastica/cantilever_outputs.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/polyline.h"
#include "textile/sim/law/seam.h"

namespace textile {
namespace {

Material Fabric(double b1, double b2, double c1, double gsm) {
  Material m;
  m.areal_density = gsm * 1e-3;
  m.bending = BendingLaw::FromKes(b1, b2, c1);
  return m;
}

TEST(AcpmShell, PlainSampleConvergesToTheElasticaAtFirstOrder) {
  // The paper's Fig. 8 fabric, one push per resolution (no extrapolation): the crossing error
  // halves with the element (first order, from the clamped and free ends) and the mirror rays
  // are cut at the same overhang (each half of the width is split along mirrored diagonals).
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  const BarrierCrossing exact = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density);
  ASSERT_TRUE(exact.converged);
  AcpmOptions options;
  options.num_rays = 3;
  const std::vector<double> rays = options.RayPositions();
  std::vector<double> error;
  for (double element : {0.002, 0.001, 0.0005}) {
    ShellAcpmSettings settings;
    settings.element_length = element;
    settings.extrapolate = false;
    const AcpmCrossings shell = ShellAcpmCrossings(m, options, rays, settings);
    ASSERT_TRUE(shell.converged) << shell.message;
    EXPECT_NEAR(shell.overhang.front(), shell.overhang.back(), 1e-9);  // mirrored halves
    EXPECT_FALSE(shell.profile_x.empty());
    EXPECT_GT(shell.shape.num_triangles(), 0);
    EXPECT_GT(shell.solves, 3);
    error.push_back(shell.overhang[1] / exact.overhang - 1.0);
  }
  // Measured: -4.7 %, -2.4 %, -1.2 %. The ratio of successive errors is that of the elements.
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(error[k], 0.0);
    EXPECT_NEAR(error[k] / error[k + 1], 2.0, 0.25) << k;
  }
}

TEST(AcpmShell, ExtrapolatedPlainSampleAgreesWithTheElastica) {
  // The default: 2 mm and 1 mm elements, 2 L(1 mm) - L(2 mm). Issue 7's tolerance is 0.5 %;
  // measured -0.05 % (Fig. 8), -0.01 % (interlining), -0.18 % (a very soft fabric: 10 cells).
  for (const Material& m : {Fabric(0.1, 0.0892, -0.0092, 200), Fabric(0.5168, 1.8856, 2.2683, 150),
                            Fabric(0.005, 0.005, 0.0, 60)}) {
    const BarrierCrossing exact = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density);
    ASSERT_TRUE(exact.converged);
    AcpmOptions options;
    options.num_rays = 3;
    const AcpmCrossings shell = ShellAcpmCrossings(m, options, options.RayPositions());
    ASSERT_TRUE(shell.converged) << shell.message;
    for (double l : shell.overhang) EXPECT_NEAR(l / exact.overhang, 1.0, 0.005);
  }
}

TEST(AcpmShell, HingeBendingIsTooSoftForAFreeStrip) {
  // The paper's hinge energies couple bend with twist on a triangle grid (docs/methods/statics.md):
  // the plain strip crosses 20-25 % short of the elastica at any resolution. Kept as a check
  // that the tensor model is what fixed it.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  const BarrierCrossing exact = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density);
  AcpmOptions options;
  options.num_rays = 3;
  ShellAcpmSettings settings;
  settings.bending = BendingDiscretization::kHinge;
  settings.extrapolate = false;
  const AcpmCrossings shell = ShellAcpmCrossings(m, options, options.RayPositions(), settings);
  ASSERT_TRUE(shell.converged) << shell.message;
  EXPECT_NEAR(shell.overhang.front(), shell.overhang.back(), 1e-9);  // alternating diagonals
  EXPECT_GT(shell.overhang[1] / exact.overhang, 0.7);
  EXPECT_LT(shell.overhang[1] / exact.overhang, 0.85);
}

// A strip pushed along x, the warp, bends with the warp law in both discretisations: a limp
// warp and a stiff weft (8x) cross near the warp law's elastica, not the weft's (twice as far),
// and a limper bias changes nothing.
// The hinges once blended by the edge's own angle and bent a warp strip with the weft law.
TEST(AcpmShell, AWarpStripBendsWithTheWarpLawInBothDiscretisations) {
  Material m = Fabric(0.05, 0.05, 0.0, 200);
  m.bending_weft = BendingLaw::FromKes(0.4, 0.4, 0.0);
  // A bias law bends no warp strip: the push drops it (the tensor elements would refuse it).
  m.bending_bias = BendingLaw::FromKes(0.01, 0.01, 0.0);
  const double warp = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density).overhang;
  const double weft = FindBarrierCrossing(m.EffectiveWeftLaw(), m.areal_density).overhang;
  ASSERT_NEAR(weft / warp, 2.0, 1e-6);
  AcpmOptions options;
  options.num_rays = 3;
  for (BendingDiscretization d : {BendingDiscretization::kTensor, BendingDiscretization::kHinge}) {
    ShellAcpmSettings settings;
    settings.bending = d;
    settings.extrapolate = false;
    const AcpmCrossings shell = ShellAcpmCrossings(m, options, options.RayPositions(), settings);
    ASSERT_TRUE(shell.converged) << shell.message;
    // The hinges are 0.7-0.85 of the law on this grid (HingeBendingIsTooSoftForAFreeStrip).
    EXPECT_GT(shell.overhang[1] / warp, 0.7);
    EXPECT_LT(shell.overhang[1] / warp, 1.0);
    if (d == BendingDiscretization::kHinge) {  // the diagonals would otherwise take the bias
      Material no_bias = m;
      no_bias.bending_bias.reset();
      const AcpmCrossings plain =
          ShellAcpmCrossings(no_bias, options, options.RayPositions(), settings);
      ASSERT_TRUE(plain.converged) << plain.message;
      EXPECT_EQ(plain.overhang, shell.overhang);
    }
  }
}

TEST(AcpmShell, SeamAlongThePushStiffensTheRaysNearItSymmetrically) {
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  options.num_rays = 5;
  options.seam.direction = AcpmSeamDirection::kAlong;
  options.seam.profile = SeamPreset("C-plain");
  const std::vector<double> rays = options.RayPositions();
  ShellAcpmSettings settings;
  settings.element_length = 0.004;
  settings.width_cells_seam = 10;
  const AcpmCrossings shell = ShellAcpmCrossings(m, options, rays, settings);
  ASSERT_TRUE(shell.converged) << shell.message;
  ASSERT_TRUE(std::isfinite(shell.plain_overhang));
  // The rays near the seam are cut later than the edges; left and right alike. (The plate
  // couples the width: the front is nearly flat over the middle, docs/methods/acpm.md.)
  EXPECT_GT(shell.overhang[2], shell.overhang[0]);
  EXPECT_GT(shell.overhang[1], shell.overhang[0]);
  // Mirror rays agree to 0.5 % of L: the uniform diagonals tilt the front at first order in
  // the element, the extrapolation (4 and 2 mm here) leaves ~0.4 %.
  EXPECT_NEAR(shell.overhang[0], shell.overhang[4], 0.005 * shell.overhang[0]);
  EXPECT_NEAR(shell.overhang[1], shell.overhang[3], 0.005 * shell.overhang[0]);
  EXPECT_GT(shell.overhang[2], shell.plain_overhang);
}

// One ray of the ACPM push with a C-plain seam across the strip, `position` [m] behind the front.
AcpmOptions OneRayAcrossCPlainSeam(double position) {
  AcpmOptions options;
  options.num_rays = 1;
  options.seam.direction = AcpmSeamDirection::kAcross;
  options.seam.profile = SeamPreset("C-plain");
  options.seam.position = position;
  return options;
}

TEST(AcpmShell, AcrossSeamBehindTheEdgeStiffensTheOverhang) {
  // A C-plain seam 100 mm behind the front: the plain Fig. 8 strip is cut at 33.6 mm, with
  // the seam line still 66 mm back on the platform, where S(d) (reaching d_max + fade =
  // 120 mm) already stiffens the hanging strip. The shell must agree with the exact 1D
  // elastica (61.7 mm); it used to ignore the seam until the line left the platform and gave
  // the plain crossing. Tolerance: the default shell's crossings are within 0.1 % of the
  // elastica on plain strips; the seamed push runs at one resolution (4 mm elements here,
  // stretched over the longer overhang) with the plain run's extrapolation as a correction,
  // measured +/- 1 %, so 3 %.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options = OneRayAcrossCPlainSeam(0.1);
  options.model = AcpmModelKind::kElastica;
  const AcpmResult elastica = RunAcpm(m, options);
  ASSERT_GT(elastica.rays[0].overhang, 0.055);  // docs/methods/acpm.md: 61.7 mm
  const AcpmCrossings shell = ShellAcpmCrossings(m, options, options.RayPositions());
  ASSERT_TRUE(shell.converged) << shell.message;
  EXPECT_NEAR(shell.overhang[0] / elastica.rays[0].overhang, 1.0, 0.03);
  EXPECT_FALSE(shell.profile_x.empty());
  EXPECT_GE(shell.profile_x.front(), -1e-12);  // the profile starts at the edge
  EXPECT_LT(shell.profile_x.front(), 1e-3);
}

TEST(AcpmShell, AcrossSeamFarBehindTheEdgeChangesNothing) {
  // Past d_max + fade (120 mm) behind the crossing the seam no longer reaches the overhang:
  // the seamed push and the plain one are cut at the same overhang.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options = OneRayAcrossCPlainSeam(0.2);
  ShellAcpmSettings settings;
  settings.extrapolate = false;
  const AcpmCrossings seamed = ShellAcpmCrossings(m, options, options.RayPositions(), settings);
  ASSERT_TRUE(seamed.converged) << seamed.message;
  // The crossing tolerance (0.05 mm) bounds how far apart two refinements of one root land.
  EXPECT_NEAR(seamed.overhang[0], seamed.plain_overhang, options.crossing_tolerance);
}

TEST(AcpmShell, SeamAlongOnASideEdgeIsMirroredByTheOtherEdge) {
  // docs/methods/acpm.md refuses only z_s outside [0, W]: a seam on either side edge runs along that
  // edge's grid line (it used to move an inner line onto the edge: a degenerate triangle).
  // The two are mirror images: ray i of one is ray n-1-i of the other, and the rays next to
  // the seam are cut later than those far from it.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  options.num_rays = 3;
  options.seam.direction = AcpmSeamDirection::kAlong;
  options.seam.profile = SeamPreset("C-plain");
  ShellAcpmSettings settings;
  settings.element_length = 0.004;
  settings.extrapolate = false;
  const std::vector<double> rays = options.RayPositions();
  options.seam.position = 0.0;
  const AcpmCrossings left = ShellAcpmCrossings(m, options, rays, settings);
  options.seam.position = options.width;
  const AcpmCrossings right = ShellAcpmCrossings(m, options, rays, settings);
  ASSERT_TRUE(left.converged) << left.message;
  ASSERT_TRUE(right.converged) << right.message;
  for (int i = 0; i < 3; ++i)  // the crossing tolerance: refinements of mirrored roots
    EXPECT_NEAR(left.overhang[i], right.overhang[2 - i], options.crossing_tolerance) << i;
  EXPECT_GT(left.overhang[0], left.overhang[2]);
}

TEST(AcpmShell, TooStiffWithinTheSampleLengthIsBadInputAndLongerSamplesAreSearched) {
  // A board-like law: it does not reach the barrier within 300 mm (the elastica model's "too
  // stiff" is bad input: the shell's must be too, not a failed computation), but does within
  // a 1000 mm sample, which the shell must search as the elastica does.
  const Material board = Fabric(50.0, 50.0, 0.0, 100);  // tests/bad_inputs: material-board
  AcpmOptions options;
  options.num_rays = 1;
  try {
    ShellAcpmCrossings(board, options, options.RayPositions());
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not reach the barrier within 300 mm"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("too stiff"), std::string::npos) << e.what();
  }
  options.length = 1.0;
  const BarrierCrossing exact =
      FindBarrierCrossing(board.EffectiveLaw(), board.areal_density, {.max_length = 1.0});
  ASSERT_TRUE(exact.converged) << exact.message;
  ASSERT_GT(exact.overhang, 0.3);
  ShellAcpmSettings settings;
  settings.element_length = 0.02;
  settings.extrapolate = false;
  const AcpmCrossings shell = ShellAcpmCrossings(board, options, options.RayPositions(), settings);
  ASSERT_TRUE(shell.converged) << shell.message;
  // At 8 % elements the first-order error is a few % (-4.4 % at 6 % elements on Fig. 8).
  EXPECT_NEAR(shell.overhang[0] / exact.overhang, 1.0, 0.1);
}

TEST(AcpmShell, CrossingRefinementIsCapped) {
  // A tolerance below the spacing of doubles at L (~3e-18 m at 33 mm) can never be reached:
  // the refinement stops at its cap and says so instead of looping.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  options.num_rays = 1;
  options.crossing_tolerance = 1e-18;
  ShellAcpmSettings settings;
  settings.element_length = 0.004;
  settings.extrapolate = false;
  const AcpmCrossings shell = ShellAcpmCrossings(m, options, options.RayPositions(), settings);
  EXPECT_FALSE(shell.converged);
  EXPECT_NE(shell.message.find("did not narrow"), std::string::npos) << shell.message;
}

TEST(AcpmShell, BadSettingsAreRefused) {
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  ShellAcpmSettings settings;
  settings.element_length = 0.0;
  EXPECT_THROW(ShellAcpmCrossings(m, options, options.RayPositions(), settings), InputError);
  ShellAcpmSettings cap;
  cap.max_seconds = std::nan("");
  EXPECT_THROW(ShellAcpmCrossings(m, options, options.RayPositions(), cap), InputError);
}

TEST(AcpmShell, TimeCapEndsInFailureWithoutCrossings) {
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  ShellAcpmSettings cap;
  cap.max_seconds = 0.0;
  const AcpmCrossings c = ShellAcpmCrossings(m, options, options.RayPositions(), cap);
  EXPECT_FALSE(c.converged);
  EXPECT_NE(c.message.find("time cap"), std::string::npos) << c.message;
  EXPECT_TRUE(c.overhang.empty());
}

// Largest distance of the points (x_k, y_k) from the elastica's curve (a polyline of 401
// samples: its chords miss the curve by < 1 µm) [m], and the tip distance.
struct Gap {
  double max = 0.0, tip = 0.0;
};
Gap GapToElastica(const Material& m, double overhang, const std::vector<double>& x,
                  const std::vector<double>& y) {
  ElasticaOptions eo;
  eo.num_samples = 401;
  const ElasticaProfile e = SolveHeavyElastica(m.EffectiveLaw(), m.areal_density, overhang, eo);
  EXPECT_TRUE(e.converged) << e.message;
  Gap g;
  g.max = MaxDistanceToPolyline(e.x, e.y, x, y);
  g.tip = std::hypot(x.back() - e.x.back(), y.back() - e.y.back());
  return g;
}

TEST(ShellCantilever, PlainStripLiesOnTheElastica) {
  // The Fig. 8 fabric at the overhangs of the shipped profiles and a long one that hangs
  // steeply (continuation from 0.4 L): the extrapolated shell's centre line lies on the exact
  // elastica; one push at 2 mm is visibly off (first order), and the extrapolation removes
  // most of that.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  for (double overhang : {0.04, 0.08, 0.15}) {
    ShellAcpmSettings one;
    one.extrapolate = false;
    const ShellCantilever coarse = SolveShellCantilever(m, overhang, 0.025, one);
    const ShellCantilever shell = SolveShellCantilever(m, overhang, 0.025);
    ASSERT_TRUE(coarse.converged) << coarse.message;
    ASSERT_TRUE(shell.converged) << shell.message;
    EXPECT_EQ(shell.x.front(), 0.0);
    EXPECT_EQ(shell.y.front(), 0.0);
    EXPECT_GT(shell.solves, coarse.solves);
    const Gap gc = GapToElastica(m, overhang, coarse.x, coarse.y);
    const Gap gs = GapToElastica(m, overhang, shell.x, shell.y);
    // Measured: 0.035, 0.041, 0.068 mm (0.09 %, 0.05 %, 0.05 % of L), all at the tip; one
    // push at 2 mm: 1.4-1.9 mm.
    EXPECT_LT(gs.max, 0.0015 * overhang);
    EXPECT_LT(gs.tip, 0.0015 * overhang);
    EXPECT_LT(gs.tip, 0.5 * gc.tip);
  }
}

TEST(ShellCantilever, StiffTechnicalStripConvergesAtTheRoundOffFloor) {
  // The law fitted to a real technical fabric's photo (1387 g/m², b1 ~ 8600 gf·cm softening
  // 70-fold at κ0 = 0.5 /m) at its 250 mm overhang: on 1 mm elements its residual cannot fall
  // below ~1e-6 of the weight in double precision, ten times the solver's tolerance, and every
  // solve stalled there until its cap. Now converged at that floor, and on the elastica.
  const Material m = Fabric(8557.3, 119.37, -8.1671e5, 1387);
  const double overhang = 0.25;
  const ShellCantilever shell = SolveShellCantilever(m, overhang, 0.025);
  ASSERT_TRUE(shell.converged) << shell.message;
  const Gap g = GapToElastica(m, overhang, shell.x, shell.y);
  // Measured 0.24 mm (0.1 % of L): the sharp knee needs finer elements than apparel laws.
  EXPECT_LT(g.max, 0.002 * overhang);
}

TEST(ShellCantilever, RefusesBadArguments) {
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  EXPECT_THROW(SolveShellCantilever(m, 0.0, 0.025), InputError);
  EXPECT_THROW(SolveShellCantilever(m, std::nan(""), 0.025), InputError);
  EXPECT_THROW(SolveShellCantilever(m, 0.05, 0.3), InputError);
  ShellAcpmSettings bad;
  bad.width_cells_plain = 0;
  EXPECT_THROW(SolveShellCantilever(m, 0.05, 0.025, bad), InputError);
  for (double seconds : {std::nan(""), -1.0, HUGE_VAL}) {
    ShellAcpmSettings cap;
    cap.max_seconds = seconds;
    EXPECT_THROW(SolveShellCantilever(m, 0.05, 0.025, cap), InputError) << seconds;
  }
}

TEST(ShellCantilever, TimeCapEndsInFailureWithoutAProfile) {
  // A cap of 0 s has always passed at the first solve's check: the run fails with the cap's
  // message and no profile, deterministically.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  ShellAcpmSettings cap;
  cap.max_seconds = 0.0;
  const ShellCantilever c = SolveShellCantilever(m, 0.05, 0.025, cap);
  EXPECT_FALSE(c.converged);
  EXPECT_NE(c.message.find("time cap"), std::string::npos) << c.message;
  EXPECT_TRUE(c.x.empty());
}

}  // namespace
}  // namespace textile
