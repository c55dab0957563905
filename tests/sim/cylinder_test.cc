// The cylinder test of docs/spec/physics.md ("Discrete bending"): a flat sheet laid isometrically
// on a cylinder of radius R must have a bending energy per area that converges to Ψ(1/R) under
// refinement. Pabst et al.'s "resolution independence" (section 3.3, Fig. 3), measured.
//
// What holds and what does not (docs/methods/bending.md, "Cylinder test"): a hinge energy sees only
// bend angles across edges, so its limit depends on how the mesh's edges sit relative to the
// cylinder axis. With the area weight A_h = |ē| h̄e it is exact for grids whose edges run
// along and across the axis (regular grids wrapped in x or y, whatever the law) and, for a
// linear law, for equilateral meshes at every orientation. The criss-cross grid's zig-zag
// edges bend although the surface does not bend across them (κ = -1/R on the edges along
// the axis), which gives Ψ(c) + 2 Ψ(c/2) instead of Ψ(c): 3/2 for a linear law. Randomly
// jittered grids settle above Ψ by a bias that grows with the jitter (+4 % at 10 %, +17 % at
// 20 % of a cell).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "textile/sim/elements/bending_element.h"

namespace textile {
namespace {

enum class Axis { kWrapX, kWrapY };  // the coordinate that goes round the cylinder

// (x, y) -> (R sin(x/R), y, R (1 - cos(x/R))) and the same with x and y exchanged: an
// isometry onto a cylinder of curvature 1/R, bending towards +z (θ > 0 on every hinge that
// bends the right way).
Vertices OnCylinder(const Vertices& flat, double radius, Axis axis) {
  Vertices x = flat;
  for (int i = 0; i < x.rows(); ++i) {
    const int a = axis == Axis::kWrapX ? 0 : 1;
    const double s = flat(i, a);
    x(i, a) = radius * std::sin(s / radius);
    x(i, 2) = radius * (1.0 - std::cos(s / radius));
  }
  return x;
}

// A grid whose interior vertices move by up to ±fraction of a cell in x and y (seeded).
TriangleMesh JitteredGrid(double size, int n, double fraction, unsigned seed) {
  TriangleMesh m = RegularGridMesh(size, size, n, n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-fraction * size / n, fraction * size / n);
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) {
      m.vertices(j * (n + 1) + i, 0) += u(rng);
      m.vertices(j * (n + 1) + i, 1) += u(rng);
    }
  return m;
}

// Equilateral triangles, edges along x, alternate rows shifted by half an edge; about
// size × size. The kind of mesh a Delaunay mesher makes in the interior.
TriangleMesh EquilateralMesh(double size, int n) {
  const double a = size / n, row = a * std::sqrt(3.0) / 2.0;
  const int rows = static_cast<int>(std::round(size / row));
  TriangleMesh m;
  m.vertices.resize((rows + 1) * (n + 1), 3);
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.row(j * (n + 1) + i) << a * (i + 0.5 * (j % 2)), row * j, 0.0;
  m.triangles.resize(2 * rows * n, 3);
  int f = 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < n; ++i) {
      const int p = j * (n + 1) + i, q = p + 1, r = p + n + 1, s = r + 1;
      if (j % 2 == 0) {
        m.triangles.row(f++) << p, q, r;
        m.triangles.row(f++) << q, s, r;
      } else {
        m.triangles.row(f++) << p, s, r;
        m.triangles.row(f++) << p, q, s;
      }
    }
  return m;
}

struct Family {
  std::string name;
  std::function<TriangleMesh(int n)> make;
};

const std::vector<Family>& Families() {
  constexpr double kSize = 0.05;  // 5 cm × 5 cm: 2.5 rad round a 2 cm cylinder
  static const std::vector<Family> all = {
      {"regular", [](int n) { return RegularGridMesh(kSize, kSize, n, n); }},
      {"criss-cross", [](int n) { return CrissCrossGridMesh(kSize, kSize, n, n); }},
      {"jittered 10%", [](int n) { return JitteredGrid(kSize, n, 0.1, 1234u + n); }},
      {"jittered 20%", [](int n) { return JitteredGrid(kSize, n, 0.2, 4321u + n); }},
      {"equilateral", [](int n) { return EquilateralMesh(kSize, n); }},
  };
  return all;
}

