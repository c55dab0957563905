#ifndef TEXTILE_SIM_IO_MESH_IO_H_
#define TEXTILE_SIM_IO_MESH_IO_H_

// Mesh export (Wavefront OBJ, ASCII PLY) with optional per-vertex data, OBJ import for tests and
// tools, and a quality report of a triangle mesh.
//
//   textile::VertexScalar s{"seam_multiplier", multiplier};         // #V values
//   std::string ply = textile::PlyText(mesh, {s});                  // the CLI writes it atomically
//   textile::WriteObj("drape.obj", mesh, &s);                       // or write through a path
//   textile::MeshQuality q = textile::ComputeMeshQuality(mesh);
//   std::cerr << q.BriefReport() << "\n";  // "18273 triangles, 9295 vertices; angles 34.1..104.6°;
//   ..."
//
// Numbers are written in the shortest form that reads back to the same double, so a written mesh
// reads back bit for bit. Positions are in metres, as everywhere inside textile.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "textile/sim/mesh/mesh.h"

namespace textile {

// A named per-vertex quantity, e.g. the seam multiplier S.
struct VertexScalar {
  std::string name;        // PLY property name: letters, digits and '_', not starting with a digit
  Eigen::VectorXd values;  // #V, finite
};

// OBJ text: "v x y z" per vertex, "f a b c" (1-based) per triangle. With `colour`, vertices carry
// an RGB colour ("v x y z r g b", an extension MeshLab, Blender and others read) mapping the
// scalar linearly from its minimum (blue) to its maximum (red); a comment states name and range.
std::string ObjText(const TriangleMesh& mesh, const VertexScalar* colour = nullptr);
// ASCII PLY text: vertex x y z (double) followed by one double property per scalar; faces as
// "vertex_indices" lists. Throws InputError for a scalar with a bad name, size or value.
std::string PlyText(const TriangleMesh& mesh, const std::vector<VertexScalar>& scalars = {});

// Write the same texts to `path` (through a temporary file renamed into place). Throw InputError
// naming the path when it cannot be written.
void WriteObj(const std::string& path, const TriangleMesh& mesh,
              const VertexScalar* colour = nullptr);
void WritePly(const std::string& path, const TriangleMesh& mesh,
              const std::vector<VertexScalar>& scalars = {});

// How ParseObj takes a face of more than three corners.
enum class ObjPolygons {
  kRefuse,  // an InputError naming the line (the default: the solvers' meshes are triangles)
  kFan,     // split into the fan (0, k, k + 1): exact for convex polygons (scans' quads)
};

// Reads the vertices and triangles of an OBJ ("v" and "f" lines; "f" entries may be v, v/vt,
// v/vt/vn or v//vn, negative indices count from the end; other lines are ignored). Throws
// InputError "<source>:<line>: <problem>" for faces that are not triangles (kRefuse) or have
// fewer than 3 corners, bad numbers or indices out of range.
TriangleMesh ParseObj(const std::string& text, const std::string& source,
                      ObjPolygons polygons = ObjPolygons::kRefuse);
TriangleMesh ReadObj(const std::string& path);

// Reads a PLY (ascii or binary_little_endian): the vertex element's x, y, z (any scalar type)
// and the face element's vertex_indices (or vertex_index) lists (any count and index type),
// polygons fanned as ObjPolygons::kFan; other elements and properties are read past. Throws
// InputError "<source>:<line>: <problem>" (ASCII) or "<source>: <problem>" (binary) for a bad
// header, a short body, NaN or infinite coordinates, bad or out-of-range indices.
TriangleMesh ParsePly(const std::string& bytes, const std::string& source);
// Binary little-endian PLY bytes of a mesh: double x y z, faces as uchar count + int indices
// (the large meshes of tests and benchmarks; PlyText is the readable one).
std::string PlyBinaryBytes(const TriangleMesh& mesh);

// A draped mesh from a file, by its extension (any case): .obj (ParseObj with kFan) or .ply
// (ParsePly), up to 1 GB. Throws InputError naming the path for another extension, a file that
// cannot be read, or ParseObj's and ParsePly's problems. Positions are as in the file (the
// caller knows its units).
TriangleMesh ReadDrapedMesh(const std::string& path);

// Shape and size of a mesh's triangles.
struct MeshQuality {
  int num_triangles = 0;
  int num_vertices = 0;
  double min_angle_deg = 0;  // smallest interior angle [°]
  double max_angle_deg = 0;  // largest interior angle [°]
  // Largest e_max (e0 + e1 + e2) / (4 √3 A): 1 for an equilateral triangle, growing without bound
  // as a triangle degenerates (e_max over 2√3 times the inradius).
  double max_aspect_ratio = 0;
  double min_edge = 0, max_edge = 0, mean_edge = 0;  // over distinct edges [m]
  double min_area = 0, max_area = 0;                 // [m²]

  // One line: counts, angle range, aspect ratio, edge lengths in mm.
  std::string BriefReport() const;
};
MeshQuality ComputeMeshQuality(const TriangleMesh& mesh);

}  // namespace textile

#endif  // TEXTILE_SIM_IO_MESH_IO_H_
