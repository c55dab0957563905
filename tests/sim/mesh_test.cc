#include "textile/sim/mesh/mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

void ExpectRejected(const TriangleMesh& m, const std::string& fragment) {
  try {
    CheckMesh(m);
    FAIL() << "accepted; expected: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Mesh, GridsHaveEulerCountsAndPassChecks) {
  for (const TriangleMesh& m : {RegularGridMesh(0.5, 0.3, 6, 4), CrissCrossGridMesh(0.5, 0.3, 6, 4)}) {
    EXPECT_NO_THROW(CheckMesh(m));
    const int e_boundary = static_cast<int>(BoundaryEdges(m).size());
    const int e_interior = static_cast<int>(BuildHinges(m).size());
    // Euler for a disk: V - E + F = 1; 3F = 2 E_interior + E_boundary.
    EXPECT_EQ(m.num_vertices() - (e_interior + e_boundary) + m.num_triangles(), 1);
    EXPECT_EQ(3 * m.num_triangles(), 2 * e_interior + e_boundary);
    EXPECT_EQ(e_boundary, 2 * (6 + 4));
    EXPECT_NEAR(TriangleAreas(m).sum(), 0.15, 1e-15);
  }
}

// Red-green refinement: the marked triangles in four, closure by repeated red and single green
// splits, a conforming mesh of the same area and outline, and positions carried over exactly
// for a surface that is flat on each old triangle.
TEST(Mesh, RefineTrianglesSplitsMarkedTrianglesAndStaysConforming) {
  const TriangleMesh m = RegularGridMesh(0.4, 0.3, 4, 3);  // 24 triangles, cells 0.1 m
  std::vector<bool> marked(static_cast<size_t>(m.num_triangles()), false);
  marked[0] = marked[9] = true;
  const RefinedMesh r = RefineTriangles(m, marked);
  EXPECT_NO_THROW(CheckMesh(r.mesh));
  // Every child keeps the counter-clockwise orientation (positive signed area).
  const auto ccw = [](const TriangleMesh& t) {
    for (int f = 0; f < t.num_triangles(); ++f) {
      const Eigen::Vector3d a = t.vertices.row(t.triangles(f, 0)), b = t.vertices.row(t.triangles(f, 1)),
                            c = t.vertices.row(t.triangles(f, 2));
      if (!((b - a).cross(c - a).z() > 0.0)) return false;
    }
    return true;
  };
  EXPECT_TRUE(ccw(r.mesh));
  // Two marked triangles that leave a neighbour with two split edges: that one is split in four
  // too (closure), and the green splits meet the split edge in each of its three positions.
  std::vector<bool> closure(marked.size(), false);
  closure[2] = closure[10] = true;
  const RefinedMesh c = RefineTriangles(m, closure);
  EXPECT_NO_THROW(CheckMesh(c.mesh));
  EXPECT_TRUE(ccw(c.mesh));
  EXPECT_NEAR(TriangleAreas(c.mesh).sum(), 0.12, 1e-15);
  std::vector<int> children(marked.size(), 0);
  for (int parent : c.parent_triangle) ++children[static_cast<size_t>(parent)];
  int fours = 0, twos = 0;
  std::set<int> green_edge_positions;
  for (int f = 0; f < m.num_triangles(); ++f) {
    fours += children[static_cast<size_t>(f)] == 4;
    if (children[static_cast<size_t>(f)] != 2) continue;
    ++twos;
    for (int k = 0; k < 3; ++k) {
      const int p = std::min(m.triangles(f, k), m.triangles(f, (k + 1) % 3));
      const int q = std::max(m.triangles(f, k), m.triangles(f, (k + 1) % 3));
      for (const auto& e : c.parents)
        if (e[0] == p && e[1] == q) green_edge_positions.insert(k);
    }
  }
  EXPECT_EQ(fours, 3);  // the two marked and the closure
  EXPECT_GT(twos, 0);
  EXPECT_EQ(green_edge_positions.size(), 3u);
  EXPECT_EQ(r.mesh.num_vertices(), m.num_vertices() + static_cast<int>(r.parents.size()));
  EXPECT_EQ(static_cast<int>(r.parent_triangle.size()), r.mesh.num_triangles());
  EXPECT_NEAR(TriangleAreas(r.mesh).sum(), 0.12, 1e-15);
  EXPECT_EQ(BoundaryEdges(r.mesh).size(), BoundaryEdges(m).size() +
                                              [&] {  // split boundary edges count twice
                                                size_t n = 0;
                                                for (const auto& e : BoundaryEdges(m))
                                                  for (const auto& p : r.parents)
                                                    n += (std::min(e[0], e[1]) == p[0] &&
                                                          std::max(e[0], e[1]) == p[1]);
                                                return n;
                                              }());
  // Each marked triangle became four of a quarter of its area; the Euler count holds.
  const Eigen::VectorXd old_area = TriangleAreas(m), new_area = TriangleAreas(r.mesh);
  for (int marked_face : {0, 9}) {
    int children = 0;
    for (int t = 0; t < r.mesh.num_triangles(); ++t) {
      if (r.parent_triangle[static_cast<size_t>(t)] != marked_face) continue;
      ++children;
      EXPECT_NEAR(new_area(t), 0.25 * old_area(marked_face), 1e-15);
    }
    EXPECT_EQ(children, 4);
  }
  const int e = static_cast<int>(BuildHinges(r.mesh).size() + BoundaryEdges(r.mesh).size());
  EXPECT_EQ(r.mesh.num_vertices() - e + r.mesh.num_triangles(), 1);
  // Prolongation: an affine map of the rest positions is carried over exactly.
  Eigen::Matrix3d a;
  a << 1.1, 0.2, 0.0, -0.3, 0.9, 0.1, 0.5, 0.4, 1.0;
  const Eigen::RowVector3d shift(0.01, -0.02, 0.3);
  const Vertices x = (m.vertices * a.transpose()).rowwise() + shift;
  const Vertices fine = r.Prolong(x);
  const Vertices expected = (r.mesh.vertices * a.transpose()).rowwise() + shift;
  EXPECT_LT((fine - expected).cwiseAbs().maxCoeff(), 1e-15);
  // Nothing marked: the same mesh.
  const RefinedMesh same = RefineTriangles(m, std::vector<bool>(marked.size(), false));
  EXPECT_EQ(same.mesh.triangles, m.triangles);
  EXPECT_TRUE(same.parents.empty());
  // Everything marked: four times the triangles.
  EXPECT_EQ(RefineTriangles(m, std::vector<bool>(marked.size(), true)).mesh.num_triangles(),
            4 * m.num_triangles());
}

TEST(Mesh, RefineTrianglesRefusesMismatchedSizes) {
  const TriangleMesh m = RegularGridMesh(0.4, 0.3, 4, 3);
  EXPECT_THROW(RefineTriangles(m, std::vector<bool>(5, true)), InputError);
  const RefinedMesh r = RefineTriangles(m, std::vector<bool>(24, true));
  EXPECT_THROW(r.Prolong(r.mesh.vertices), InputError);  // the new mesh's size, not the old one's
}

TEST(Mesh, HingesKeepTriangleOrientation) {
  const TriangleMesh m = CrissCrossGridMesh(1.0, 1.0, 3, 3);
  for (const Hinge& h : BuildHinges(m)) {
    // (v0, v2, v3) is a cyclic shift of its face; (v1, v3, v2) of the other.
    const auto cyclic = [&](int f, int a, int b, int c) {
      for (int k = 0; k < 3; ++k) {
        if (m.triangles(f, k) == a && m.triangles(f, (k + 1) % 3) == b && m.triangles(f, (k + 2) % 3) == c)
          return true;
      }
      return false;
    };
    EXPECT_TRUE(cyclic(h.faces[0], h.v[0], h.v[2], h.v[3]));
    EXPECT_TRUE(cyclic(h.faces[1], h.v[1], h.v[3], h.v[2]));
  }
}

TEST(Mesh, RejectsBadMeshesNamingTheElement) {
  const TriangleMesh good = RegularGridMesh(1.0, 1.0, 2, 2);
  TriangleMesh m = good;
  m.vertices(4, 1) = std::nan("");
  ExpectRejected(m, "vertex 4 has a NaN");
  m = good;
  m.triangles(3, 2) = 99;
  ExpectRejected(m, "triangle 3 refers to vertex 99, outside 0..8");
  m = good;
  m.triangles(2, 1) = m.triangles(2, 0);
  ExpectRejected(m, "triangle 2 repeats a vertex");
  m = good;
  m.vertices.row(4) = m.vertices.row(0);  // triangle 0 = (0, 1, 4) collapses to a segment
  ExpectRejected(m, "triangle 0 is degenerate");
  m = good;
  m.vertices.conservativeResize(m.vertices.rows() + 1, 3);
  m.vertices.row(m.vertices.rows() - 1) << 5, 5, 0;
  ExpectRejected(m, "vertex 9 is used by no triangle");
  m = good;
  m.triangles.row(0) = Eigen::Vector3i(m.triangles(0, 0), m.triangles(0, 2), m.triangles(0, 1));
  ExpectRejected(m, "edge (0, 4) of triangles 0 and 1 is oriented the same way");
  m = TriangleMesh{};
  ExpectRejected(m, "no triangles");
}

TEST(Mesh, RejectsNonManifoldEdgeAndDuplicateVertex) {
  TriangleMesh m;
  m.vertices.resize(5, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  m.triangles.resize(3, 3);
  m.triangles << 0, 1, 2, 1, 0, 3, 0, 1, 4;  // edge (0, 1) in three triangles
  ExpectRejected(m, "0, 1");
  TriangleMesh d;
  d.vertices.resize(6, 3);
  d.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 1, 0, 0;  // vertex 5 duplicates 1
  d.triangles.resize(2, 3);
  d.triangles << 0, 1, 2, 5, 3, 4;
  d.vertices(4, 1) = 1.0;
  ExpectRejected(d, "vertices 1 and 5 coincide");
}

}  // namespace
}  // namespace textile
