#include "textile/sim/mesh.h"

#include <gtest/gtest.h>

#include "textile/sim/error.h"

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
  ExpectRejected(m, "triangle 3 refers to vertex 99");
  m = good;
  m.triangles(2, 1) = m.triangles(2, 0);
  ExpectRejected(m, "triangle 2 repeats a vertex");
  m = good;
  m.vertices.row(4) = m.vertices.row(0);  // collapses triangles around vertex 4 onto vertex 0's
  ExpectRejected(m, "degenerate");
  m = good;
  m.vertices.conservativeResize(m.vertices.rows() + 1, 3);
  m.vertices.row(m.vertices.rows() - 1) << 5, 5, 0;
  ExpectRejected(m, "is used by no triangle");
  m = good;
  m.triangles.row(0) = Eigen::Vector3i(m.triangles(0, 0), m.triangles(0, 2), m.triangles(0, 1));
  ExpectRejected(m, "oriented the same way");
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
