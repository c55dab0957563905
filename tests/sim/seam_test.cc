#include "textile/sim/law/seam.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/law/material.h"

namespace textile {
namespace {

const std::string kSamples = std::string(TEXTILE_SOURCE_DIR) + "/samples/seams/";
const std::string kBad = std::string(TEXTILE_SOURCE_DIR) + "/tests/data/seams/";

// Table 2 typed in again (not taken from the library), with B_f(100 mm) worked out by hand.
struct Table2Row {
  const char* type;
  int layers;
  double a2, a1, a0;
  double at_100mm;
};
constexpr Table2Row kTable2[] = {
    {"A-plain", 2, 5.0e-5, -0.0211, 3.46, 1.85}, {"A-twill", 2, 2.0e-5, -0.0127, 2.64, 1.57},
    {"B-plain", 3, 4.0e-5, -0.0322, 5.92, 3.10}, {"B-twill", 3, 4.0e-5, -0.0287, 4.37, 1.90},
    {"C-plain", 4, 2.0e-4, -0.0702, 9.07, 4.05}, {"C-twill", 4, 1.0e-4, -0.0524, 6.86, 2.62},
};

// Evaluating a quadratic with O(1) terms: a few ulps.
constexpr double kPolynomialTolerance = 1e-12;

SeamLine Line(std::initializer_list<std::array<double, 2>> points) {
  SeamLine line(static_cast<Eigen::Index>(points.size()), 2);
  Eigen::Index k = 0;
  for (const auto& p : points) line.row(k++) << p[0], p[1];
  return line;
}

Seam MakeSeam(const std::string& type, std::initializer_list<std::array<double, 2>> points) {
  return Seam{SeamPreset(type), Line(points)};
}

// A regular grid with interior vertices moved by up to 0.15 of a cell (boundary kept, so the
// pattern and its area are unchanged; triangles stay well shaped).
TriangleMesh PerturbedGridMesh(double width, double height, int nx, int ny, unsigned seed) {
  TriangleMesh m = RegularGridMesh(width, height, nx, ny);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (int j = 1; j < ny; ++j) {
    for (int i = 1; i < nx; ++i) {
      const int v = j * (nx + 1) + i;
      m.vertices(v, 0) += u(rng) * width / nx;
      m.vertices(v, 1) += u(rng) * height / ny;
    }
  }
  return m;
}

std::vector<TriangleMesh> MeshFamily(double width, double height) {
  std::vector<TriangleMesh> meshes;
  for (int n : {3, 7, 16, 41}) {
    const int ny = std::max(2, static_cast<int>(std::lround(n * height / width)));
    meshes.push_back(RegularGridMesh(width, height, n, ny));
    meshes.push_back(CrissCrossGridMesh(width, height, n, ny));
    meshes.push_back(PerturbedGridMesh(width, height, n, ny, 17u + n));
  }
  return meshes;
}

// --- Profiles ---------------------------------------------------------------------------------

TEST(SeamPreset, ReproducesTable2) {
  ASSERT_EQ(SeamPresetNames().size(), 6u);
  for (const Table2Row& row : kTable2) {
    SCOPED_TRACE(row.type);
    const SeamProfile p = SeamPreset(row.type);
    EXPECT_EQ(p.type, row.type);
    EXPECT_EQ(p.layers, row.layers);
    EXPECT_EQ(p.coefficients_mm[0], row.a2);  // the same decimal literals: exact
    EXPECT_EQ(p.coefficients_mm[1], row.a1);
    EXPECT_EQ(p.coefficients_mm[2], row.a0);
    EXPECT_EQ(p.StiffnessFactor(0.0), row.a0);
    EXPECT_NEAR(p.StiffnessFactor(50.0), row.a2 * 2500.0 + row.a1 * 50.0 + row.a0,
                kPolynomialTolerance);
    EXPECT_NEAR(p.StiffnessFactor(100.0), row.at_100mm, kPolynomialTolerance);
    EXPECT_EQ(p.influence_mm, 100.0);
    EXPECT_EQ(p.fade_mm, 20.0);
    EXPECT_EQ(p.allowance_mm, 10.0);
    EXPECT_EQ(p.multiplier, SeamMultiplierReading::kFactor);
    std::string why;
    EXPECT_TRUE(p.Check(&why)) << why;
  }
}

TEST(SeamPreset, SampleFilesMatchPresets) {
  for (const std::string& type : SeamPresetNames()) {
    SCOPED_TRACE(type);
    const SeamProfile file = ReadSeamProfile(kSamples + type + ".json");
    const SeamProfile preset = SeamPreset(type);
    EXPECT_EQ(file.type, preset.type);
    EXPECT_EQ(file.name, preset.name);
    EXPECT_EQ(file.layers, preset.layers);
    EXPECT_EQ(file.coefficients_mm, preset.coefficients_mm);
    EXPECT_EQ(file.range_mm, preset.range_mm);
    EXPECT_EQ(file.influence_mm, preset.influence_mm);
    EXPECT_EQ(file.fade_mm, preset.fade_mm);
    EXPECT_EQ(file.allowance_mm, preset.allowance_mm);
    EXPECT_EQ(file.multiplier, preset.multiplier);
    EXPECT_EQ(file.extra["source"], preset.extra["source"]);
  }
}

TEST(SeamPreset, UnknownNameIsInputError) {
  try {
    SeamPreset("D-plain");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'D-plain': unknown"), std::string::npos) << e.what();
  }
}

// --- The multiplier S(d) ---------------------------------------------------------------------

// A fit that ends barely above 1 with a steep slope: a cubic Hermite fade towards 1 would dip
// below 1 here (3 (S - 1) + fade S' = 0.03 - 1 < 0).
SeamProfile SteepFit() {
  SeamProfile steep;
  steep.layers = 2;
  steep.coefficients_mm = {0.0, -0.05, 6.01};  // B_f(100) = 1.01, slope -0.05 per mm
  return steep;
}

// Every preset under both readings, with the default lengths and with short ones.
std::vector<SeamProfile> ProfileVariants() {
  std::vector<SeamProfile> out{SteepFit()};
  for (const std::string& type : SeamPresetNames()) {
    for (auto reading : {SeamMultiplierReading::kFactor, SeamMultiplierReading::kPaperLiteral}) {
      for (auto [influence, fade] : {std::pair{100.0, 20.0}, std::pair{60.0, 5.0}}) {
        SeamProfile p = SeamPreset(type);
        p.multiplier = reading;
        p.influence_mm = influence;
        p.fade_mm = fade;
        out.push_back(p);
      }
    }
  }
  return out;
}

std::string Describe(const SeamProfile& p) {
  return p.type + (p.multiplier == SeamMultiplierReading::kFactor ? " factor" : " paper-literal") +
         " d_max " + std::to_string(p.influence_mm) + " fade " + std::to_string(p.fade_mm);
}

TEST(SeamMultiplier, IsC1AtInfluenceAndFadeEnds) {
  // One-sided second-order differences with h = 1e-3 mm: truncation h² |S'''| / 3 stays below
  // 1e-5 per mm for these profiles (|S'''| ≤ 6 · 65 / 5³ for the Hermite with the shortest
  // fade, ≤ 0.01 · 98³ / 20³ for the steep fit's exponential), rounding is ~1e-11. A kink
  // would change the slope by |dc/dd(d_max)| ≥ 0.01 per mm.
  constexpr double kH = 1e-3;               // [mm]
  constexpr double kSlopeTolerance = 1e-5;  // [1/mm]
  for (const SeamProfile& p : ProfileVariants()) {
    SCOPED_TRACE(Describe(p));
    const auto left = [&](double d) {
      return (3 * p.Multiplier(d) - 4 * p.Multiplier(d - kH) + p.Multiplier(d - 2 * kH)) / (2 * kH);
    };
    const auto right = [&](double d) {
      return (-3 * p.Multiplier(d) + 4 * p.Multiplier(d + kH) - p.Multiplier(d + 2 * kH)) /
             (2 * kH);
    };
    const double d_max = p.influence_mm, d_end = p.influence_mm + p.fade_mm;
    // The slope the polynomial has at d_max, continued into the fade.
    const double a2 = p.coefficients_mm[0], a1 = p.coefficients_mm[1], a0 = p.coefficients_mm[2];
    double slope = 2 * a2 * d_max + a1;
    if (p.multiplier == SeamMultiplierReading::kPaperLiteral) slope *= a0 - 1.0;
    EXPECT_NEAR(left(d_max), slope, kSlopeTolerance);
    EXPECT_NEAR(right(d_max), slope, kSlopeTolerance);
    EXPECT_NEAR(left(d_end), 0.0, kSlopeTolerance);
    EXPECT_NEAR(right(d_end), 0.0, kSlopeTolerance);
    // Continuity: the values on both sides agree to the slope times the step.
    EXPECT_NEAR(p.Multiplier(d_max + 1e-9), p.Multiplier(d_max), 1e-9);
    EXPECT_NEAR(p.Multiplier(d_end - 1e-9), 1.0, 1e-12);
  }
}

TEST(SeamMultiplier, IsOneFarAwayAndAtLeastOneEverywhere) {
  std::vector<SeamProfile> profiles = ProfileVariants();
  // And a fit that crosses 1 before d_max (S = 1 from there on).
  const SeamProfile steep = SteepFit();
  SeamProfile crossing;
  crossing.layers = 2;
  crossing.coefficients_mm = {0.0, -0.025, 3.0};  // B_f = 1 at 80 mm
  profiles.push_back(crossing);
  for (const SeamProfile& p : profiles) {
    SCOPED_TRACE(Describe(p));
    std::string why;
    ASSERT_TRUE(p.Check(&why)) << why;
    const double d_end = p.influence_mm + p.fade_mm;
    for (double d = 0.0; d <= 400.0; d += 0.01) {
      const double s = p.Multiplier(d);
      ASSERT_GE(s, 1.0) << "d = " << d;
      if (d >= d_end) {
        ASSERT_EQ(s, 1.0) << "d = " << d;
      }
    }
  }
  EXPECT_EQ(crossing.Multiplier(85.0), 1.0);
  EXPECT_GT(crossing.Multiplier(75.0), 1.0);
  EXPECT_GT(steep.Multiplier(101.0), 1.0);
  EXPECT_LT(steep.Multiplier(101.0), steep.Multiplier(100.0));
}

TEST(SeamMultiplier, FollowsMaxOfOneAndFactorInsideInfluence) {
  for (const std::string& type : SeamPresetNames()) {
    const SeamProfile p = SeamPreset(type);
    for (double d = 0.0; d <= p.influence_mm; d += 0.5) {
      EXPECT_EQ(p.Multiplier(d), std::max(1.0, p.StiffnessFactor(d))) << type << " d = " << d;
    }
  }
}

TEST(SeamMultiplier, PaperLiteralVersusFactorAtSeamLine) {
  for (const Table2Row& row : kTable2) {
    SeamProfile p = SeamPreset(row.type);
    EXPECT_EQ(p.Multiplier(0.0), row.a0) << row.type;
    p.multiplier = SeamMultiplierReading::kPaperLiteral;
    // 1 + B_f(0)(B_f(0) - 1): the measured factor squared, roughly.
    EXPECT_NEAR(p.Multiplier(0.0), 1.0 + row.a0 * (row.a0 - 1.0), kPolynomialTolerance) << row.type;
  }
  SeamProfile c = SeamPreset("C-plain");
  c.multiplier = SeamMultiplierReading::kPaperLiteral;
  EXPECT_NEAR(c.Multiplier(0.0), 74.1949, kPolynomialTolerance * 100);  // vs 9.07 measured
  EXPECT_NEAR(c.Multiplier(100.0), 1.0 + 4.05 * 8.07, kPolynomialTolerance * 100);
}

TEST(SeamAreaFactor, IsCeilOfFactorNearAndOneFar) {
  SeamProfile c = SeamPreset("C-plain");
  c.multiplier = SeamMultiplierReading::kPaperLiteral;  // refinement follows B_f under any reading
  const auto factor = SeamAreaFactor({c});
  EXPECT_EQ(factor(0.0), 10.0);   // ⌈9.07⌉
  EXPECT_EQ(factor(0.010), 9.0);  // ⌈8.388⌉
  EXPECT_EQ(factor(0.050), 7.0);  // ⌈6.06⌉
  EXPECT_EQ(factor(0.110), 3.0);  // mid-fade: 1 + (1/4)(3.05 + (6.1 - 0.604)/2) = 2.45
  EXPECT_EQ(factor(0.120), 1.0);
  EXPECT_EQ(factor(1.0), 1.0);
  const auto two = SeamAreaFactor({SeamPreset("A-twill"), SeamPreset("C-plain")});
  EXPECT_EQ(two(0.0), 10.0);
  EXPECT_EQ(SeamAreaFactor({})(0.0), 1.0);
  for (double d = 0.0; d < 0.3; d += 1e-4) ASSERT_GE(factor(d), 1.0);
}

// --- Geometry ---------------------------------------------------------------------------------

TEST(SeamGeometry, DistancesAreExactForSimpleGeometries) {
  constexpr double kTol = 1e-15;  // a few ulps of O(1) lengths
  const SeamLine segment = Line({{0.0, 0.0}, {1.0, 0.0}});
  EXPECT_NEAR(DistanceToSeamLine({0.3, 0.4}, segment), 0.4, kTol);   // interior
  EXPECT_NEAR(DistanceToSeamLine({-0.3, 0.4}, segment), 0.5, kTol);  // beyond the start
  EXPECT_NEAR(DistanceToSeamLine({1.3, -0.4}, segment), 0.5, kTol);  // beyond the end
  EXPECT_EQ(DistanceToSeamLine({0.25, 0.0}, segment), 0.0);          // on it
  const SeamLine ell = Line({{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}});
  EXPECT_NEAR(DistanceToSeamLine({0.5, 0.5}, ell), 0.5, kTol);   // equidistant
  EXPECT_NEAR(DistanceToSeamLine({2.0, 0.5}, ell), 1.0, kTol);   // second segment
  EXPECT_NEAR(DistanceToSeamLine({1.3, -0.4}, ell), 0.5, kTol);  // the corner
  EXPECT_NEAR(DistanceToSeamLine({0.9, 0.05}, ell), 0.05, kTol);
  const SeamLine diagonal = Line({{0.0, 0.0}, {1.0, 1.0}});
  EXPECT_NEAR(DistanceToSeamLine({1.0, 0.0}, diagonal), std::sqrt(0.5), kTol);
}

// The L-shaped pattern [0, 0.2]² without the quadrant x > 0.1, y > 0.1.
TriangleMesh LShapedMesh() {
  const TriangleMesh square = RegularGridMesh(0.2, 0.2, 4, 4);
  std::vector<int> keep;
  for (int f = 0; f < square.num_triangles(); ++f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += square.vertices.row(square.triangles(f, k)).transpose() / 3.0;
    if (!(c.x() > 0.1 && c.y() > 0.1)) keep.push_back(f);
  }
  std::vector<int> new_id(square.num_vertices(), -1);
  TriangleMesh m;
  m.triangles.resize(static_cast<Eigen::Index>(keep.size()), 3);
  std::vector<int> old_of_new;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      int& id = new_id[square.triangles(keep[i], k)];
      if (id < 0)
        id = static_cast<int>(old_of_new.size()),
        old_of_new.push_back(square.triangles(keep[i], k));
      m.triangles(static_cast<Eigen::Index>(i), k) = id;
    }
  }
  m.vertices.resize(static_cast<Eigen::Index>(old_of_new.size()), 3);
  for (std::size_t i = 0; i < old_of_new.size(); ++i)
    m.vertices.row(static_cast<Eigen::Index>(i)) = square.vertices.row(old_of_new[i]);
  return m;
}

