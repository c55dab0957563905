#include "textile/sim/io/mesh_io.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

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

namespace {

// The words of one line of text, split at blanks (space, tab, CR), without copies.
class Words {
 public:
  explicit Words(std::string_view line) : rest_(line) {}
  // The next word, or false at the end of the line.
  bool Next(std::string_view* word) {
    std::size_t b = 0;
    while (b < rest_.size() && IsBlank(rest_[b])) ++b;
    if (b == rest_.size()) return false;
    std::size_t e = b;
    while (e < rest_.size() && !IsBlank(rest_[e])) ++e;
    *word = rest_.substr(b, e - b);
    rest_ = rest_.substr(e);
    return true;
  }

 private:
  static bool IsBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
  }
  std::string_view rest_;
};

template <typename T>
bool ParseWhole(std::string_view word, T* value) {
  const auto r = std::from_chars(word.data(), word.data() + word.size(), *value);
  return r.ec == std::errc() && r.ptr == word.data() + word.size();
}

// Splits a polygon of n >= 3 corners into the fan (0, k, k + 1), k = 1 .. n - 2.
template <typename Index, typename Push>
void Fan(const std::vector<Index>& corners, Push push) {
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) push(corners[0], corners[k], corners[k + 1]);
}

}  // namespace

TriangleMesh ParseObj(const std::string& text, const std::string& source, ObjPolygons polygons) {
  std::vector<double> xyz;
  std::vector<std::array<long, 3>> faces;
  std::vector<int> face_lines;
  std::vector<long> ids;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(source + ":" + std::to_string(line_no) + ": " + what);
  };
  const std::string_view all(text);
  std::size_t at = 0;
  while (at < all.size()) {
    std::size_t end = all.find('\n', at);
    if (end == std::string_view::npos) end = all.size();
    Words words(all.substr(at, end - at));
    at = end + 1;
    ++line_no;
    std::string_view key, word;
    if (!words.Next(&key)) continue;
    if (key == "v") {
      for (int c = 0; c < 3; ++c) {
        double value;
        if (!words.Next(&word)) fail("a vertex needs 3 coordinates");
        if (!ParseWhole(word, &value) || !std::isfinite(value))
          fail("bad coordinate \"" + std::string(word) + "\"");
        xyz.push_back(value);
      }
    } else if (key == "f") {
      ids.clear();
      while (words.Next(&word)) {
        const std::string_view head = word.substr(0, word.find('/'));
        long id;
        if (!ParseWhole(head, &id) || id == 0)
          fail("bad vertex index \"" + std::string(word) + "\"");
        ids.push_back(id);
      }
      if (polygons == ObjPolygons::kRefuse ? ids.size() != 3 : ids.size() < 3)
        fail("face with " + std::to_string(ids.size()) + " vertices; only " +
             (polygons == ObjPolygons::kRefuse ? "triangles" : "polygons of 3 or more") +
             " are read");
      const long defined = static_cast<long>(xyz.size() / 3);
      for (long& id : ids) {
        const long given = id;
        id = id > 0 ? id - 1 : defined + id;  // negative: relative to the end
        if (id < 0) fail("vertex index " + std::to_string(given) + " is out of range");
      }
      Fan(ids, [&](long a, long b, long c) {
        faces.push_back({a, b, c});
        face_lines.push_back(line_no);
      });
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

namespace {

// PLY (Turk's polygon file format): the header's elements and properties, and readers of the
// body in ASCII (words, line numbers for messages) and binary little-endian (bytes).
enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::kUint8;  // lists only
  PlyType type = PlyType::kFloat64;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool binary = false;
  std::vector<PlyElement> elements;
  std::size_t body = 0;  // offset of the first byte after "end_header\n"
  int body_line = 0;     // the body's first line number (ASCII messages)
};

int PlySize(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 8;
}

bool ParsePlyType(std::string_view name, PlyType* t) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [n, type] : kNames)
    if (name == n) {
      *t = type;
      return true;
    }
  return false;
}

