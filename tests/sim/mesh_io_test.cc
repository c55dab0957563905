#include "textile/sim/io/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "scratch_dir.h"
#include "textile/sim/core/error.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/mesh/pattern_mesh.h"

namespace textile {
namespace {

namespace fs = std::filesystem;

// A small mesh with awkward coordinates (not short in decimal).
TriangleMesh AwkwardMesh() {
  TriangleMesh m = RegularGridMesh(0.1, 0.07, 3, 2);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (int v = 0; v < m.num_vertices(); ++v)
    m.vertices.row(v) += Eigen::RowVector3d(u(rng), u(rng), u(rng) / 3);
  return m;
}

std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(MeshIo, ObjRoundTripsBitForBit) {
  const TriangleMesh m = AwkwardMesh();
  const TriangleMesh back = ParseObj(ObjText(m), "mem.obj");
  EXPECT_EQ(back.vertices, m.vertices);
  EXPECT_EQ(back.triangles, m.triangles);
  // Through a file too, with colours (ignored on reading).
  const fs::path dir = ScratchDir("mesh_io_obj");
  VertexScalar s{"seam_multiplier", Eigen::VectorXd::LinSpaced(m.num_vertices(), 1.0, 9.07)};
  WriteObj((dir / "m.obj").string(), m, &s);
  const TriangleMesh from_file = ReadObj((dir / "m.obj").string());
  EXPECT_EQ(from_file.vertices, m.vertices);
  EXPECT_EQ(from_file.triangles, m.triangles);
  EXPECT_FALSE(fs::exists(dir / "m.obj.tmp"));
}

TEST(MeshIo, ObjColoursMapTheScalarFromBlueToRed) {
  TriangleMesh m = RegularGridMesh(1, 1, 1, 1);
  VertexScalar s{"seam_multiplier", Eigen::Vector4d(1.0, 2.0, 3.0, 5.0)};
  const std::string text = ObjText(m, &s);
  EXPECT_NE(text.find("# vertex colour: seam_multiplier from 1 (blue) to 5 (red)\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("v 0 0 0 0 0 1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("v 1 0 0 0.25 0 0.75\n"), std::string::npos) << text;
  EXPECT_NE(text.find("v 1 1 0 1 0 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("f 1 2 4\nf 1 4 3\n"), std::string::npos) << text;
}

TEST(MeshIo, PlyCarriesScalarsAsProperties) {
  const TriangleMesh m = AwkwardMesh();
  Eigen::VectorXd a = m.vertices.col(0) * 3.1,
                  b = Eigen::VectorXd::Constant(m.num_vertices(), 1.0 / 3);
  const std::string text = PlyText(m, {{"seam_multiplier", a}, {"distance_m", b}});
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> header;
  while (std::getline(in, line) && line != "end_header") header.push_back(line);
  ASSERT_GE(header.size(), 10u);
  EXPECT_EQ(header[0], "ply");
  EXPECT_EQ(header[1], "format ascii 1.0");
  EXPECT_NE(
      std::find(header.begin(), header.end(), "element vertex " + std::to_string(m.num_vertices())),
      header.end());
  EXPECT_NE(std::find(header.begin(), header.end(), "property double seam_multiplier"),
            header.end());
  EXPECT_NE(std::find(header.begin(), header.end(), "property double distance_m"), header.end());
  EXPECT_NE(
      std::find(header.begin(), header.end(), "element face " + std::to_string(m.num_triangles())),
      header.end());
  for (int v = 0; v < m.num_vertices(); ++v) {
    double x, y, z, s, d;
    in >> x >> y >> z >> s >> d;
    EXPECT_EQ(x, m.vertices(v, 0));
    EXPECT_EQ(z, m.vertices(v, 2));
    EXPECT_EQ(s, a(v));
    EXPECT_EQ(d, b(v));
  }
  for (int f = 0; f < m.num_triangles(); ++f) {
    int n, i, j, k;
    in >> n >> i >> j >> k;
    EXPECT_EQ(n, 3);
    EXPECT_EQ(Eigen::RowVector3i(i, j, k), m.triangles.row(f));
  }
  EXPECT_TRUE(static_cast<bool>(in));
  // Through a path.
  const fs::path dir = ScratchDir("mesh_io_ply");
  WritePly((dir / "m.ply").string(), m, {{"seam_multiplier", a}});
  std::ifstream file(dir / "m.ply");
  std::stringstream content;
  content << file.rdbuf();
  EXPECT_EQ(content.str(), PlyText(m, {{"seam_multiplier", a}}));
}

TEST(MeshIo, BadVertexDataAndPathsAreRefusedByName) {
  const TriangleMesh m = RegularGridMesh(1, 1, 1, 1);
  EXPECT_EQ(InputErrorOf([&] {
              PlyText(m, {{"seam multiplier", Eigen::Vector4d::Ones()}});
            }),
            "mesh export: vertex data name \"seam multiplier\" must be letters, digits and '_', "
            "not starting with a digit");
  EXPECT_EQ(InputErrorOf([&] {
              PlyText(m, {{"s", Eigen::Vector3d::Ones()}});
            }),
            "mesh export: vertex data \"s\" has 3 values for 4 vertices");
  VertexScalar nan{"s", Eigen::Vector4d(1, 2, std::nan(""), 4)};
  EXPECT_EQ(InputErrorOf([&] { ObjText(m, &nan); }),
            "mesh export: vertex data \"s\" value 2 is NaN or infinite");
  EXPECT_EQ(InputErrorOf([&] { WriteObj("/nonexistent-dir/m.obj", m); }),
            "/nonexistent-dir/m.obj: cannot open for writing");
  EXPECT_EQ(InputErrorOf([&] { ReadObj("/nonexistent-dir/m.obj"); }),
            "/nonexistent-dir/m.obj: cannot open mesh (OBJ)");
}

TEST(MeshIo, ObjReaderHandlesCommonFormsAndNamesBadLines) {
  const TriangleMesh m =
      ParseObj("# c\nv 0 0 0\nv 1 0 0\nvt 0 0\nv 0 1 0 0.5 0.5 0.5\nf 1/1 2/1/1 3//1\nf -3 -2 -1\n",
               "a.obj");
  EXPECT_EQ(m.num_vertices(), 3);
  ASSERT_EQ(m.num_triangles(), 2);
  EXPECT_EQ(m.triangles.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.triangles.row(1), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(
      InputErrorOf([] { ParseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n", "q.obj"); }),
      "q.obj:5: face with 4 vertices; only triangles are read");
  EXPECT_EQ(InputErrorOf([] { ParseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "q.obj"); }),
            "q.obj:4: vertex index 7 is out of range (3 vertices)");
  EXPECT_EQ(InputErrorOf([] { ParseObj("v 0 zero 0\n", "q.obj"); }),
            "q.obj:1: bad coordinate \"zero\"");
  EXPECT_EQ(InputErrorOf([] { ParseObj("v 0 0\n", "q.obj"); }),
            "q.obj:1: a vertex needs 3 coordinates");
}

TEST(MeshIo, ObjReaderFansPolygonsWhenAsked) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3\n";
  const TriangleMesh m = ParseObj(quad, "q.obj", ObjPolygons::kFan);
  ASSERT_EQ(m.num_triangles(), 3);
  EXPECT_EQ(m.triangles.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.triangles.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(InputErrorOf([] { ParseObj("v 0 0 0\nv 1 0 0\nf 1 2\n", "q.obj", ObjPolygons::kFan); }),
            "q.obj:3: face with 2 vertices; only polygons of 3 or more are read");
}

// Bytes of a little-endian value, for hand-made binary PLYs.
template <typename T>
void Put(std::string* out, T v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

TEST(MeshIo, PlyAsciiAndBinaryReadBackEqual) {
  const TriangleMesh m = AwkwardMesh();
  const TriangleMesh a =
      ParsePly(PlyText(m, {{"s", Eigen::VectorXd::LinSpaced(m.num_vertices(), 0, 1)}}), "a.ply");
  const TriangleMesh b = ParsePly(PlyBinaryBytes(m), "b.ply");
  EXPECT_EQ(a.vertices, m.vertices);  // shortest round-trip text: bit for bit
  EXPECT_EQ(b.vertices, m.vertices);
  EXPECT_EQ(a.triangles, m.triangles);
  EXPECT_EQ(b.triangles, m.triangles);
}

TEST(MeshIo, PlyReaderSkipsOtherDataAndFansQuads) {
  // float coordinates among normals and colours, a quad and a triangle with uint indices, and
  // an edge element after the faces; the same in ASCII and in binary.
  const std::string header_tail =
      "element vertex 4\nproperty float nx\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nelement face 2\nproperty uchar flags\n"
      "property list uchar uint vertex_indices\nelement edge 1\nproperty int vertex1\n"
      "property int vertex2\nend_header\n";
  const std::string ascii = "ply\nformat ascii 1.0\ncomment hand-made\n" + header_tail +
                            "9 0 0 0 255\n9 1 0 0 255\n9 1 1 0.5 255\n9 0 1 0 255\n"
                            "7 4 0 1 2 3\n7 3 0 2 3\n0 1\n";
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + header_tail;
  const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, 0}};
  for (const auto& p : xyz) {
    Put<float>(&binary, 9.0f);
    for (float c : p) Put<float>(&binary, c);
    Put<std::uint8_t>(&binary, 255);
  }
  Put<std::uint8_t>(&binary, 7);
  Put<std::uint8_t>(&binary, 4);
  for (std::uint32_t i : {0u, 1u, 2u, 3u}) Put<std::uint32_t>(&binary, i);
  Put<std::uint8_t>(&binary, 7);
  Put<std::uint8_t>(&binary, 3);
  for (std::uint32_t i : {0u, 2u, 3u}) Put<std::uint32_t>(&binary, i);
  Put<std::int32_t>(&binary, 0);
  Put<std::int32_t>(&binary, 1);
  for (const std::string& bytes : {ascii, binary}) {
    const TriangleMesh m = ParsePly(bytes, "h.ply");
    ASSERT_EQ(m.num_vertices(), 4);
    ASSERT_EQ(m.num_triangles(), 3);
    EXPECT_EQ(m.vertices(2, 2), 0.5);
    EXPECT_EQ(m.triangles.row(1), Eigen::RowVector3i(0, 2, 3));
    EXPECT_EQ(m.triangles.row(2), Eigen::RowVector3i(0, 2, 3));
  }
  // Cut short, the binary file is refused, not read past its end.
  EXPECT_EQ(InputErrorOf([&] { ParsePly(binary.substr(0, binary.size() - 5), "h.ply"); }),
            "h.ply: the file ends before the data its header announces");
}

TEST(MeshIo, PlyReaderNamesBadInput) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(InputErrorOf([&] { ParsePly(head + "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n", "n.ply"); }),
            "n.ply:11: vertex 1: coordinate z is NaN or infinite");
  EXPECT_EQ(InputErrorOf([&] { ParsePly(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "i.ply"); }),
            "i.ply:13: face 0: vertex index 9 is out of range (3 vertices)");
  EXPECT_EQ(InputErrorOf([&] { ParsePly(head + "0 0 0\n1 0 0\n", "s.ply"); }),
            "s.ply:12: the file ends before the data its header announces");
  EXPECT_EQ(InputErrorOf([] { ParsePly("solid x\n", "g.ply"); }),
            "g.ply:1: not a PLY file (its first line is not \"ply\")");
  EXPECT_EQ(
      InputErrorOf([] { ParsePly("ply\nformat binary_big_endian 1.0\nend_header\n", "b.ply"); }),
      "b.ply:2: format binary_big_endian is not read (ascii or binary_little_endian)");
  EXPECT_EQ(
      InputErrorOf([] {
        ParsePly(
            "ply\nformat ascii 1.0\nelement vertex 99999999\nproperty float x\nend_header\n1\n",
            "c.ply");
      }),
      "c.ply: the PLY header announces 99999999 vertex elements, more than the file holds");
  EXPECT_EQ(InputErrorOf([] { ReadDrapedMesh("mesh.stl"); }),
            "mesh.stl: not a mesh this reads: name it .obj or .ply");
}

TEST(MeshIo, QualityOfKnownTriangles) {
  TriangleMesh equilateral;
  equilateral.vertices.resize(3, 3);
  equilateral.vertices << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0;
  equilateral.triangles.resize(1, 3);
  equilateral.triangles << 0, 1, 2;
  MeshQuality q = ComputeMeshQuality(equilateral);
  // Round-off of sqrt and atan2 only.
  EXPECT_NEAR(q.min_angle_deg, 60.0, 1e-12);
  EXPECT_NEAR(q.max_angle_deg, 60.0, 1e-12);
  EXPECT_NEAR(q.max_aspect_ratio, 1.0, 1e-12);
  EXPECT_NEAR(q.mean_edge, 1.0, 1e-15);
  // The regular grid's right isosceles triangles: 45°, 90°; aspect √2 (2 + √2) / (4 √3 · ½).
  q = ComputeMeshQuality(RegularGridMesh(0.2, 0.2, 2, 2));
  EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-12);
  EXPECT_NEAR(q.max_angle_deg, 90.0, 1e-12);
  EXPECT_NEAR(q.max_aspect_ratio, std::sqrt(2.0) * (2 + std::sqrt(2.0)) / (2 * std::sqrt(3.0)),
              1e-12);
  EXPECT_NEAR(q.min_edge, 0.1, 1e-15);
  EXPECT_NEAR(q.max_edge, 0.1 * std::sqrt(2.0), 1e-15);
  EXPECT_EQ(q.num_triangles, 8);
  EXPECT_EQ(q.num_vertices, 9);
  EXPECT_NEAR(q.min_area, 0.005, 1e-15);
  EXPECT_EQ(q.BriefReport(),
            "8 triangles, 9 vertices; angles 45.0..90.0°; max aspect ratio 1.39; edges "
            "100.00..141.42 mm (mean 110.36 mm)");
}

TEST(MeshIo, GmshPatternMeshesAreWellShaped) {
  PatternMeshOptions o;
  o.element_size = 0.01;
  o.area_factor = [](double d) { return d < 0.03 ? 9.07 - 70.2 * d : 1.0; };  // C-plain-like steps
  Polyline2 seam(2, 2);
  seam << -0.15, 0, 0.15, 0;
  const MeshQuality q = ComputeMeshQuality(MeshDisk(0.15, {seam}, o).mesh);
  // Frontal-Delaunay gives near-equilateral triangles; the size steps of ⌈factor⌉ (10 levels here)
  // cost some: 23° and 2.16 measured, 20° and 2.5 required.
  EXPECT_GT(q.min_angle_deg, 20.0) << q.BriefReport();
  EXPECT_LT(q.max_aspect_ratio, 2.5) << q.BriefReport();
  EXPECT_LT(q.max_edge, 0.01 * 1.5) << q.BriefReport();
  EXPECT_GT(q.min_edge, 0.01 / std::sqrt(10.0) / 2) << q.BriefReport();
}

}  // namespace
}  // namespace textile
