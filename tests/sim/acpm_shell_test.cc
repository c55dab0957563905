#include "textile/sim/acpm_shell.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/cantilever_outputs.h"
#include "textile/sim/error.h"

namespace textile {
namespace {

Material Fabric(double b1, double b2, double c1, double gsm) {
  Material m;
  m.areal_density = gsm * 1e-3;
  m.bending = BendingLaw::FromKes(b1, b2, c1);
  return m;
}

TEST(AcpmShell, PlainSampleIsCutEvenlyAndConvergesUnderRefinement) {
  // The paper's Fig. 8 fabric. Every ray of a plain sample is cut at the same overhang, and the
  // crossing converges as the elements shrink. It does NOT converge to the exact elastica's:
  // the hinge energies couple bending with twist on these grids and a free strip is about
  // twice as soft (docs/statics.md, "Bending-twist coupling"); the factor of a seamed sample is
  // therefore taken against the shell's own plain crossing at the same resolution.
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  options.num_rays = 3;
  const std::vector<double> rays = options.RayPositions();
  std::vector<double> crossing;
  for (double element : {0.004, 0.002, 0.001}) {
    ShellAcpmSettings settings;
    settings.element_length = element;
    const AcpmCrossings shell = ShellAcpmCrossings(m, options, rays, settings);
    ASSERT_TRUE(shell.converged) << shell.message;
    // Alternating diagonals keep the mesh mirror-symmetric: the outer rays agree.
    EXPECT_NEAR(shell.overhang.front(), shell.overhang.back(), 1e-9);
    EXPECT_FALSE(shell.profile_x.empty());
    EXPECT_GT(shell.solves, 3);
    crossing.push_back(shell.overhang[1]);
  }
  // Differences shrink with each halving (first-order convergence or better).
  EXPECT_LT(std::abs(crossing[2] - crossing[1]), std::abs(crossing[1] - crossing[0]));
  const BarrierCrossing exact = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density);
  ASSERT_TRUE(exact.converged);
  // The documented bias: 20-25 % short. If the elements are ever fixed this fails on purpose.
  EXPECT_GT(crossing[2] / exact.overhang, 0.7);
  EXPECT_LT(crossing[2] / exact.overhang, 0.85);
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
  // couples the width: the front is nearly flat over the middle, docs/acpm.md.)
  EXPECT_GT(shell.overhang[2], shell.overhang[0]);
  EXPECT_GT(shell.overhang[1], shell.overhang[0]);
  EXPECT_NEAR(shell.overhang[0], shell.overhang[4], 2e-4);
  EXPECT_NEAR(shell.overhang[1], shell.overhang[3], 2e-4);
  EXPECT_GT(shell.overhang[2], shell.plain_overhang);
}

TEST(AcpmShell, BadSettingsAreRefused) {
  const Material m = Fabric(0.1, 0.0892, -0.0092, 200);
  AcpmOptions options;
  ShellAcpmSettings settings;
  settings.element_length = 0.0;
  EXPECT_THROW(ShellAcpmCrossings(m, options, options.RayPositions(), settings), InputError);
}

}  // namespace
}  // namespace textile