PlyHeader ParsePlyHeader(const std::string& bytes, const std::string& source) {
  PlyHeader h;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(source + ":" + std::to_string(line_no) + ": " + what);
  };
  const std::string_view all(bytes);
  std::size_t at = 0;
  bool format_seen = false;
  while (true) {
    if (at >= all.size()) {
      ++line_no;
      fail("the PLY header has no end_header line");
    }
    std::size_t end = all.find('\n', at);
    if (end == std::string_view::npos) end = all.size();
    const std::string_view line = all.substr(at, end - at);
    at = end + 1;
    ++line_no;
    Words words(line);
    std::string_view key, a, b, c, d;
    if (!words.Next(&key)) {
      if (line_no == 1) fail("not a PLY file (its first line is not \"ply\")");
      continue;
    }
    if (line_no == 1) {
      if (key != "ply") fail("not a PLY file (its first line is not \"ply\")");
      continue;
    }
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") break;
    if (key == "format") {
      if (!words.Next(&a)) fail("format: needs ascii or binary_little_endian");
      if (a == "ascii")
        h.binary = false;
      else if (a == "binary_little_endian")
        h.binary = true;
      else
        fail("format " + std::string(a) + " is not read (ascii or binary_little_endian)");
      format_seen = true;
    } else if (key == "element") {
      PlyElement e;
      if (!words.Next(&a) || !words.Next(&b) || !ParseWhole(b, &e.count))
        fail("element: needs a name and a count");
      e.name = a;
      h.elements.push_back(e);
    } else if (key == "property") {
      if (h.elements.empty()) fail("property before any element");
      PlyProperty p;
      if (!words.Next(&a)) fail("property: needs a type and a name");
      if (a == "list") {
        p.list = true;
        if (!words.Next(&b) || !words.Next(&c) || !words.Next(&d))
          fail("property list: needs a count type, an item type and a name");
        if (!ParsePlyType(b, &p.count_type) || !ParsePlyType(c, &p.type))
          fail("property list: unknown type \"" + std::string(ParsePlyType(b, &p.type) ? c : b) +
               "\"");
        p.name = d;
      } else {
        if (!ParsePlyType(a, &p.type)) fail("property: unknown type \"" + std::string(a) + "\"");
        if (!words.Next(&b)) fail("property: needs a name");
        p.name = b;
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail("unknown header line \"" + std::string(key) + "\"");
    }
  }
  if (!format_seen) throw InputError(source + ": the PLY header has no format line");
  h.body = std::min(at, all.size());
  h.body_line = line_no + 1;
  return h;
}

// Reads the ASCII body word by word, counting lines for messages.
class PlyAsciiReader {
 public:
  PlyAsciiReader(std::string_view body, int first_line, const std::string& source)
      : text_(body), line_(first_line), source_(source) {}
  double Read(PlyType type) {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) {
      if (text_[at_] == '\n') ++line_;
      ++at_;
    }
    if (at_ >= text_.size()) Fail("the file ends before the data its header announces");
    std::size_t end = at_;
    while (end < text_.size() && !std::isspace(static_cast<unsigned char>(text_[end]))) ++end;
    const std::string_view word = text_.substr(at_, end - at_);
    at_ = end;
    // Whole numbers (counts, indices) parse faster as integers; "1.0" for an int falls through.
    if (type != PlyType::kFloat32 && type != PlyType::kFloat64) {
      long i;
      if (ParseWhole(word, &i)) return static_cast<double>(i);
    }
    double v;
    if (!ParseWhole(word, &v)) Fail("bad number \"" + std::string(word) + "\"");
    return v;
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(source_ + ":" + std::to_string(line_) + ": " + what);
  }
  // Where a problem found later is: "<source>:<line>" of a line recorded by Line().
  std::string Where(int line) const { return source_ + ":" + std::to_string(line); }
  int Line() const { return line_; }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
  int line_;
  const std::string& source_;
};

