#include "textile/sim/scenes/drape_measure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/io/mesh_io.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
constexpr double kR = 0.15, kRs = 0.09;
// A 0.5 mm raster's area error over an outline of about 0.8 m: cells cut by the outline count
// whole or not at all, so the error is a fraction of perimeter × cell / 2 ≈ 2e-4 m² at worst,
// 0.005 in DC; on a smooth outline the cut cells nearly cancel (measured under 3e-4).
constexpr double kRasterDc = 1.5e-3;
// A polygon of 720 rim points loses (2π/720)²/6 ≈ 1.3e-5 of the circle's area.
constexpr int kSectors = 720;

TriangleMesh Drape(const std::function<double(double)>& outline, int sectors = kSectors) {
  return SyntheticDrapeMesh(kR, kRs, 40, sectors, outline);
}

double ExpectedDc(double shadow_area) {
  return (shadow_area - kPi * kRs * kRs) / (kPi * kR * kR - kPi * kRs * kRs);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

template <typename E>
bool Throws(const std::function<void()>& f) {
  try {
    f();
  } catch (const E&) {
    return true;
  } catch (...) {
  }
  return false;
}

// The mesh turned about the x axis by `degrees`.
TriangleMesh Tilted(TriangleMesh m, double degrees) {
  const double c = std::cos(degrees * kDegree), s = std::sin(degrees * kDegree);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double y = m.vertices(v, 1), z = m.vertices(v, 2);
    m.vertices(v, 1) = c * y - s * z;
    m.vertices(v, 2) = s * y + c * z;
  }
  return m;
}

TEST(DrapeMeasureMesh, FlatDiskHasDcOneAndNoNodes) {
  const MeasuredDrape m = MeasureDrapeMesh(Drape([](double) { return kR; }), {}, "flat");
  EXPECT_NEAR(m.drape_coefficient, 1.0, kRasterDc);
  EXPECT_TRUE(m.nodes.angles.empty());
  EXPECT_EQ(m.input_kind, "mesh");
  EXPECT_EQ(m.centre_from, "origin");  // symmetric: the flat top's centroid is the origin
  EXPECT_NEAR(m.max_radius, kR, 0.001);
}

TEST(DrapeMeasureMesh, ConeGivesTheCircleAreaDc) {
  for (double r : {0.1, 0.12, 0.14}) {
    const MeasuredDrape m = MeasureDrapeMesh(Drape([r](double) { return r; }), {}, "cone");
    EXPECT_NEAR(m.drape_coefficient, ExpectedDc(kPi * r * r), kRasterDc) << r;
    EXPECT_NEAR(m.mean_radius, r, 0.001) << r;  // cell centres within half a diagonal
    EXPECT_TRUE(m.nodes.angles.empty()) << r;
  }
}

std::function<double(double)> SixLobes() {
  return [](double t) { return 0.12 + 0.015 * std::cos(6.0 * (t - 10.0 * kDegree)); };
}

// The lobed shadow's area: ∫ r²/2 dθ = π (a² + b²/2).
constexpr double kLobedArea = kPi * (0.12 * 0.12 + 0.015 * 0.015 / 2.0);

TEST(DrapeMeasureMesh, SixLobesGiveSixNodesAtTheirAngles) {
  const MeasuredDrape m = MeasureDrapeMesh(Drape(SixLobes()), {}, "lobes");
  EXPECT_NEAR(m.drape_coefficient, ExpectedDc(kLobedArea), kRasterDc);
  ASSERT_EQ(m.nodes.angles.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    // One outline bin (1°) either way.
    EXPECT_NEAR(m.nodes.angles[k], (10.0 + 60.0 * k) * kDegree, 1.0 * kDegree) << k;
    EXPECT_NEAR(m.nodes.radii[k], 0.135, 0.001) << k;
  }
  EXPECT_NEAR(m.min_radius, 0.105, 0.001);
}

TEST(DrapeMeasureMesh, TranslatedScanGivesTheSameFigures) {
  const TriangleMesh centred = Drape(SixLobes());
  TriangleMesh moved = centred;
  moved.vertices.col(0).array() += 0.037;
  moved.vertices.col(1).array() -= 0.012;
  moved.vertices.col(2).array() += 0.4;  // a scan's own height
  const MeasuredDrape a = MeasureDrapeMesh(centred, {}, "a"), b = MeasureDrapeMesh(moved, {}, "b");
  EXPECT_EQ(b.centre_from, "plateau");
  EXPECT_NEAR(b.centre.x(), 0.037, 1e-6);
  EXPECT_NEAR(b.centre.y(), -0.012, 1e-6);
  EXPECT_NEAR(a.drape_coefficient, b.drape_coefficient, 5e-4);
  ASSERT_EQ(a.nodes.angles.size(), b.nodes.angles.size());
  for (size_t k = 0; k < a.nodes.angles.size(); ++k) {
    EXPECT_NEAR(a.nodes.radii[k], b.nodes.radii[k], 0.0005) << k;
    EXPECT_NEAR(a.nodes.angles[k], b.nodes.angles[k], 1.0 * kDegree) << k;
  }
}