void ExpectSeamRejected(const std::vector<Seam>& seams, const TriangleMesh& mesh,
                        const std::string& fragment) {
  try {
    CheckSeams(seams, mesh);
    FAIL() << "accepted; expected: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(SeamGeometry, RejectsBadLinesNamingSeamAndPoint) {
  const TriangleMesh square = RegularGridMesh(0.2, 0.2, 4, 4);
  EXPECT_NO_THROW(CheckSeams({MakeSeam("A-plain", {{0.1, 0.0}, {0.1, 0.2}})}, square));
  EXPECT_NO_THROW(
      CheckSeams({MakeSeam("A-plain", {{0.0, 0.0}, {0.2, 0.0}})}, square));  // on the edge
  ExpectSeamRejected({MakeSeam("A-plain", {{0.1, 0.0}})}, square,
                     "seam 0 (A-plain): line: needs at least 2 points");
  ExpectSeamRejected({MakeSeam("A-plain", {{0.1, 0.0}, {0.1, std::nan("")}})}, square,
                     "line: point 1 has a NaN");
  ExpectSeamRejected({MakeSeam("A-plain", {{0.1, 0.0}, {0.1, 0.1}}),
                      MakeSeam("B-plain", {{0.1, 0.0}, {0.1, 0.0}, {0.1, 0.2}})},
                     square, "seam 1 (B-plain): line: segment 0 (points 0, 1) has zero length");
  ExpectSeamRejected({MakeSeam("A-plain", {{0.1, 0.0}, {0.1, 0.25}})}, square,
                     "line: point 1 (0.1, 0.25) m lies outside the pattern");
  Seam broken = MakeSeam("A-plain", {{0.1, 0.0}, {0.1, 0.2}});
  broken.profile.layers = 0;
  ExpectSeamRejected({broken}, square, "seam 0 (A-plain): layers: must be >= 1");
  // A concave pattern: inside the bounding box is not inside the pattern.
  const TriangleMesh ell = LShapedMesh();
  ASSERT_NO_THROW(CheckMesh(ell));
  ExpectSeamRejected({MakeSeam("A-plain", {{0.05, 0.05}, {0.15, 0.15}})}, ell,
                     "point 1 (0.15, 0.15) m lies outside the pattern");
  ExpectSeamRejected({MakeSeam("A-plain", {{0.05, 0.19}, {0.19, 0.05}})}, ell,
                     "seam 0 (A-plain): line: segment 0 leaves the pattern");
  // Touching the re-entrant corner (0.1, 0.1) and running along the boundary stay inside.
  EXPECT_NO_THROW(CheckSeams({MakeSeam("A-plain", {{0.05, 0.15}, {0.15, 0.05}})}, ell));
  EXPECT_NO_THROW(CheckSeams({MakeSeam("A-plain", {{0.0, 0.1}, {0.2, 0.1}})}, ell));
  EXPECT_NO_THROW(CheckSeams({MakeSeam("A-plain", {{0.1, 0.2}, {0.1, 0.1}, {0.2, 0.1}})}, ell));
}

TEST(SeamHinges, GridWithSeamAlongXConstPicksUpTheSeam) {
  const TriangleMesh mesh = RegularGridMesh(0.4, 0.2, 40, 20);  // 10 mm cells
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  const Seam seam = MakeSeam("C-plain", {{0.2, 0.0}, {0.2, 0.2}});
  const std::vector<double> s = HingeSeamMultipliers(mesh, hinges, {seam});
  const std::vector<double> d = HingeSeamDistances(mesh, hinges, seam.line);
  ASSERT_EQ(s.size(), hinges.size());
  ASSERT_EQ(d.size(), hinges.size());
  const auto midpoint = [&](std::size_t h) -> Eigen::Vector2d {
    return 0.5 * (mesh.vertices.row(hinges[h].v[2]) + mesh.vertices.row(hinges[h].v[3]))
                     .head<2>()
                     .transpose();
  };
  int on_line = 0, stiffened = 0, expected_stiffened = 0;
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    // The seam spans the full height, so the distance is |x_mid - 0.2| (computed here anew).
    const double d_mm = 1e3 * std::abs(midpoint(h).x() - 0.2);
    EXPECT_NEAR(1e3 * d[h], d_mm, 1e-9);
    EXPECT_NEAR(s[h], seam.profile.Multiplier(d_mm), kPolynomialTolerance * 10);
    if (d_mm < 1e-9) {
      ++on_line;
      EXPECT_NEAR(s[h], 9.07, kPolynomialTolerance * 10);
    }
    if (d_mm >= 120.0) {
      EXPECT_EQ(s[h], 1.0);
    }
    stiffened += s[h] > 1.0;
    expected_stiffened += d_mm < 120.0 - 1e-9;  // closer than d_max + fade
  }
  EXPECT_EQ(on_line, 20);  // the vertical edges on x = 0.2, all interior
  EXPECT_EQ(stiffened, expected_stiffened);
  EXPECT_GT(stiffened, static_cast<int>(hinges.size()) / 3);
  // A second, softer seam across: the crossing keeps the stiffer seam's multiplier (max).
  const Seam across = MakeSeam("A-plain", {{0.0, 0.1}, {0.4, 0.1}});
  const std::vector<double> both = HingeSeamMultipliers(mesh, hinges, {seam, across});
  const std::vector<double> d_across = HingeSeamDistances(mesh, hinges, across.line);
  int far_on_across = 0;
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    EXPECT_EQ(both[h], std::max(s[h], across.profile.Multiplier(1e3 * d_across[h])));
    // The edge (0.34, 0.1)-(0.35, 0.1): on the A seam, 145 mm from the C seam: A's factor.
    if ((midpoint(h) - Eigen::Vector2d(0.345, 0.1)).norm() < 1e-9) {
      ++far_on_across;
      EXPECT_NEAR(both[h], 3.46, kPolynomialTolerance * 10);
    }
  }
  EXPECT_EQ(far_on_across, 1);
}

