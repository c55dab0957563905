#include "textile/sim/mesh/pattern_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <set>
#include <thread>

#include "textile/sim/core/error.h"
#include "textile/sim/mesh/mesh.h"

#include "ring_area.h"

namespace textile {
namespace {

Polyline2 Line(std::initializer_list<std::pair<double, double>> points) {
  Polyline2 p(static_cast<int>(points.size()), 2);
  int i = 0;
  for (const auto& [x, y] : points) p.row(i++) << x, y;
  return p;
}

PatternMeshOptions Options(double h) {
  PatternMeshOptions o;
  o.element_size = h;
  return o;
}

std::string MeshError(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// Every seam path is a chain of mesh edges from the seam's first point to its last.
void ExpectSeamPathsAreEdgePaths(const PatternMesh& pm, const std::vector<Polyline2>& seams) {
  std::set<std::pair<int, int>> edges;
  for (int f = 0; f < pm.mesh.num_triangles(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = pm.mesh.triangles(f, c), b = pm.mesh.triangles(f, (c + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  ASSERT_EQ(pm.seam_paths.size(), seams.size());
  for (std::size_t k = 0; k < seams.size(); ++k) {
    const std::vector<int>& path = pm.seam_paths[k];
    ASSERT_GE(path.size(), 2u);
    // Gmsh puts seam end points exactly where asked (up to OCC's tolerance, 1e-7 m).
    EXPECT_LT((pm.mesh.vertices.row(path.front()).head<2>() - seams[k].row(0)).norm(), 1e-7);
    EXPECT_LT(
        (pm.mesh.vertices.row(path.back()).head<2>() - seams[k].row(seams[k].rows() - 1)).norm(),
        1e-7);
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      EXPECT_TRUE(edges.count({std::min(path[i], path[i + 1]), std::max(path[i], path[i + 1])}))
          << "seam " << k << " step " << i;
    }
    for (int v : path) EXPECT_LE(pm.vertex_seam[v], static_cast<int>(k));
  }
}

void ExpectFlatCcw(const TriangleMesh& m) {
  EXPECT_NO_THROW(CheckMesh(m));
  EXPECT_EQ(m.vertices.col(2).cwiseAbs().maxCoeff(), 0.0);
  for (int f = 0; f < m.num_triangles(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.triangles(f, 0)),
                          b = m.vertices.row(m.triangles(f, 1)),
                          c = m.vertices.row(m.triangles(f, 2));
    ASSERT_GT((b - a).cross(c - a).z(), 0.0) << "triangle " << f;
  }
}

TEST(PatternMesh, RectangleIsFlatCcwAndCoversTheArea) {
  const PatternMesh pm = MeshRectangle(0.2, 0.05, {}, Options(0.01));
  ExpectFlatCcw(pm.mesh);
  // Straight boundary: the triangles tile the rectangle exactly (round-off only).
  EXPECT_NEAR(TriangleAreas(pm.mesh).sum(), 0.2 * 0.05, 1e-15);
  EXPECT_NEAR(pm.mesh.vertices.col(0).minCoeff(), 0.0, 1e-15);
  EXPECT_NEAR(pm.mesh.vertices.col(0).maxCoeff(), 0.2, 1e-15);
  // Equilateral-ish triangles of edge h: about 2.31 A / h² = 231.
  EXPECT_GT(pm.mesh.num_triangles(), 150);
  EXPECT_LT(pm.mesh.num_triangles(), 350);
  EXPECT_TRUE(pm.seam_paths.empty());
  for (int s : pm.vertex_seam) EXPECT_EQ(s, -1);
}

TEST(PatternMesh, DiskAreaConvergesToPiR2) {
  const double r = 0.15;
  const PatternMesh coarse = MeshDisk(r, {}, Options(0.02));
  const PatternMesh fine = MeshDisk(r, {}, Options(0.005));
  ExpectFlatCcw(fine.mesh);
  const double exact = std::numbers::pi * r * r;
  const double err_coarse = exact - TriangleAreas(coarse.mesh).sum();
  const double err_fine = exact - TriangleAreas(fine.mesh).sum();
  // Inscribed polygon: area error ≈ (2π/3) r h² / ... ∝ h²; 4× finer -> about 16× smaller.
  EXPECT_GT(err_fine, 0.0);
  EXPECT_LT(err_fine, err_coarse / 8);
  EXPECT_LT(err_fine / exact, 1e-3);
  // Every boundary vertex lies on the circle.
  for (const auto& e : BoundaryEdges(fine.mesh)) {
    EXPECT_NEAR(fine.mesh.vertices.row(e[0]).norm(), r, 1e-12);
  }
}

TEST(PatternMesh, ConcavePolygonClockwiseOrClosedGivesTheSameMesh) {
  // An L shape, counter-clockwise; also given clockwise and explicitly closed.
  const Polyline2 ccw = Line({{0, 0}, {0.2, 0}, {0.2, 0.1}, {0.1, 0.1}, {0.1, 0.2}, {0, 0.2}});
  Polyline2 cw = ccw.colwise().reverse();
  Polyline2 closed(7, 2);
  closed << ccw, ccw.row(0);
  const PatternMesh a = MeshPolygon(ccw, {}, Options(0.02));
  ExpectFlatCcw(a.mesh);
  EXPECT_NEAR(TriangleAreas(a.mesh).sum(), 0.03, 1e-15);
  const PatternMesh b = MeshPolygon(closed, {}, Options(0.02));
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  const PatternMesh c = MeshPolygon(cw, {}, Options(0.02));
  ExpectFlatCcw(c.mesh);
  EXPECT_NEAR(TriangleAreas(c.mesh).sum(), 0.03, 1e-15);
}

TEST(PatternMesh, MeshingIsDeterministic) {
  const std::vector<Polyline2> seams = {Line({{-0.1, 0}, {0.1, 0}})};
  const PatternMesh a = MeshDisk(0.15, seams, Options(0.01));
  const PatternMesh b = MeshDisk(0.15, seams, Options(0.01));
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.seam_paths, b.seam_paths);
}

TEST(PatternMesh, DrapemeterSeamsAreEdgePathsThroughTheCentre) {
  const double r = 0.15;
  // Weft and warp seams through the centre (ending on the rim) and a shifted chord.
  const std::vector<Polyline2> seams = {
      Line({{-r, 0}, {r, 0}}), Line({{0, -r}, {0, r}}),
      Line({{0.05, -std::sqrt(r * r - 0.0025)}, {0.05, std::sqrt(r * r - 0.0025)}})};
  const PatternMesh pm = MeshDisk(r, seams, Options(0.01));
  ExpectFlatCcw(pm.mesh);
  ExpectSeamPathsAreEdgePaths(pm, seams);
  // The two diameters cross at the centre: one vertex on both paths.
  std::set<int> weft(pm.seam_paths[0].begin(), pm.seam_paths[0].end());
  int shared = -1;
  for (int v : pm.seam_paths[1]) {
    if (weft.count(v)) shared = v;
  }
  ASSERT_GE(shared, 0);
  EXPECT_LT(pm.mesh.vertices.row(shared).norm(), 1e-12);
  EXPECT_EQ(pm.vertex_seam[shared], 0);  // the lowest index where seams cross
  // Seam vertices lie on their line, and every vertex marked on a seam is on a path.
  for (int v : pm.seam_paths[2]) EXPECT_NEAR(pm.mesh.vertices(v, 0), 0.05, 1e-12);
  for (int v = 0; v < pm.mesh.num_vertices(); ++v) {
    if (pm.vertex_seam[v] < 0) continue;
    const auto& path = pm.seam_paths[pm.vertex_seam[v]];
    EXPECT_NE(std::find(path.begin(), path.end(), v), path.end());
  }
}

TEST(PatternMesh, SeamInsideAndPolylineSeamsAreEdgePaths) {
  // A seam ending inside the pattern, a bent seam with one end on the boundary and a seam
  // starting on the first one (a T junction).
  const std::vector<Polyline2> seams = {Line({{0.05, 0.05}, {0.15, 0.05}}),
                                        Line({{0.0, 0.15}, {0.1, 0.12}, {0.17, 0.17}}),
                                        Line({{0.1, 0.05}, {0.1, 0.09}})};
  const PatternMesh pm = MeshRectangle(0.2, 0.2, seams, Options(0.015));
  ExpectFlatCcw(pm.mesh);
  ExpectSeamPathsAreEdgePaths(pm, seams);
  EXPECT_NE(std::find(pm.seam_paths[0].begin(), pm.seam_paths[0].end(), pm.seam_paths[2].front()),
            pm.seam_paths[0].end());
}

TEST(PatternMesh, RefinesNearSeamsByTheAreaFactor) {
  // Factor 4 within 20 mm of the seam y = 0.1: triangles there a quarter the area of the rest.
  PatternMeshOptions o = Options(0.01);
  o.area_factor = [](double d) { return d < 0.02 ? 4.0 : 1.0; };
  const std::vector<Polyline2> seams = {Line({{0, 0.1}, {0.3, 0.1}})};
  const PatternMesh pm = MeshRectangle(0.3, 0.2, seams, o);
  ExpectFlatCcw(pm.mesh);
  ExpectSeamPathsAreEdgePaths(pm, seams);
  const Eigen::VectorXd areas = TriangleAreas(pm.mesh);
  double near_sum = 0, far_sum = 0;
  int near_n = 0, far_n = 0;
  for (int f = 0; f < pm.mesh.num_triangles(); ++f) {
    double cy = 0;
    for (int c = 0; c < 3; ++c) cy += pm.mesh.vertices(pm.mesh.triangles(f, c), 1) / 3;
    const double d = std::abs(cy - 0.1);
    if (d < 0.012) near_sum += areas(f), ++near_n;
    if (d > 0.04 && d < 0.09) far_sum += areas(f), ++far_n;
  }
  const double ratio = (far_sum / far_n) / (near_sum / near_n);
  // The mesher follows sizes loosely (grading across the step); a factor 4 comes out 3..5.
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.0);
  // Non-integer factors round up: 1.2 counts as 2, i.e. edges h/√2.
  o.area_factor = [](double) { return 1.2; };
  const PatternMesh all = MeshRectangle(0.3, 0.2, seams, o);
  const double mean_area = 0.06 / all.mesh.num_triangles();
  EXPECT_NEAR(mean_area / (std::sqrt(3.0) / 4 * 0.01 * 0.01 / 2), 1.0, 0.2);
  // The range option switches the refinement off beyond it.
  o.refinement_range = 0.0;
  const PatternMesh none = MeshRectangle(0.3, 0.2, seams, o);
  EXPECT_LT(none.mesh.num_triangles(), 0.6 * all.mesh.num_triangles());
}

TEST(PatternMesh, RefinesNearTheRefiningLinesOnly) {
  // A diameter seam y = 0 and a circle of radius 90 mm (the drapemeter's support) on a 150 mm
  // disk, factor 4 within 20 mm of a refining line. With both refining the ring about the
  // circle is refined too; with only the seam refining (refining_lines = 1) the ring keeps the
  // plain size away from the seam, and the seam's own band stays refined.
  PatternMeshOptions o = Options(0.012);
  o.area_factor = [](double d) { return d < 0.02 ? 4.0 : 1.0; };
  Polyline2 circle(48, 2);  // segments of about h, its points off the seam, as the drapemeter's
  for (int k = 0; k < 48; ++k) {
    const double angle = 2 * std::numbers::pi * (k + 0.5) / 48 + 0.0123;
    circle.row(k) << 0.09 * std::cos(angle), 0.09 * std::sin(angle);
  }
  const std::vector<Polyline2> lines = {Line({{-0.15, 0}, {0.15, 0}}), circle};
  const PatternMesh both = MeshDisk(0.15, lines, o);
  o.refining_lines = 1;
  const PatternMesh seam_only = MeshDisk(0.15, lines, o);
  ExpectFlatCcw(seam_only.mesh);
  ExpectSeamPathsAreEdgePaths(seam_only, lines);
  // Mean triangle area about the circle (|y| > 40 mm, so away from the seam) and along the seam
  // (|y| < 8 mm, 20-60 mm from the centre, inside the circle's ring).
  auto mean_area = [](const TriangleMesh& m, auto inside) {
    const Eigen::VectorXd areas = TriangleAreas(m);
    double sum = 0;
    int n = 0;
    for (int f = 0; f < m.num_triangles(); ++f) {
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k)
        c += m.vertices.row(m.triangles(f, k)).transpose().template head<2>() / 3;
      if (inside(c)) sum += areas(f), ++n;
    }
    return sum / n;
  };
  auto ring = [](const Eigen::Vector2d& c) {
    return std::abs(c.norm() - 0.09) < 0.006 && std::abs(c.y()) > 0.04;
  };
  auto band = [](const Eigen::Vector2d& c) {
    return std::abs(c.y()) < 0.004 && std::abs(c.x()) > 0.02 && std::abs(c.x()) < 0.06;
  };
  EXPECT_GT(mean_area(seam_only.mesh, ring) / mean_area(both.mesh, ring), 2.5);
  EXPECT_NEAR(mean_area(seam_only.mesh, band) / mean_area(both.mesh, band), 1.0, 0.3);
  EXPECT_LT(seam_only.mesh.num_triangles(), both.mesh.num_triangles());
  o.refining_lines = 0;  // none refines: the plain mesh
  const PatternMesh none = MeshDisk(0.15, lines, o);
  EXPECT_GT(mean_area(none.mesh, band) / mean_area(seam_only.mesh, band), 2.5);
}

TEST(PatternMesh, MaxSizeRefinesWhereItIsSmallerOnly) {
  // 12 mm disk mesh with edges of at most 4 mm in the ring 90 mm < r < 110 mm: triangles in the
  // ring have about a ninth of the area of those near the centre, which keep theirs.
  PatternMeshOptions o = Options(0.012);
  const PatternMesh plain = MeshDisk(0.15, {}, o);
  o.max_size = [](double x, double y) {
    const double r = std::hypot(x, y);
    return r > 0.09 && r < 0.11 ? 0.004 : 1.0;  // 1 m: above element_size, no effect
  };
  const PatternMesh ring = MeshDisk(0.15, {}, o);
  ExpectFlatCcw(ring.mesh);
  const auto mean_area = MeanTriangleAreaInRing;
  const double ratio = mean_area(ring.mesh, 0.0, 0.05) / mean_area(ring.mesh, 0.094, 0.106);
  EXPECT_GT(ratio, 6.0);
  EXPECT_LT(ratio, 12.0);
  EXPECT_NEAR(mean_area(ring.mesh, 0.0, 0.05) / mean_area(plain.mesh, 0.0, 0.05), 1.0, 0.25);
  // The cap also feeds the triangle estimate that guards the mesher.
  o.max_triangles = plain.mesh.num_triangles() * 3 / 2;
  EXPECT_LT(plain.mesh.num_triangles() * 3 / 2, ring.mesh.num_triangles());
  EXPECT_NE(MeshError([&] { MeshDisk(0.15, {}, o); }).find("would exceed the limit"),
            std::string::npos);
  // A cap that is not a length is refused, naming the point.
  o = Options(0.012);
  o.max_size = [](double x, double) { return x > 0.1 ? std::nan("") : 0.012; };
  const std::string bad = MeshError([&] { MeshDisk(0.15, {}, o); });
  EXPECT_NE(bad.find("pattern mesh: max_size("), std::string::npos) << bad;
  EXPECT_NE(bad.find("returned nan; it must be a finite length > 0"), std::string::npos) << bad;
}

TEST(PatternMesh, IsThreadSafeAndQuiet) {
  testing::internal::CaptureStdout();
  std::vector<PatternMesh> out(4);
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([&out, i] {
      out[i] = MeshDisk(0.1, {Line({{-0.1, 0}, {0.1, 0}})}, Options(0.01));
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  for (int i = 1; i < 4; ++i) EXPECT_EQ(out[i].mesh.triangles, out[0].mesh.triangles);
}

TEST(PatternMesh, OptionsCheckNamesTheField) {
  PatternMeshOptions o;
  std::string why;
  EXPECT_TRUE(o.Check(&why));
  o.element_size = 0;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_NE(why.find("element_size"), std::string::npos);
  o.element_size = std::nan("");
  EXPECT_FALSE(o.Check(&why));
  o = PatternMeshOptions();
  o.max_triangles = 0;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_NE(why.find("max_triangles"), std::string::npos);
  o = PatternMeshOptions();
  o.gmsh_algorithm = 3;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "gmsh_algorithm must be 1, 2, 5 or 6, got 3");
  o = PatternMeshOptions();
  o.refining_lines = -2;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "refining_lines must be >= -1, got -2");
}

TEST(PatternMesh, BadOutlinesAreRefusedByName) {
  const PatternMeshOptions o = Options(0.01);
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {1, 0}}), {}, o);
            }),
            "pattern mesh: the outline has 2 points; a polygon needs at least 3");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {1, 0}, {std::nan(""), 1}}), {}, o);
            }),
            "pattern mesh: outline point 2 is NaN or infinite");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {0.1, 0}, {0.1, 0.1}, {0.1, 0.1}}), {}, o);
            }),
            "pattern mesh: outline points 2 and 3 coincide (zero-length edge)");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {0.1, 0}, {0.2, 0}}), {}, o);
            }).substr(0, 46),
            "pattern mesh: the outline is degenerate (area ");
  // A bow tie.
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {0.1, 0.1}, {0.1, 0}, {0, 0.2}}), {}, o);
            }),
            "pattern mesh: the outline intersects itself (edges 0 and 2)");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(Line({{0, 0}, {0.2, 0}, {0.1, 0}, {0.1, 0.1}}), {}, o);
            }),
            "pattern mesh: the outline folds back on itself at point 1");
  EXPECT_EQ(MeshError([&] { MeshDisk(-1, {}, o); }),
            "pattern mesh: disk radius must be a positive length, got -1 m");
  EXPECT_EQ(MeshError([&] { MeshRectangle(0.1, 0, {}, o); }),
            "pattern mesh: rectangle sides must be positive lengths, got 0.1 × 0 m");
  EXPECT_EQ(MeshError([&] { MeshDisk(0.1, {}, Options(-0.01)); }),
            "pattern mesh: element_size must be a positive length in metres, got -0.01");
}

