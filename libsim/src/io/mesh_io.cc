#include "textile/sim/io/mesh_io.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <system_error>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// Shortest text that reads back to the same double.
void Append(std::string* out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out->append(buf, r.ptr);
}

void Append(std::string* out, long v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out->append(buf, r.ptr);
}

void CheckScalar(const TriangleMesh& mesh, const VertexScalar& s) {
  const bool name_ok = !s.name.empty() && !std::isdigit(static_cast<unsigned char>(s.name[0])) &&
                       std::all_of(s.name.begin(), s.name.end(), [](char c) {
                         return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
                       });
  if (!name_ok) {
    throw InputError("mesh export: vertex data name \"" + s.name +
                     "\" must be letters, digits and '_', not starting with a digit");
  }
  if (s.values.size() != mesh.num_vertices()) {
    throw InputError("mesh export: vertex data \"" + s.name + "\" has " +
                     std::to_string(s.values.size()) + " values for " +
                     std::to_string(mesh.num_vertices()) + " vertices");
  }
  for (int i = 0; i < s.values.size(); ++i) {
    if (!std::isfinite(s.values(i))) {
      throw InputError("mesh export: vertex data \"" + s.name + "\" value " + std::to_string(i) +
                       " is NaN or infinite");
    }
  }
}

void WriteText(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  // A name of its own (process and a random number), so that it neither replaces a user's
  // "x.obj.tmp" nor collides with another run writing the same file.
  fs::path temp = target;
  temp +=
      ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}() % 1000000);
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path + ": cannot open for writing");
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::error_code ignore;
      fs::remove(temp, ignore);
      throw InputError(path + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    std::error_code ignore;
    fs::remove(temp, ignore);
    throw InputError(path + ": cannot replace the file: " + ec.message());
  }
}

}  // namespace

std::string ObjText(const TriangleMesh& mesh, const VertexScalar* colour) {
  std::string out = "# textile mesh: " + std::to_string(mesh.num_vertices()) + " vertices, " +
                    std::to_string(mesh.num_triangles()) + " triangles; positions in metres\n";
  double lo = 0, hi = 0;
  if (colour) {
    CheckScalar(mesh, *colour);
    lo = mesh.num_vertices() ? colour->values.minCoeff() : 0.0;
    hi = mesh.num_vertices() ? colour->values.maxCoeff() : 0.0;
    out += "# vertex colour: " + colour->name + " from ";
    Append(&out, lo);
    out += " (blue) to ";
    Append(&out, hi);
    out += " (red)\n";
  }
  out.reserve(out.size() +
              60 * static_cast<std::size_t>(mesh.num_vertices() + mesh.num_triangles()));
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    out += "v";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      Append(&out, mesh.vertices(v, c));
    }
    if (colour) {
      const double t = hi > lo ? (colour->values(v) - lo) / (hi - lo) : 0.0;
      const double rgb[3] = {t, 0.0, 1.0 - t};
      for (double x : rgb) {
        out += ' ';
        Append(&out, std::round(x * 1000) / 1000);
      }
    }
    out += '\n';
  }
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    out += "f";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      Append(&out, static_cast<long>(mesh.triangles(f, c)) + 1);
    }
    out += '\n';
  }
  return out;
}

std::string PlyText(const TriangleMesh& mesh, const std::vector<VertexScalar>& scalars) {
  for (const VertexScalar& s : scalars) CheckScalar(mesh, s);
  std::string out = "ply\nformat ascii 1.0\ncomment textile mesh; positions in metres\n";
  out += "element vertex " + std::to_string(mesh.num_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  for (const VertexScalar& s : scalars) out += "property double " + s.name + "\n";
  out += "element face " + std::to_string(mesh.num_triangles()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) {
      if (c) out += ' ';
      Append(&out, mesh.vertices(v, c));
    }
    for (const VertexScalar& s : scalars) {
      out += ' ';
      Append(&out, s.values(v));
    }
    out += '\n';
  }
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    out += "3";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      Append(&out, static_cast<long>(mesh.triangles(f, c)));
    }
    out += '\n';
  }
  return out;
}

void WriteObj(const std::string& path, const TriangleMesh& mesh, const VertexScalar* colour) {
  WriteText(path, ObjText(mesh, colour));
}

void WritePly(const std::string& path, const TriangleMesh& mesh,
              const std::vector<VertexScalar>& scalars) {
  WriteText(path, PlyText(mesh, scalars));
}