struct Law {
  std::string name;
  BendingLaw law;
};

const std::vector<Law>& Laws() {
  static const std::vector<Law> all = {
      {"linear", BendingLaw::FromKes(0.1, 0.1, 0.0)},
      {"fig8", BendingLaw::FromKes(0.1, 0.0892, -0.0092)},
      {"interlining", BendingLaw::FromKes(0.5168, 1.8856, 2.2683)},
  };
  return all;
}

constexpr int kLevels[] = {5, 10, 20, 40, 80};
constexpr int kNumLevels = static_cast<int>(std::size(kLevels));
// 1/R = 50 /m and 100 /m: below and above the Fig. 8 fabric's κ0 = 58.7 /m, above the
// interlining's κ0 = 30.2 /m, so both branches of both laws are exercised.
constexpr double kRadii[] = {0.02, 0.01};

// Bending energy per area [J/m²] of the mesh laid on the cylinder.
double EnergyPerArea(const TriangleMesh& flat, const BendingLaw& law, double radius, Axis axis) {
  const BendingElements b(flat, BuildHinges(flat), law, std::nullopt,
                          {.model = BendingModel::kPabst});
  return b.Energy(OnCylinder(flat.vertices, radius, axis)) / TriangleAreas(flat).sum();
}

struct Row {
  std::string family, law;
  Axis axis;
  double radius;
  std::vector<double> ratio;  // E/A / Ψ(1/R), one per level
};

// Every family × axis × law × radius × level once (a few seconds), shared by the tests.
const std::vector<Row>& Table() {
  static const std::vector<Row> rows = [] {
    std::vector<Row> out;
    for (const Family& family : Families()) {
      std::vector<TriangleMesh> meshes;
      for (int n : kLevels) meshes.push_back(family.make(n));
      for (Axis axis : {Axis::kWrapX, Axis::kWrapY})
        for (const Law& law : Laws())
          for (double radius : kRadii) {
            Row r{family.name, law.name, axis, radius, {}};
            for (const TriangleMesh& m : meshes)
              r.ratio.push_back(EnergyPerArea(m, law.law, radius, axis) /
                                law.law.Energy(1.0 / radius));
            out.push_back(r);
          }
    }
    return out;
  }();
  return rows;
}

const BendingLaw& LawNamed(const std::string& name) {
  for (const Law& l : Laws())
    if (l.name == name) return l.law;
  throw std::logic_error(name);
}

TEST(CylinderTest, PrintsTheErrorTable) {
  // The table of docs/methods/bending.md: relative error of the energy per area against Ψ(1/R).
  std::printf("| mesh | wrap | law | R [mm] |");
  for (int n : kLevels) std::printf(" n = %d |", n);
  std::printf("\n|---|---|---|---|");
  for (int i = 0; i < kNumLevels; ++i) std::printf("---|");
  std::printf("\n");
  for (const Row& r : Table()) {
    std::printf("| %s | %s | %s | %.0f |", r.family.c_str(), r.axis == Axis::kWrapX ? "x" : "y",
                r.law.c_str(), r.radius * 1e3);
    for (double q : r.ratio) std::printf(" %+.4f |", q - 1.0);
    std::printf("\n");
  }
  EXPECT_EQ(Table().size(), 5u * 2 * 3 * 2);
}

// The regular grid bends only across the edges that run along the axis, each by exactly
// |ē|/R, so every hinge is exact; what is missing is the one column of hinges at the
// boundary: error -1/n. At n = 80: 1.25 %; the bound allows round-off on top.
constexpr double kRegularBoundAtFinest = 0.0125 + 1e-9;

TEST(CylinderTest, RegularGridsConvergeToPsiForEveryLawAlongBothAxes) {
  for (const Row& r : Table()) {
    if (r.family != "regular") continue;
    for (int k = 0; k < kNumLevels; ++k) {
      EXPECT_NEAR(r.ratio[k] - 1.0, -1.0 / kLevels[k], 1e-9) << r.law << " n = " << kLevels[k];
      if (k > 0) {
        EXPECT_LT(std::abs(r.ratio[k] - 1.0), std::abs(r.ratio[k - 1] - 1.0));
      }
    }
    EXPECT_LE(std::abs(r.ratio.back() - 1.0), kRegularBoundAtFinest) << r.law;
  }
}