TEST(SeamHinges, RibFactorStiffensTheBandAgainstBendingTheSeamLine) {
  // 10 mm cells cut along one diagonal; a C-plain seam up x = 0.2 with a 12 mm band: the edges
  // across it (horizontal, midpoints 5 mm off) bend the seam line fully, the diagonals beside it
  // (midpoints 5 mm off, φ = 45°) half, the edges on it (φ = 0) not at all.
  const TriangleMesh mesh = RegularGridMesh(0.4, 0.2, 40, 20);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  Seam seam = MakeSeam("C-plain", {{0.2, 0.0}, {0.2, 0.2}});
  seam.profile.allowance_mm = 12.0;
  const std::vector<double> plain = HingeSeamMultipliers(mesh, hinges, {seam});
  seam.profile.rib_factor = 10.0;
  const std::vector<double> rib = HingeSeamMultipliers(mesh, hinges, {seam});
  int across = 0, diagonal = 0, along = 0, outside = 0;
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const Eigen::Vector2d a = mesh.vertices.row(hinges[h].v[2]).head<2>().transpose();
    const Eigen::Vector2d b = mesh.vertices.row(hinges[h].v[3]).head<2>().transpose();
    const double d = std::abs(0.5 * (a.x() + b.x()) - 0.2);
    const bool horizontal = std::abs(a.y() - b.y()) < 1e-12;
    const bool vertical = std::abs(a.x() - b.x()) < 1e-12;
    if (d > 0.006) {
      EXPECT_EQ(rib[h], plain[h]) << "hinge " << h;
      ++outside;
    } else if (horizontal) {
      EXPECT_NEAR(rib[h], 10.0 * plain[h], 1e-12) << "hinge " << h;
      ++across;
    } else if (vertical) {
      EXPECT_NEAR(rib[h], plain[h], 1e-12) << "hinge " << h;
      EXPECT_NEAR(plain[h], 9.07, 1e-12);  // on the line
      ++along;
    } else {
      EXPECT_NEAR(rib[h], 5.5 * plain[h], 1e-12) << "hinge " << h;
      ++diagonal;
    }
  }
  EXPECT_EQ(across, 2 * 19);  // interior horizontal edges on either side, 19 rows
  EXPECT_EQ(diagonal, 2 * 20);
  EXPECT_EQ(along, 20);
  EXPECT_GT(outside, 1000);

  // A bent seam: each hinge takes the direction of the segment nearest to it. The edge
  // (0.1, 0.05)-(0.11, 0.05) crosses the vertical leg, the edge (0.2, 0.1)-(0.2, 0.11) the
  // horizontal one: both are bent the full way; the edge (0.2, 0.1)-(0.21, 0.1) lies on the
  // horizontal leg, along it: not at all.
  Seam bent = MakeSeam("C-plain", {{0.1, 0.0}, {0.1, 0.1}, {0.3, 0.1}});
  bent.profile.allowance_mm = 12.0;
  bent.profile.rib_factor = 10.0;
  const std::vector<double> bent_plain = [&] {
    Seam b = bent;
    b.profile.rib_factor = 1.0;
    return HingeSeamMultipliers(mesh, hinges, {b});
  }();
  const std::vector<double> bent_rib = HingeSeamMultipliers(mesh, hinges, {bent});
  int checked = 0;
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const Eigen::Vector2d a = mesh.vertices.row(hinges[h].v[2]).head<2>().transpose();
    const Eigen::Vector2d b = mesh.vertices.row(hinges[h].v[3]).head<2>().transpose();
    const auto is = [&](double x0, double y0, double x1, double y1) {
      const Eigen::Vector2d p(x0, y0), q(x1, y1);
      return ((a - p).norm() < 1e-12 && (b - q).norm() < 1e-12) ||
             ((a - q).norm() < 1e-12 && (b - p).norm() < 1e-12);
    };
    if (is(0.1, 0.05, 0.11, 0.05) || is(0.2, 0.1, 0.2, 0.11)) {
      EXPECT_NEAR(bent_rib[h], 10.0 * bent_plain[h], 1e-12) << "hinge " << h;
      ++checked;
    }
    if (is(0.2, 0.1, 0.21, 0.1)) {  // on the horizontal leg, along it
      EXPECT_EQ(bent_rib[h], bent_plain[h]);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3);
}