TEST(DrapeMeasureMesh, YUpAndMillimetresMeasureTheSame) {
  const TriangleMesh z_up = Drape(SixLobes());
  TriangleMesh y_up = z_up, mm = z_up;
  // (X, Y, H) z-up is (X, H, -Y) y-up: seen from above the same right-handed frame.
  y_up.vertices.col(1) = z_up.vertices.col(2);
  y_up.vertices.col(2) = -z_up.vertices.col(1);
  mm.vertices *= 1000.0;
  DrapeMeshOptions oy, omm;
  oy.up = MeshUpAxis::kY;
  omm.metres_per_unit = 0.001;
  const MeasuredDrape a = MeasureDrapeMesh(z_up, {}, "z");
  const MeasuredDrape b = MeasureDrapeMesh(y_up, oy, "y");
  const MeasuredDrape c = MeasureDrapeMesh(mm, omm, "mm");
  for (const MeasuredDrape* m : {&b, &c}) {
    EXPECT_NEAR(m->drape_coefficient, a.drape_coefficient, 1e-9);
    ASSERT_EQ(m->nodes.angles.size(), a.nodes.angles.size());
    for (size_t k = 0; k < a.nodes.angles.size(); ++k)
      EXPECT_NEAR(m->nodes.angles[k], a.nodes.angles[k], 1e-9);
  }
  // The y-up mesh read as z-up has no flat top: the flag is named.
  EXPECT_NE(ErrorOf([&] { MeasureDrapeMesh(y_up, {}, "y.obj"); }).find("--up y"),
            std::string::npos);
}

TEST(DrapeMeasureMesh, StrayPointsWithoutFacesChangeNothing) {
  const TriangleMesh clean = Drape(SixLobes());
  TriangleMesh stray = clean;
  stray.vertices.conservativeResize(clean.num_vertices() + 2, 3);
  stray.vertices.row(clean.num_vertices()) << 0.3, -0.2, 0.05;  // above the top, far out
  stray.vertices.row(clean.num_vertices() + 1) << -5.0, 0.0, -1.0;
  const MeasuredDrape a = MeasureDrapeMesh(clean, {}, "a"), b = MeasureDrapeMesh(stray, {}, "b");
  EXPECT_EQ(a.drape_coefficient, b.drape_coefficient);
  EXPECT_EQ(b.centre_from, "origin");
}

TEST(DrapeMeasureMesh, SpikesAndStrayFacesAboveTheTopChangeNothing) {
  const TriangleMesh clean = Drape(SixLobes());
  TriangleMesh noisy = clean;
  noisy.vertices(1 + 5 * kSectors + 100, 2) += 0.02;  // a spike 20 mm up on the support
  const int n = noisy.num_vertices();
  noisy.vertices.conservativeResize(n + 3, 3);
  noisy.vertices.row(n) << 0.03, 0.03, 0.05;  // a stray 1 mm² face 50 mm above the support
  noisy.vertices.row(n + 1) << 0.032, 0.03, 0.05;
  noisy.vertices.row(n + 2) << 0.03, 0.031, 0.05;
  noisy.triangles.conservativeResize(noisy.num_triangles() + 1, 3);
  noisy.triangles.row(noisy.num_triangles() - 1) << n, n + 1, n + 2;
  const MeasuredDrape a = MeasureDrapeMesh(clean, {}, "a"), b = MeasureDrapeMesh(noisy, {}, "b");
  EXPECT_EQ(a.drape_coefficient, b.drape_coefficient);
  EXPECT_EQ(b.centre_from, "origin");
  EXPECT_TRUE(b.notes.empty());  // not levelled by the spike
}

TEST(DrapeMeasureMesh, GivenCentreIsUsed) {
  TriangleMesh moved = Drape(SixLobes());
  moved.vertices.col(0).array() += 0.02;
  DrapeMeshOptions o;
  o.centre = Eigen::Vector2d(0.02, 0.0);
  const MeasuredDrape m = MeasureDrapeMesh(moved, o, "given");
  EXPECT_EQ(m.centre_from, "given");
  EXPECT_NEAR(m.drape_coefficient, ExpectedDc(kLobedArea), kRasterDc);
}