// Reads the binary little-endian body value by value.
class PlyBinaryReader {
 public:
  PlyBinaryReader(std::string_view body, const std::string& source)
      : bytes_(body), source_(source) {}
  double Read(PlyType t) {
    const int n = PlySize(t);
    if (bytes_.size() - at_ < static_cast<std::size_t>(n))
      Fail("the file ends before the data its header announces");
    const char* p = bytes_.data() + at_;
    at_ += n;
    switch (t) {
      case PlyType::kInt8:
        return Load<std::int8_t>(p);
      case PlyType::kUint8:
        return Load<std::uint8_t>(p);
      case PlyType::kInt16:
        return Load<std::int16_t>(p);
      case PlyType::kUint16:
        return Load<std::uint16_t>(p);
      case PlyType::kInt32:
        return Load<std::int32_t>(p);
      case PlyType::kUint32:
        return Load<std::uint32_t>(p);
      case PlyType::kFloat32:
        return Load<float>(p);
      case PlyType::kFloat64:
        return Load<double>(p);
    }
    return 0.0;
  }
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(source_ + ": " + what); }
  std::string Where(int) const { return source_; }
  int Line() const { return 0; }

 private:
  template <typename T>
  static double Load(const char* p) {
    static_assert(std::endian::native == std::endian::little,
                  "binary PLY reader: little-endian only");
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }
  std::string_view bytes_;
  std::size_t at_ = 0;
  const std::string& source_;
};

int PropertyIndex(const PlyElement& e, std::initializer_list<const char*> names) {
  for (std::size_t k = 0; k < e.properties.size(); ++k)
    for (const char* n : names)
      if (e.properties[k].name == n) return static_cast<int>(k);
  return -1;
}

// The body: x, y, z of each vertex, each face's polygon fanned into triangles; every other
// element and property read past.
template <typename Reader>
TriangleMesh ReadPlyBody(const PlyHeader& h, Reader& in, const std::string& source) {
  std::vector<double> xyz;
  std::vector<std::array<double, 3>> faces;
  // Where each triangle's face was (line, face number), for an index found out of range once
  // every vertex is known.
  std::vector<std::pair<int, std::size_t>> face_where;
  bool vertices_seen = false, faces_seen = false;
  std::vector<double> corners;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex" && !vertices_seen;
    const bool is_face = e.name == "face" && !faces_seen;
    int ix = -1, iy = -1, iz = -1, ifaces = -1;
    if (is_vertex) {
      vertices_seen = true;
      ix = PropertyIndex(e, {"x"}), iy = PropertyIndex(e, {"y"}), iz = PropertyIndex(e, {"z"});
      if (ix < 0 || iy < 0 || iz < 0 || e.properties[ix].list || e.properties[iy].list ||
          e.properties[iz].list)
        throw InputError(source + ": the PLY vertex element needs scalar properties x, y and z");
      xyz.reserve(3 * e.count);
    }
    if (is_face) {
      faces_seen = true;
      ifaces = PropertyIndex(e, {"vertex_indices", "vertex_index"});
      if (ifaces < 0 || !e.properties[ifaces].list)
        throw InputError(source + ": the PLY face element needs a list property vertex_indices");
      faces.reserve(2 * e.count);
    }
    for (std::size_t n = 0; n < e.count; ++n) {
      double p[3] = {0.0, 0.0, 0.0};
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& prop = e.properties[k];
        if (!prop.list) {
          const double v = in.Read(prop.type);
          const int kk = static_cast<int>(k);
          if (is_vertex && (kk == ix || kk == iy || kk == iz)) {
            if (!std::isfinite(v))
              in.Fail("vertex " + std::to_string(n) + ": coordinate " + prop.name +
                      " is NaN or infinite");
            p[kk == ix ? 0 : kk == iy ? 1 : 2] = v;
          }
          continue;
        }
        const double count = in.Read(prop.count_type);
        if (!(count >= 0.0 && count == std::floor(count) && count <= 1e6))
          in.Fail(e.name + " " + std::to_string(n) + ": bad list length " + NumberText(count));
        const bool wanted = is_face && static_cast<int>(k) == ifaces;
        corners.clear();
        for (int c = 0; c < static_cast<int>(count); ++c) {
          const double id = in.Read(prop.type);
          if (!wanted) continue;
          if (!(id >= 0.0 && id == std::floor(id)))
            in.Fail("face " + std::to_string(n) + ": bad vertex index " + NumberText(id));
          corners.push_back(id);
        }
        if (!wanted) continue;
        if (corners.size() < 3)
          in.Fail("face " + std::to_string(n) + " has " + std::to_string(corners.size()) +
                  " vertices; faces need 3 or more");
        Fan(corners, [&](double a, double b, double c) {
          faces.push_back({a, b, c});
          face_where.push_back({in.Line(), n});
        });
      }
      if (is_vertex) xyz.insert(xyz.end(), p, p + 3);
    }
  }
  if (!vertices_seen) throw InputError(source + ": the PLY file has no vertex element");
  TriangleMesh mesh;
  const std::size_t nv = xyz.size() / 3;
  mesh.vertices = Eigen::Map<const Vertices>(xyz.data(), static_cast<Eigen::Index>(nv), 3);
  mesh.triangles.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      if (faces[f][c] >= static_cast<double>(nv))
        throw InputError(in.Where(face_where[f].first) + ": face " +
                         std::to_string(face_where[f].second) + ": vertex index " +
                         NumberText(faces[f][c]) + " is out of range (" + std::to_string(nv) +
                         " vertices)");
      mesh.triangles(static_cast<Eigen::Index>(f), c) = static_cast<int>(faces[f][c]);
    }
  return mesh;
}

}  // namespace