TriangleMesh ParseObj(const std::string& text, const std::string& source) {
  std::vector<double> xyz;
  std::vector<std::array<long, 3>> faces;
  std::vector<int> face_lines;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(source + ":" + std::to_string(line_no) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    if (key == "v") {
      std::string word;
      for (int c = 0; c < 3; ++c) {
        double value;
        if (!(words >> word)) fail("a vertex needs 3 coordinates");
        const auto r = std::from_chars(word.data(), word.data() + word.size(), value);
        if (r.ec != std::errc() || r.ptr != word.data() + word.size() || !std::isfinite(value)) {
          fail("bad coordinate \"" + word + "\"");
        }
        xyz.push_back(value);
      }
    } else if (key == "f") {
      std::vector<long> ids;
      std::string word;
      while (words >> word) {
        const std::string head = word.substr(0, word.find('/'));
        long id;
        const auto r = std::from_chars(head.data(), head.data() + head.size(), id);
        if (r.ec != std::errc() || r.ptr != head.data() + head.size() || id == 0)
          fail("bad vertex index \"" + word + "\"");
        ids.push_back(id);
      }
      if (ids.size() != 3)
        fail("face with " + std::to_string(ids.size()) + " vertices; only triangles are read");
      const long defined = static_cast<long>(xyz.size() / 3);
      std::array<long, 3> face;
      for (int c = 0; c < 3; ++c) {
        face[c] = ids[c] > 0 ? ids[c] - 1 : defined + ids[c];  // negative: relative to the end
        if (face[c] < 0) fail("vertex index " + std::to_string(ids[c]) + " is out of range");
      }
      faces.push_back(face);
      face_lines.push_back(line_no);
    }
  }
  TriangleMesh mesh;
  const int nv = static_cast<int>(xyz.size() / 3);
  mesh.vertices = Eigen::Map<const Vertices>(xyz.data(), nv, 3);
  mesh.triangles.resize(static_cast<int>(faces.size()), 3);
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    for (int c = 0; c < 3; ++c) {
      if (faces[f][c] >= nv) {
        line_no = face_lines[f];
        fail("vertex index " + std::to_string(faces[f][c] + 1) + " is out of range (" +
             std::to_string(nv) + " vertices)");
      }
      mesh.triangles(f, c) = static_cast<int>(faces[f][c]);
    }
  }
  return mesh;
}

TriangleMesh ReadObj(const std::string& path) {
  // 1 GB: some twenty million triangles, far beyond what the solvers take.
  return ParseObj(ReadInputFile(path, "mesh (OBJ)", 1u << 30), path);
}

MeshQuality ComputeMeshQuality(const TriangleMesh& mesh) {
  MeshQuality q;
  q.num_triangles = mesh.num_triangles();
  q.num_vertices = mesh.num_vertices();
  if (q.num_triangles == 0) return q;
  q.min_angle_deg = q.min_edge = q.min_area = std::numeric_limits<double>::infinity();
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * static_cast<std::size_t>(q.num_triangles));
  for (int f = 0; f < q.num_triangles; ++f) {
    Eigen::Vector3d p[3];
    for (int c = 0; c < 3; ++c) p[c] = mesh.vertices.row(mesh.triangles(f, c)).transpose();
    double len[3], longest = 0, perimeter = 0;
    for (int c = 0; c < 3; ++c) {
      len[c] = (p[(c + 1) % 3] - p[c]).norm();
      longest = std::max(longest, len[c]);
      perimeter += len[c];
      const int a = mesh.triangles(f, c), b = mesh.triangles(f, (c + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    q.min_area = std::min(q.min_area, area);
    q.max_area = std::max(q.max_area, area);
    q.max_aspect_ratio =
        std::max(q.max_aspect_ratio, area > 0 ? longest * perimeter / (4 * std::sqrt(3.0) * area)
                                              : std::numeric_limits<double>::infinity());
    for (int c = 0; c < 3; ++c) {
      // Angle at corner c from atan2(|u × v|, u · v): accurate for small and obtuse angles.
      const Eigen::Vector3d u = p[(c + 1) % 3] - p[c], v = p[(c + 2) % 3] - p[c];
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / std::numbers::pi;
      q.min_angle_deg = std::min(q.min_angle_deg, angle);
      q.max_angle_deg = std::max(q.max_angle_deg, angle);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  double sum = 0;
  for (const auto& [a, b] : edges) {
    const double l = (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
    q.min_edge = std::min(q.min_edge, l);
    q.max_edge = std::max(q.max_edge, l);
    sum += l;
  }
  q.mean_edge = sum / static_cast<double>(edges.size());
  return q;
}

std::string MeshQuality::BriefReport() const {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s << num_triangles << " triangles, " << num_vertices << " vertices; angles "
    << std::setprecision(1) << min_angle_deg << ".." << max_angle_deg << "°; max aspect ratio "
    << std::setprecision(2) << max_aspect_ratio << "; edges " << min_edge * 1e3 << ".."
    << max_edge * 1e3 << " mm (mean " << mean_edge * 1e3 << " mm)";
  return s.str();
}

}  // namespace textile