// Equilateral meshes with a linear law: exact in the interior at every orientation
// (docs/methods/bending.md derives Σ κ² = c² per pair of triangles), O(1/n) from the boundary.
constexpr double kEquilateralLinearBoundAtFinest = 0.012;

TEST(CylinderTest, EquilateralMeshesConvergeToPsiForALinearLaw) {
  for (const Row& r : Table()) {
    if (r.family != "equilateral" || r.law != "linear") continue;
    for (int k = 1; k < kNumLevels; ++k)
      EXPECT_LT(std::abs(r.ratio[k] - 1.0), std::abs(r.ratio[k - 1] - 1.0));
    EXPECT_LE(std::abs(r.ratio.back() - 1.0), kEquilateralLinearBoundAtFinest);
  }
}

// A nonlinear law sees the equilateral mesh's mix of hinge curvatures (2c/3, 2c/3, -c/3 for
// a cylinder across an edge) through Ψ, not through Ψ's quadratic part: the limit is off by
// up to 20 % for the stiffening interlining. Bound stated from the measured table.
constexpr double kEquilateralNonlinearBound = 0.21;

TEST(CylinderTest, EquilateralMeshesStayWithinTheNonlinearMixBound) {
  for (const Row& r : Table()) {
    if (r.family != "equilateral") continue;
    EXPECT_LE(std::abs(r.ratio.back() - 1.0), kEquilateralNonlinearBound) << r.law;
    if (r.axis == Axis::kWrapY) {
      // Edges along the axis (y-wrap of this mesh): only they bend, each exactly; any law.
      EXPECT_LE(std::abs(r.ratio.back() - 1.0), kEquilateralLinearBoundAtFinest) << r.law;
    }
  }
}

// The criss-cross grid does NOT converge to Ψ(1/R): per cell, the edges across the axis bend
// by c, the edges along it by -c (zig-zag), the four half-diagonals by c/2, with areas a²/2
// each, so E/A -> Ψ(c) + 2 Ψ(c/2). The test holds that limit (and fails if the energy ever
// comes close to Ψ, which would mean the derivation no longer describes the code).
TEST(CylinderTest, CrissCrossGridsConvergeToTheirZigZagLimitNotToPsi) {
  for (const Row& r : Table()) {
    if (r.family != "criss-cross") continue;
    const BendingLaw& law = LawNamed(r.law);
    const double c = 1.0 / r.radius;
    const double limit = (law.Energy(c) + 2.0 * law.Energy(0.5 * c)) / law.Energy(c);
    for (int k = 1; k < kNumLevels; ++k)
      EXPECT_LT(std::abs(r.ratio[k] - limit), std::abs(r.ratio[k - 1] - limit)) << r.law;
    // Boundary deficit of at most one cell ring (1/n of the limit) plus O(h²) chord effects.
    EXPECT_LE(std::abs(r.ratio.back() - limit), 1.5 * limit / kLevels[kNumLevels - 1]) << r.law;
    EXPECT_GT(r.ratio.back() - 1.0, 0.3) << r.law;
  }
}

// Jittered grids settle at a bias that grows with the jitter (spurious bends across skewed
// edges add energy; they never cancel in a sum of squares): measured +4 % at 10 % jitter and
// +16 % at 20 %. Bounds stated from the table; the last refinement must have settled.
TEST(CylinderTest, JitteredGridsSettleWithinTheirMeshQualityBias) {
  for (const Row& r : Table()) {
    const double bound = r.family == "jittered 10%" ? 0.06 : r.family == "jittered 20%" ? 0.19 : -1;
    if (bound < 0) continue;
    EXPECT_LE(std::abs(r.ratio.back() - 1.0), bound) << r.family << " " << r.law;
    EXPECT_LE(std::abs(r.ratio[kNumLevels - 1] - r.ratio[kNumLevels - 2]), 0.03)
        << r.family << " " << r.law;
  }
}

}  // namespace
}  // namespace textile