TEST(SeamHinges, NoSeamsGiveOnes) {
  const TriangleMesh mesh = CrissCrossGridMesh(0.1, 0.1, 3, 3);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  EXPECT_EQ(HingeSeamMultipliers(mesh, hinges, {}), std::vector<double>(hinges.size(), 1.0));
}

// --- Mass -------------------------------------------------------------------------------------

constexpr double kRho = 0.2;  // areal density [kg/m²] (200 g/m²)
// Straight band edges are clipped exactly, as polygons; what is left is round-off summed over
// up to 1e5 triangles (measured ≤ 5e-14).
constexpr double kStraightBandRelTolerance = 1e-12;
// Round caps are linearised on pieces of h = allowance/256: the distance to a point is
// overestimated by ~h²/(8 r), which loses ~π h²/8 of area along a cap, ~1e-7 of these bands
// (measured ≤ 2e-7 on all meshes, up to 40000 triangles).
constexpr double kCurvedBandRelTolerance = 1e-6;

struct MassCase {
  const char* what;
  double width, height;  // pattern [m]
  Seam seam;
  double band_area;  // exact band area inside the pattern [m²]
  double tolerance;  // relative
};

std::vector<MassCase> MassCases() {
  const double r = 0.005;  // half the default 10 mm allowance [m]
  const double pi = std::numbers::pi;
  std::vector<MassCase> cases;
  cases.push_back({"straight seam x = 0.0731 across", 0.3, 0.2,
                   MakeSeam("C-plain", {{0.0731, 0.0}, {0.0731, 0.2}}), 2 * r * 0.2,
                   kStraightBandRelTolerance});
  // Corner to corner: every pattern point projects inside the segment, so the band is the
  // square minus two corner triangles with legs s - r√2.
  const double s = 0.2, leg = s - r * std::sqrt(2.0);
  cases.push_back({"diagonal corner to corner", s, s, MakeSeam("B-twill", {{0.0, 0.0}, {s, s}}),
                   s * s - leg * leg, kStraightBandRelTolerance});
  cases.push_back({"interior seam with round caps", 0.3, 0.2,
                   MakeSeam("A-plain", {{0.05, 0.0873}, {0.25, 0.0873}}), 2 * r * 0.2 + pi * r * r,
                   kCurvedBandRelTolerance});
  // A right-angle bend: the outer side gains a quarter disk, the inner side's strips overlap in
  // an r × r square: 2 r L + π r² + r² (π/4 - 1).
  cases.push_back({"bent interior seam", 0.3, 0.2,
                   MakeSeam("C-twill", {{0.05, 0.0537}, {0.2013, 0.0537}, {0.2013, 0.15}}),
                   2 * r * (0.1513 + 0.0963) + pi * r * r + r * r * (pi / 4 - 1),
                   kCurvedBandRelTolerance});
  return cases;
}