TEST(DrapeMeasureMesh, RefusesBadMeshes) {
  TriangleMesh none = Drape(SixLobes());
  none.triangles.resize(0, 3);
  EXPECT_NE(ErrorOf([&] {
              MeasureDrapeMesh(none, {}, "none.obj");
            }).find("none.obj: the mesh has no faces"),
            std::string::npos);
  TriangleMesh nan = Drape(SixLobes());
  nan.vertices(7, 1) = std::nan("");
  EXPECT_TRUE(Throws<InputError>([&] { MeasureDrapeMesh(nan, {}, "nan.obj"); }));
  EXPECT_NE(ErrorOf([&] { MeasureDrapeMesh(nan, {}, "nan.obj"); }).find("vertex 7"),
            std::string::npos);
  TriangleMesh bad_index = Drape(SixLobes());
  bad_index.triangles(3, 2) = bad_index.num_vertices();
  EXPECT_NE(ErrorOf([&] { MeasureDrapeMesh(bad_index, {}, "i.obj"); }).find("out of range"),
            std::string::npos);
}

TEST(DrapeMeasureMesh, RefusesWrongUnitsNamingTheFlag) {
  TriangleMesh mm = Drape(SixLobes());
  mm.vertices *= 1000.0;  // a 150 mm specimen read as 150 m
  const std::string big = ErrorOf([&] { MeasureDrapeMesh(mm, {}, "mm.ply"); });
  EXPECT_NE(big.find("--units mm"), std::string::npos) << big;
  DrapeMeshOptions as_mm;
  as_mm.metres_per_unit = 0.001;  // a mesh in metres read as mm
  const std::string small = ErrorOf([&] { MeasureDrapeMesh(Drape(SixLobes()), as_mm, "m.ply"); });
  EXPECT_NE(small.find("--units m"), std::string::npos) << small;
  EXPECT_TRUE(Throws<InputError>([&] { MeasureDrapeMesh(mm, {}, "mm.ply"); }));
}

TEST(DrapeMeasureMesh, RefusesHalfADiskAndATiltedMesh) {
  // Half the specimen: the outline is not closed around the support.
  TriangleMesh half = Drape(SixLobes());
  Triangles kept(half.num_triangles(), 3);
  int n = 0;
  for (int t = 0; t < half.num_triangles(); ++t) {
    const Eigen::RowVector3d c =
        (half.vertices.row(half.triangles(t, 0)) + half.vertices.row(half.triangles(t, 1)) +
         half.vertices.row(half.triangles(t, 2))) /
        3.0;
    if (c.y() > 0.0) kept.row(n++) = half.triangles.row(t);
  }
  half.triangles = kept.topRows(n);
  DrapeMeshOptions at_origin;
  at_origin.centre = Eigen::Vector2d::Zero();
  const std::string cut = ErrorOf([&] { MeasureDrapeMesh(half, at_origin, "half.obj"); });
  EXPECT_NE(cut.find("not a closed curve around the support"), std::string::npos) << cut;
  EXPECT_TRUE(Throws<ComputeError>([&] { MeasureDrapeMesh(half, at_origin, "half.obj"); }));
  EXPECT_TRUE(Throws<std::exception>([&] { MeasureDrapeMesh(half, {}, "half.obj"); }));

  // Tilted by 3° about x: past max_tilt (2°); --up and --centre-mm are named.
  const std::string tilt =
      ErrorOf([&] { MeasureDrapeMesh(Tilted(Drape(SixLobes()), 3.0), {}, "t.obj"); });
  EXPECT_NE(tilt.find("slopes by 3°, over 2°"), std::string::npos) << tilt;
  EXPECT_NE(tilt.find("--centre-mm"), std::string::npos) << tilt;
}

TEST(DrapeMeasureMesh, SlightlyTiltedScanIsLevelled) {
  const TriangleMesh level = Drape(SixLobes());
  const MeasuredDrape a = MeasureDrapeMesh(level, {}, "level");
  EXPECT_TRUE(a.notes.empty());
  for (double degrees : {0.5, 1.5}) {
    TriangleMesh tilted = Tilted(level, degrees);
    tilted.vertices.col(0).array() += 0.037;
    tilted.vertices.col(1).array() -= 0.012;
    const MeasuredDrape b = MeasureDrapeMesh(tilted, {}, "tilted");
    ASSERT_EQ(b.notes.size(), 1u) << degrees;
    EXPECT_EQ(b.notes[0].code, "levelled");
    EXPECT_NE(b.notes[0].text.find(NumberText(degrees, 3) + "°"), std::string::npos)
        << b.notes[0].text;
    // Levelled about the top's centre (at the origin before the move): the centre and the
    // figures are the level mesh's, to the raster's sampling.
    EXPECT_NEAR(b.centre.x(), 0.037, 1e-4) << degrees;
    EXPECT_NEAR(b.centre.y(), -0.012, 1e-4) << degrees;
    EXPECT_NEAR(b.drape_coefficient, a.drape_coefficient, 5e-4) << degrees;
    ASSERT_EQ(b.nodes.angles.size(), a.nodes.angles.size()) << degrees;
    for (size_t k = 0; k < a.nodes.angles.size(); ++k)
      EXPECT_NEAR(b.nodes.radii[k], a.nodes.radii[k], 0.0005) << degrees << " " << k;
  }
  // Under kLevelBelow (0.1°) the mesh keeps its frame.
  EXPECT_TRUE(MeasureDrapeMesh(Tilted(level, 0.05), {}, "t").notes.empty());
}

