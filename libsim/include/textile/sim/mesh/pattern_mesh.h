#ifndef TEXTILE_SIM_MESH_PATTERN_MESH_H_
#define TEXTILE_SIM_MESH_PATTERN_MESH_H_

// Unstructured triangle meshes of flat cloth patterns (plane z = 0), made with Gmsh, with seam
// lines kept as mesh edge paths and the mesh refined near them (Pabst et al. section 4.3).
//
//   textile::PatternMeshOptions options;
//   options.element_size = 0.01;                              // h = 10 mm away from seams
//   options.area_factor = [](double d_m) { return d_m < 0.02 ? 4.0 : 1.0; };  // e.g. S(d)
//   textile::Polyline2 seam(2, 2);
//   seam << -0.15, 0.0, 0.15, 0.0;                            // a diameter: the weft seam
//   textile::PatternMesh pm = textile::MeshDisk(0.15, {seam}, options);
//   // pm.mesh passes CheckMesh; pm.seam_paths[0] walks the seam from (-0.15, 0) to (0.15, 0)
//   // along mesh edges; pm.vertex_seam[v] says which seam vertex v lies on (-1: none).
//
// Refinement: an element at distance d from the nearest seam gets edge length
// h / sqrt(⌈area_factor(d)⌉), i.e. it is about ⌈area_factor(d)⌉ times smaller in area than the
// base element (factors below 1 count as 1). Gmsh is global state: calls are serialised by a mutex
// and each call initialises and finalises Gmsh; nothing is printed.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "textile/sim/mesh/mesh.h"

namespace textile {

// A polyline or polygon in the pattern plane: #K×2 points (x, y) [m].
using Polyline2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

struct PatternMeshOptions {
  // Target edge length h away from seams [m].
  double element_size = 0.01;
  // Area refinement factor as a function of the distance d [m] from the nearest seam line; the
  // seams module plugs in S(d) (docs/spec/physics.md, "Seams"). Empty: no refinement. Must return a
  // finite number; values below 1 mean no refinement. It should fall to 1 away from the seams: raw
  // Table 2 polynomials rise again far from the seam, S(d) does not.
  std::function<double(double d_m)> area_factor;
  // area_factor is consulted only for d < refinement_range [m]; elsewhere the factor is 1.
  double refinement_range = std::numeric_limits<double>::infinity();
  // d is measured from the first refining_lines of the lines passed (the seams) only; the lines
  // after them are embedded without refinement (the drapemeter's support circle). -1: all.
  int refining_lines = -1;
  // An upper bound on the edge length at the pattern point (x, y) [m], on top of the seams' field
  // (e.g. the drapemeter's finer band along the support's rim); empty: none. It must return a
  // finite length > 0 wherever it is asked; values above element_size change nothing.
  std::function<double(double x, double y)> max_size;
  // Refuse (InputError) patterns whose estimated or actual triangle count exceeds this.
  long max_triangles = 2'000'000;
  // Gmsh's 2D algorithm (option Mesh.Algorithm): 6 Frontal-Delaunay (best-shaped triangles),
  // 5 Delaunay (faster on large meshes), 1 MeshAdapt, 2 automatic.
  int gmsh_algorithm = 6;

  // False with a one-line reason when a field is out of range.
  bool Check(std::string* why) const;
};

struct PatternMesh {
  TriangleMesh mesh;  // z = 0, counter-clockwise seen from +z, no unused vertices
  // #V: the seam vertex v lies on, -1 for none (the lowest index where seams cross).
  std::vector<int> vertex_seam;
  // Per seam: its vertex ids in order from the seam's first point to its last; consecutive ids
  // share a mesh edge.
  std::vector<std::vector<int>> seam_paths;
};

// A width × height rectangle [m] with corner (0, 0) (a strip), like RegularGridMesh.
// @param seams  each #K×2 (K ≥ 2) seam polyline [m], inside the pattern or ending on its boundary
PatternMesh MeshRectangle(double width, double height, const std::vector<Polyline2>& seams,
                          const PatternMeshOptions& options);

// A disk of radius [m] centred at (0, 0) (the drapemeter specimen).
PatternMesh MeshDisk(double radius, const std::vector<Polyline2>& seams,
                     const PatternMeshOptions& options);

// A simple polygon. @param outline  #N×2 corners [m] (N ≥ 3) in either orientation; a last
// point equal to the first is dropped.
PatternMesh MeshPolygon(const Polyline2& outline, const std::vector<Polyline2>& seams,
                        const PatternMeshOptions& options);

// All the above throw InputError naming the problem (bad outline, "seam 2 point 3 lies outside
// the pattern", zero-length seam segment, too many triangles, ...) and ComputeError when Gmsh
// fails or returns a mesh that breaks the promises above.

}  // namespace textile

#endif  // TEXTILE_SIM_MESH_PATTERN_MESH_H_