TEST(SeamMass, TotalIsFabricPlusBandOnEveryMesh) {
  for (const MassCase& c : MassCases()) {
    const double expected =
        kRho * c.width * c.height + (c.seam.profile.layers - 1) * kRho * c.band_area;
    for (const TriangleMesh& mesh : MeshFamily(c.width, c.height)) {
      SCOPED_TRACE(std::string(c.what) + ", " + std::to_string(mesh.num_triangles()) +
                   " triangles");
      ASSERT_NO_THROW(CheckMesh(mesh));
      const Eigen::VectorXd band = SeamBandAreas(mesh, c.seam);
      EXPECT_NEAR(band.sum(), c.band_area, c.tolerance * c.band_area);
      const Eigen::VectorXd areas = TriangleAreas(mesh);
      for (int f = 0; f < mesh.num_triangles(); ++f) {
        ASSERT_GE(band(f), 0.0);
        ASSERT_LE(band(f), areas(f) * (1 + 1e-12));
      }
      const Eigen::VectorXd m = LumpedMasses(mesh, kRho, {c.seam});
      EXPECT_NEAR(m.sum(), expected, c.tolerance * expected);
      EXPECT_GT(m.minCoeff(), 0.0);
    }
  }
}

TEST(SeamMass, ExtraMassSitsOnTheSeam) {
  const double x0 = 0.0731, r = 0.005;
  const Seam seam = MakeSeam("C-plain", {{x0, 0.0}, {x0, 0.2}});
  for (const TriangleMesh& mesh : MeshFamily(0.3, 0.2)) {
    SCOPED_TRACE(std::to_string(mesh.num_triangles()) + " triangles");
    const Eigen::VectorXd plain = LumpedMasses(mesh, kRho, {});
    const Eigen::VectorXd extra = LumpedMasses(mesh, kRho, {seam}) - plain;
    double longest_edge = 0.0;
    for (int f = 0; f < mesh.num_triangles(); ++f) {
      for (int k = 0; k < 3; ++k) {
        longest_edge = std::max(longest_edge, (mesh.vertices.row(mesh.triangles(f, k)) -
                                               mesh.vertices.row(mesh.triangles(f, (k + 1) % 3)))
                                                  .norm());
      }
    }
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      ASSERT_GE(extra(v), -1e-15);
      const double d = std::abs(mesh.vertices(v, 0) - x0);
      // Only vertices of triangles that meet the band carry extra mass.
      if (d > r + longest_edge) {
        EXPECT_EQ(extra(v), 0.0) << "vertex " << v;
      }
      centre += extra(v) * mesh.vertices.row(v).head<2>().transpose();
    }
    centre /= extra.sum();
    // Linear-shape-function lumping keeps the first moment: the extra mass is centred on the
    // seam line at mid-height (round-off only).
    EXPECT_NEAR(centre.x(), x0, 1e-12);
    EXPECT_NEAR(centre.y(), 0.1, 1e-12);
    EXPECT_NEAR(extra.sum(), 3 * kRho * 2 * r * 0.2, kStraightBandRelTolerance * extra.sum());
  }
}