TEST(DrapeMeasureMesh, PlateauCentreFollowsAreaNotVertexDensity) {
  // The flat top's vertices crowded towards the support's edge on the +x side (r' = R_s
  // (r/R_s)^(1 - cos θ / 2), one to one along each ray): the triangles still tile the same disk.
  TriangleMesh m = Drape(SixLobes());
  Eigen::Vector2d vertex_mean = Eigen::Vector2d::Zero();
  int top = 0;
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.vertices(v, 0), y = m.vertices(v, 1), r = std::hypot(x, y);
    if (r >= kRs - 1e-12 || r == 0.0) continue;
    const double t = std::atan2(y, x), r2 = kRs * std::pow(r / kRs, 1.0 - 0.5 * std::cos(t));
    m.vertices(v, 0) = r2 * std::cos(t);
    m.vertices(v, 1) = r2 * std::sin(t);
    vertex_mean += m.vertices.row(v).head<2>().transpose();
    ++top;
  }
  vertex_mean /= top;
  EXPECT_GT(vertex_mean.x(), 0.005);  // a vertex centroid would be pulled this far
  const MeshSupportCentre c =
      FindMeshSupportCentre(MeshInMeasureFrame(m, {}, "m"), m.triangles, {}, "m");
  EXPECT_LT(c.centre.norm(), 1e-9);
  EXPECT_GT(c.plateau_area, kPi * kRs * kRs * 0.99);
}

TEST(DrapeMeasureMesh, RasteriseFabricCoversATriangleWithMargin) {
  Vertices f(3, 3);
  // Corners a quarter cell off the 1 mm lattice of cell centres, so that no centre lies on an
  // edge (where round-off decides).
  f << 0.00025, 0.00025, 0.0, 0.01025, 0.00025, 0.0, 0.00025, 0.01025, 0.0;
  Triangles t(1, 3);
  t << 0, 1, 2;
  const DrapeShadow s = RasteriseFabric(f, t, Eigen::Vector2d(0.0, 0.0), 0.001, 0.005);
  long covered = 0;
  for (auto c : s.mask) covered += c;
  // Lattice points (i, j) mm with i, j ≥ 1 and i + j ≤ 10: 45.
  EXPECT_EQ(covered, 45);
  EXPECT_LE(s.origin_x, -0.005 - 2 * 0.001 + 1e-12);
  for (int i = 0; i < s.width; ++i) EXPECT_EQ(s.mask[i], 0);
}

TEST(MeasuredDrapeJson, ReadsBackWhatItWrites) {
  const MeasuredDrape m = MeasureDrapeMesh(Drape(SixLobes()), {}, "lobes.obj");
  const MeasuredDrape back = ParseMeasuredDrapeJson(MeasuredDrapeJson(m), "m.json");
  EXPECT_NEAR(back.drape_coefficient, m.drape_coefficient, 1e-12);
  EXPECT_EQ(back.nodes.angles.size(), m.nodes.angles.size());
  EXPECT_EQ(back.input_kind, "mesh");
  EXPECT_EQ(back.centre_from, "origin");
  EXPECT_EQ(back.shadow.radii.size(), m.shadow.radii.size());
  EXPECT_NEAR((back.shadow.radii - m.shadow.radii).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  EXPECT_TRUE(Throws<InputError>([] { ParseMeasuredDrapeJson("{\"format\": \"x\"}", "x.json"); }));
}

TEST(DrapeMeshOptions, CheckNamesTheField) {
  DrapeMeshOptions o;
  std::string why;
  EXPECT_TRUE(o.Check(&why));
  o.metres_per_unit = 0.0;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "unit: must be > 0 metres");
  EXPECT_EQ(ParseMeshUpAxis("y"), MeshUpAxis::kY);
  EXPECT_TRUE(Throws<InputError>([] { ParseMeshUpAxis("x"); }));
}

}  // namespace
}  // namespace textile