TEST(PatternMesh, BadSeamsAreRefusedByName) {
  const PatternMeshOptions o = Options(0.01);
  auto disk = [&](std::vector<Polyline2> seams) {
    return MeshError([&] { MeshDisk(0.1, seams, o); });
  };
  const Polyline2 ok = Line({{0, 0}, {0.05, 0}});
  EXPECT_EQ(disk({ok, ok, Line({{0, 0}})}),
            "pattern mesh: seam 2 has 1 point(s); a seam needs at least 2");
  EXPECT_EQ(disk({ok, ok, Line({{0, 0}, {0.01, 0}, {0.02, 0}, {0.2, 0}})}),
            "pattern mesh: seam 2 point 3 lies outside the pattern (100 mm from its boundary)");
  EXPECT_EQ(disk({Line({{0, 0}, {0.01, std::nan("")}})}),
            "pattern mesh: seam 0 point 1 is NaN or infinite");
  EXPECT_EQ(
      disk({ok, Line({{0, 0}, {0.01, 0}, {0.01, 0}})}),
      "pattern mesh: seam 1 segment 1 has zero length (points 1 and 2 coincide within 1e-05 m)");
  EXPECT_EQ(disk({Line({{-0.05, 0}, {0.05, 0}, {0.05, 0.05}, {0, -0.05}})}),
            "pattern mesh: seam 0 crosses itself (segments 0 and 2)");
  EXPECT_EQ(disk({Line({{-0.05, 0}, {0.05, 0}, {0.0, 0}})}),
            "pattern mesh: seam 0 folds back on itself at point 1");
  // Both ends inside a concave pattern, the segment across the notch.
  const Polyline2 l_shape = Line({{0, 0}, {0.2, 0}, {0.2, 0.1}, {0.1, 0.1}, {0.1, 0.2}, {0, 0.2}});
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(l_shape, {Line({{0.05, 0.18}, {0.18, 0.05}})}, o);
            }),
            "pattern mesh: seam 0 segment 0 crosses the pattern boundary");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(l_shape, {Line({{0.1, 0.15}, {0.15, 0.1}})}, o);
            }),
            "pattern mesh: seam 0 segment 0 runs outside or along the pattern boundary");
  EXPECT_EQ(MeshError([&] {
              MeshPolygon(l_shape, {Line({{0.0, 0.05}, {0.0, 0.15}})}, o);
            }),
            "pattern mesh: seam 0 segment 0 runs outside or along the pattern boundary");
  PatternMeshOptions nan_factor = o;
  nan_factor.area_factor = [](double d) { return d < 0.01 ? std::nan("") : 1.0; };
  const std::string nan_error = MeshError([&] { MeshDisk(0.1, {ok}, nan_factor); });
  EXPECT_EQ(nan_error.substr(0, 30), "pattern mesh: area_factor(d = ") << nan_error;
  EXPECT_NE(nan_error.find(" m) returned nan; it must be a finite number"), std::string::npos)
      << nan_error;
}

TEST(PatternMesh, RefusesMeshesAboveTheTriangleCap) {
  // 1 m disk at 0.5 mm: about 2.31·π·1/0.25e-6 ≈ 29 million triangles.
  const std::string big = MeshError([&] { MeshDisk(1.0, {}, Options(0.0005)); });
  EXPECT_EQ(big.substr(0, 23), "pattern mesh: about 290") << big;
  EXPECT_NE(big.find(" triangles at element size 0.5 mm would exceed the limit of 2000000"),
            std::string::npos)
      << big;
  PatternMeshOptions o = Options(0.01);
  o.max_triangles = 100;
  const std::string e = MeshError([&] { MeshDisk(0.15, {}, o); });
  EXPECT_NE(e.find("would exceed the limit of 100; use a larger element size"), std::string::npos)
      << e;
}

}  // namespace
}  // namespace textile