TEST(SeamMass, ZeroAllowanceOrSingleLayerAddsNothing) {
  const TriangleMesh mesh = RegularGridMesh(0.2, 0.2, 8, 8);
  Seam seam = MakeSeam("C-plain", {{0.1, 0.0}, {0.1, 0.2}});
  seam.profile.allowance_mm = 0.0;
  EXPECT_EQ(LumpedMasses(mesh, kRho, {seam}), LumpedMasses(mesh, kRho, {}));
  seam = Seam{SeamProfile{}, seam.line};  // "fitted", 2 layers by default
  seam.profile.layers = 1;
  EXPECT_EQ(LumpedMasses(mesh, kRho, {seam}), LumpedMasses(mesh, kRho, {}));
  EXPECT_NEAR(LumpedMasses(mesh, kRho, {}).sum(), kRho * 0.04, 1e-15);
}

TEST(SeamMass, RejectsBadDensity) {
  const TriangleMesh mesh = RegularGridMesh(0.2, 0.2, 2, 2);
  EXPECT_THROW(LumpedMasses(mesh, 0.0, {}), InputError);
  EXPECT_THROW(LumpedMasses(mesh, std::nan(""), {}), InputError);
}

// --- Files ------------------------------------------------------------------------------------

TEST(SeamFile, DefaultsWhenSettingsOmitted) {
  const SeamProfile p = ParseSeamJson(
      R"({"type": "fitted", "layers": 3, "coefficients_mm": [4e-05, -0.0322, 5.92]})", "minimal");
  EXPECT_EQ(p.influence_mm, 100.0);
  EXPECT_EQ(p.fade_mm, 20.0);
  EXPECT_EQ(p.allowance_mm, 10.0);
  EXPECT_EQ(p.multiplier, SeamMultiplierReading::kFactor);
  EXPECT_EQ(p.rib_factor, 1.0);
  EXPECT_EQ(p.range_mm, (std::array<double, 2>{0.0, 100.0}));
  EXPECT_FALSE(p.covariance.has_value());
}

