#ifndef TEXTILE_SIM_MESH_MESH_H_
#define TEXTILE_SIM_MESH_MESH_H_

// Triangle meshes of cloth patterns and their bending hinges: the data every element, solver and
// scene shares. Patterns are flat: rest positions lie in the plane z = 0 (x, y in metres).
//
//   textile::TriangleMesh mesh = textile::RegularGridMesh(0.5, 0.5, 30, 30);  // 1800 triangles
//   textile::CheckMesh(mesh);                       // throws InputError naming the element
//   std::vector<textile::Hinge> hinges = textile::BuildHinges(mesh);
//   // hinges[h].v: {wing 0, wing 1, edge start, edge end}, Pabst et al. Fig. 2 numbering.
//
// Layout: contiguous row-major arrays (#V×3 doubles, #F×3 ints), so that element loops stream
// through memory and Eigen maps them without copies.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace textile {

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // #V×3 [m]
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;   // #F×3 vertex ids

struct TriangleMesh {
  Vertices vertices;    // #V×3 rest positions [m]; z = 0 for flat patterns
  Triangles triangles;  // #F×3 vertex indices, counter-clockwise seen from +z
  int num_vertices() const { return static_cast<int>(vertices.rows()); }
  int num_triangles() const { return static_cast<int>(triangles.rows()); }
};

// A bending element: two triangles sharing the edge (v[2], v[3]); v[0] and v[1] are the wing
// vertices opposite the edge (Pabst et al. section 3.2, Fig. 2: x0, x1 wings, x2 x3 the edge).
// Triangle (v[0], v[2], v[3]) and triangle (v[1], v[3], v[2]) keep the mesh's orientation.
struct Hinge {
  std::array<int, 4> v{};
  std::array<int, 2> faces{};  // the two triangles (face of v[0], face of v[1])
};

// Throws InputError with the first problem, naming the element: no triangles, NaN or infinite
// coordinates (vertex i), indices out of range or repeated within a triangle (triangle f),
// degenerate triangles (area below 1e-12 of the mean triangle area; triangle f), duplicate
// vertices (two vertices closer than 1e-9 of the bounding box), unused vertices, non-manifold
// edges (more than two triangles share an edge), inconsistent orientation.
void CheckMesh(const TriangleMesh& mesh);

// Interior edges as hinges, in a deterministic order. Assumes CheckMesh passed.
std::vector<Hinge> BuildHinges(const TriangleMesh& mesh);

// Boundary edges (used by one triangle only), each as (start, end) following the triangle's
// orientation.
std::vector<std::array<int, 2>> BoundaryEdges(const TriangleMesh& mesh);

// Structured meshes for tests and benchmarks, in the plane z = 0 with corner (0, 0):
// a width × height rectangle [m] split into nx × ny cells, each cut into two triangles along the
// same diagonal ("regular") or into four around its centre ("criss-cross", one extra vertex per
// cell). 2·nx·ny and 4·nx·ny triangles.
TriangleMesh RegularGridMesh(double width, double height, int nx, int ny);
TriangleMesh CrissCrossGridMesh(double width, double height, int nx, int ny);

// Per-triangle rest areas [m²] (#F).
Eigen::VectorXd TriangleAreas(const TriangleMesh& mesh);

// A mesh refined by splitting edges at their midpoints (red-green refinement).
struct RefinedMesh {
  TriangleMesh mesh;  // the old vertices keep their ids; split points follow
  // Per new vertex (id #V_old + i): the old edge {a, b}, a < b, whose midpoint it is.
  std::vector<std::array<int, 2>> parents;
  // Per new triangle: the old triangle it lies in.
  std::vector<int> parent_triangle;
  // Positions of the old mesh (#V_old×3), e.g. a deformed state, carried to the new one:
  // old vertices as they are, each split point at the middle of its parent edge. A surface
  // that is flat on each old triangle stays the same surface.
  Vertices Prolong(const Vertices& x) const;
};

// Splits each `marked` triangle (#F flags) into four at its edge midpoints. A triangle with two
// split edges is split in four too (repeated until none is left), one with a single split edge
// in two across it, so the result is conforming (no hanging vertices) and its triangles keep
// the orientation and, for the fours, the shape of their parents. The rest positions of the
// split points are the midpoints of the rest edges (so the pattern's area and outline stay
// those of the old mesh). Throws InputError when `marked` does not have #F entries.
RefinedMesh RefineTriangles(const TriangleMesh& mesh, const std::vector<bool>& marked);

}  // namespace textile

#endif  // TEXTILE_SIM_MESH_MESH_H_
