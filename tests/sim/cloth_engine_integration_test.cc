// The cloth engine's pieces together: a Gmsh-meshed strip with an embedded seam refined by the
// seam's own factor, per-hinge seam multipliers fed to the bending elements, and the seam band's
// mass. Each piece has its own tests; this checks that they fit.

#include <gtest/gtest.h>

#include <cmath>

#include "textile/sim/elements/bending_element.h"
#include "textile/sim/mesh/pattern_mesh.h"
#include "textile/sim/law/seam.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

// A 200 × 100 mm strip with a C-plain seam across it at x = 100 mm.
struct SeamedStrip {
  PatternMesh pm;
  std::vector<Hinge> hinges;
  Seam seam;
};

SeamedStrip MakeStrip(bool refine) {
  SeamedStrip s;
  s.seam.profile = SeamPreset("C-plain");
  s.seam.line.resize(2, 2);
  s.seam.line << 0.1, 0.0, 0.1, 0.1;
  PatternMeshOptions o;
  o.element_size = 0.01;
  if (refine) o.area_factor = SeamAreaFactor({s.seam.profile});
  s.pm = MeshRectangle(0.2, 0.1, {Polyline2(s.seam.line)}, o);
  s.hinges = BuildHinges(s.pm.mesh);
  return s;
}

TEST(ClothEngine, SeamRefinementAndMultipliersReachTheBendingElements) {
  const SeamedStrip plain = MakeStrip(false), refined = MakeStrip(true);
  // Refinement only near the seam: more triangles, and the small ones sit near x = 0.1 m.
  EXPECT_GT(refined.pm.mesh.num_triangles(), 2 * plain.pm.mesh.num_triangles());
  const Eigen::VectorXd areas = TriangleAreas(refined.pm.mesh);
  double near = 0;
  int n_near = 0;
  for (int f = 0; f < refined.pm.mesh.num_triangles(); ++f) {
    double cx = 0;
    for (int k = 0; k < 3; ++k) cx += refined.pm.mesh.vertices(refined.pm.mesh.triangles(f, k), 0) / 3;
    if (std::abs(cx - 0.1) < 0.005) near += areas(f), ++n_near;
  }
  ASSERT_GT(n_near, 0);
  // At the seam ⌈S(0)⌉ = ⌈9.07⌉ = 10: triangles there are about 10× smaller in area than the
  // unrefined mesh's (C-plain never falls to 1 within 100 mm, so the whole strip is refined
  // somewhat; Gmsh's size grading blurs the factor, hence the margin).
  const double plain_mean = TriangleAreas(plain.pm.mesh).mean();
  EXPECT_GT(plain_mean / (near / n_near), 5.0);
  EXPECT_LT(plain_mean / (near / n_near), 20.0);

  // Multipliers: S(0) = 9.07 for hinges on the seam line, 1 for hinges beyond the influence and
  // fade ranges (none here: the strip is only 100 mm from the seam), monotone in between.
  const std::vector<double> S = HingeSeamMultipliers(refined.pm.mesh, refined.hinges, {refined.seam});
  ASSERT_EQ(S.size(), refined.hinges.size());
  double s_max = 0;
  for (double v : S) s_max = std::max(s_max, v);
  EXPECT_NEAR(s_max, 9.07, 1e-9);  // B_f(0) of Table 2, on the seam's own edges

  // The same bend costs more energy with the seam's multipliers: bend the strip about the y
  // axis onto a cylinder of radius 0.1 m, with and without S.
  const auto law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const BendingElements bare(refined.pm.mesh, refined.hinges, law, std::nullopt);
  const BendingElements seamed(refined.pm.mesh, refined.hinges, law, std::nullopt, {}, S);
  Vertices x = refined.pm.mesh.vertices;
  const double R = 0.1;
  for (int v = 0; v < x.rows(); ++v) {
    const double u = refined.pm.mesh.vertices(v, 0);
    x(v, 0) = R * std::sin(u / R);
    x(v, 2) = R * (1 - std::cos(u / R));
  }
  const double e_bare = bare.Energy(x), e_seamed = seamed.Energy(x);
  EXPECT_GT(e_bare, 0.0);
  // Uniform bending: the energy ratio is the area-weighted mean of S over the strip, which for
  // C-plain across a 200 mm strip lies well above 1 and below S(0).
  EXPECT_GT(e_seamed / e_bare, 2.0);
  EXPECT_LT(e_seamed / e_bare, 9.07);
}

TEST(ClothEngine, SeamBandMassIsIndependentOfTheMesh) {
  const double rho = units::GsmToSi(200);
  const SeamedStrip a = MakeStrip(false), b = MakeStrip(true);
  const double ma = LumpedMasses(a.pm.mesh, rho, {a.seam}).sum();
  const double mb = LumpedMasses(b.pm.mesh, rho, {b.seam}).sum();
  // ρ A + (layers - 1) ρ × band area: 4 layers, a 10 mm band across the 100 mm strip.
  const double expected = rho * 0.2 * 0.1 + 3 * rho * 0.010 * 0.1;
  EXPECT_NEAR(ma, expected, 1e-12 * expected);
  EXPECT_NEAR(mb, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace textile