TEST(JsonText, RefusesDuplicateKeysNamingTheKeyAndItsObject) {
  // nlohmann keeps the last of two equal keys; a material or seam file that repeats one is an
  // editing mistake that would silently win.
  const auto message = [](const std::string& text) {
    try {
      ParseJsonText(text, "f.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(R"({"a": 1, "a": 2})"),
            "f.json: duplicate key \"a\" at the top level (a JSON parser would silently keep "
            "the last one)");
  EXPECT_EQ(message(R"({"a": {"b": [{"c": 1, "c": 1}]}})").substr(0, 36),
            "f.json: duplicate key \"c\" in \"a.b\" (");
  // Equal keys in different objects, or in sibling objects of an array, are fine.
  EXPECT_NO_THROW(
      ParseJsonText(R"({"a": {"x": 1}, "b": {"x": 1}, "l": [{"x": 1}, {"x": 2}]})", "f"));
  EXPECT_EQ(message(R"({"a": 1)").substr(0, 22), "f.json: not valid JSON");
  const std::string material =
      std::string(TEXTILE_SOURCE_DIR) + "/tests/data/materials/duplicate-key.json";
  try {
    ReadMaterial(material);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(material + ": duplicate key \"b1\" in \"bending\""),
              std::string::npos)
        << e.what();
  }
}

TEST(SeamFile, JsonRoundTrip) {
  const SeamProfile a = ParseSeamJson(R"({
      "type": "fitted", "name": "denim, ISO 2.04.05", "layers": 4,
      "coefficients_mm": [1.5e-4, -0.06, 7.5], "range_mm": [2.5, 95],
      "covariance": [[1e-10, -2e-9, 1e-8], [-2e-9, 1e-6, -3e-6], [1e-8, -3e-6, 2e-3]],
      "influence_mm": 90, "fade_mm": 15, "allowance_mm": 12, "multiplier": "paper-literal",
      "rib_factor": 7.5, "fit": {"rms": 0.08, "points": 17}, "notes": "measured 2024"})",
                                      "round trip");
  const SeamProfile b = ParseSeamJson(SeamProfileToJson(a).dump(), "written");
  EXPECT_EQ(b.type, a.type);
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.layers, a.layers);
  EXPECT_EQ(b.coefficients_mm, a.coefficients_mm);
  EXPECT_EQ(b.range_mm, a.range_mm);
  ASSERT_TRUE(b.covariance.has_value());
  EXPECT_EQ(*b.covariance, *a.covariance);
  EXPECT_EQ(b.influence_mm, 90.0);
  EXPECT_EQ(b.fade_mm, 15.0);
  EXPECT_EQ(b.allowance_mm, 12.0);
  EXPECT_EQ(b.multiplier, SeamMultiplierReading::kPaperLiteral);
  EXPECT_EQ(b.rib_factor, 7.5);
  EXPECT_EQ(b.fit, a.fit);
  EXPECT_EQ(b.extra, a.extra);
  for (const std::string& type : SeamPresetNames()) {
    const SeamProfile p = ParseSeamJson(SeamProfileToJson(SeamPreset(type)).dump(), type);
    EXPECT_EQ(p.coefficients_mm, SeamPreset(type).coefficients_mm);
  }
}