TriangleMesh ParsePly(const std::string& bytes, const std::string& source) {
  const PlyHeader h = ParsePlyHeader(bytes, source);
  // A count beyond what the body can hold is a damaged header, not a reason to reserve memory.
  for (const PlyElement& e : h.elements) {
    std::size_t per = 0;
    for (const PlyProperty& p : e.properties)
      per += h.binary ? PlySize(p.list ? p.count_type : p.type) : 2;
    if (per > 0 && e.count > (bytes.size() - h.body) / per + 1)
      throw InputError(source + ": the PLY header announces " + std::to_string(e.count) + " " +
                       e.name + " elements, more than the file holds");
  }
  const std::string_view body = std::string_view(bytes).substr(h.body);
  if (h.binary) {
    PlyBinaryReader in(body, source);
    return ReadPlyBody(h, in, source);
  }
  PlyAsciiReader in(body, h.body_line, source);
  return ReadPlyBody(h, in, source);
}

std::string PlyBinaryBytes(const TriangleMesh& mesh) {
  std::string out =
      "ply\nformat binary_little_endian 1.0\ncomment textile mesh; positions in metres\n";
  out += "element vertex " + std::to_string(mesh.num_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "element face " + std::to_string(mesh.num_triangles()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  const std::size_t header = out.size();
  out.resize(header + 24 * static_cast<std::size_t>(mesh.num_vertices()) +
             13 * static_cast<std::size_t>(mesh.num_triangles()));
  char* p = out.data() + header;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    for (int c = 0; c < 3; ++c, p += 8) {
      const double x = mesh.vertices(v, c);
      std::memcpy(p, &x, 8);
    }
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    *p++ = 3;
    for (int c = 0; c < 3; ++c, p += 4) {
      const std::int32_t id = mesh.triangles(f, c);
      std::memcpy(p, &id, 4);
    }
  }
  return out;
}

TriangleMesh ReadDrapedMesh(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // 1 GB, as ReadObj: some twenty million triangles.
  if (ext == ".obj")
    return ParseObj(ReadInputFile(path, "mesh (OBJ)", 1u << 30), path, ObjPolygons::kFan);
  if (ext == ".ply") return ParsePly(ReadInputFile(path, "mesh (PLY)", 1u << 30), path);
  throw InputError(path + ": not a mesh this reads: name it .obj or .ply");
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