TEST(SeamFile, CheckCatchesWhatJsonCannotSay) {
  SeamProfile p = SeamPreset("A-plain");
  p.type = "fitted";
  p.coefficients_mm[1] = std::nan("");
  std::string why;
  EXPECT_FALSE(p.Check(&why));
  EXPECT_EQ(why, "coefficients_mm: a1 must be finite, got nan");
  p = SeamPreset("A-plain");
  p.fade_mm = std::nan("");
  EXPECT_FALSE(p.Check(&why));
  EXPECT_NE(why.find("fade_mm"), std::string::npos) << why;
  p = SeamPreset("C-plain");
  p.rib_factor = 0.5;  // a rib softer than the band's own S is not a seam
  EXPECT_FALSE(p.Check(&why));
  EXPECT_EQ(why, "rib_factor: must lie in [1, 1000], got 0.5");
  p.rib_factor = std::nan("");
  EXPECT_FALSE(p.Check(&why));
  EXPECT_EQ(why, "rib_factor: must lie in [1, 1000], got nan");
  p.rib_factor = 1000.0;
  EXPECT_TRUE(p.Check(&why)) << why;
}

struct BadCase {
  const char* file;
  const char* field;    // must appear in the message
  const char* problem;  // must appear in the message
};

class BadSeamFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadSeamFile, IsRejectedWithFileFieldAndProblem) {
  const BadCase& c = GetParam();
  const std::string path = kBad + c.file;
  try {
    ReadSeamProfile(path);
    FAIL() << c.file << " was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(c.field), std::string::npos) << what;
    EXPECT_NE(what.find(c.problem), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    SeamFile, BadSeamFile,
    ::testing::Values(
        BadCase{"empty.json", "", "empty seam file"},
        BadCase{"not-json.json", "", "not valid JSON"},
        BadCase{"array.json", "(top level)", "must be a JSON object"},
        BadCase{"missing-type.json", "type: ", "missing"},
        BadCase{"missing-layers.json", "layers: ", "missing"},
        BadCase{"missing-coefficients.json", "coefficients_mm: ", "missing"},
        BadCase{"nan.json", "", "not valid JSON"},  // JSON has no NaN; Check() covers it in code
        BadCase{"inf.json", "", "number overflow parsing '1e999'"},
        BadCase{"type-not-string.json", "type: ", "must be a string"},
        BadCase{"type-unknown.json", "type: ", "unknown seam type 'D-plain'"},
        BadCase{"layers-negative.json", "layers: ", "must be >= 1, got -2"},
        BadCase{"layers-fraction.json", "layers: ", "must be a whole number"},
        BadCase{"layers-absurd.json", "layers: ", "suspicious count 400"},
        BadCase{"layers-preset-mismatch.json", "layers: ", "C-plain has 4 layers, got 3"},
        BadCase{"coefficients-preset-mismatch.json",
                "coefficients_mm: ", "differ from Table 2's C-plain"},
        BadCase{"coefficients-two.json", "coefficients_mm: ", "must be an array [a2, a1, a0]"},
        BadCase{"coefficient-string.json", "coefficients_mm[1]: ", "must be a number"},
        BadCase{"factor-zero-crossing.json", "coefficients_mm: ", "<= 0 at d = 100 mm"},
        BadCase{"factor-negative-between-ends.json", "coefficients_mm: ", "<= 0 at d = 50 mm"},
        BadCase{"factor-absurd.json", "coefficients_mm: ", "was d in m or cm?"},
        BadCase{"range-reversed.json", "range_mm: ", "lo 80 mm must be < hi 20 mm"},
        BadCase{"range-negative.json", "range_mm: ", "lo must be >= 0 mm, got -5"},
        BadCase{"range-one-number.json", "range_mm: ", "must be an array [lo, hi]"},
        BadCase{"influence-zero.json", "influence_mm: ", "must lie in [1, 1000] mm, got 0"},
        BadCase{"influence-in-metres.json", "influence_mm: ", "got 0.1 (the unit is mm)"},
        BadCase{"influence-string.json", "influence_mm: ", "must be a number"},
        BadCase{"fade-zero.json", "fade_mm: ", "must lie in (0, 1000] mm, got 0"},
        BadCase{"allowance-negative.json", "allowance_mm: ", "must lie in [0, 200] mm, got -10"},
        BadCase{"allowance-absurd.json", "allowance_mm: ", "got 1000"},
        BadCase{"multiplier-unknown.json", "multiplier: ", "unknown reading 'literal'"},
        BadCase{"rib-soft.json", "rib_factor: ", "must lie in [1, 1000], got 0.5"},
        BadCase{"rib-string.json", "rib_factor: ", "must be a number"},
        BadCase{"covariance-asymmetric.json", "covariance: ", "must be symmetric"},
        BadCase{"covariance-negative-variance.json", "covariance: ", "diagonal must be >= 0"},
        BadCase{"covariance-shape.json", "covariance: ", "must be a 3×3 array"},
        BadCase{"unknown-field.json", "influence: ", "unknown field"},
        BadCase{"fit-not-object.json", "fit: ", "must be an object"},
        BadCase{"duplicate-key.json", "", "duplicate key \"influence_mm\" at the top level"},
        BadCase{"multiplier-literal-absurd.json", "multiplier: ", "reaches 9703"},
        BadCase{"covariance-not-psd.json", "covariance: ", "must be positive semi-definite"},
        BadCase{"layers-uint64.json", "layers: ", "suspicious count 18446744073709551615"}),
    [](const auto& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

TEST(SeamFile, MissingFileIsInputError) {
  EXPECT_THROW(ReadSeamProfile(kBad + "does-not-exist.json"), InputError);
}

}  // namespace
}  // namespace textile
