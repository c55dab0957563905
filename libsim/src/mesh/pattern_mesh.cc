#include "textile/sim/mesh/pattern_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <mutex>
#include <numbers>
#include <unordered_map>
#include <unordered_set>

#include "gmsh_api.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

using Eigen::Vector2d;

double Cross(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Distance from p to the segment [a, b], and the segment parameter t in [0, 1] of the nearest
// point.
double SegmentDistance(const Vector2d& p, const Vector2d& a, const Vector2d& b,
                       double* t_out = nullptr) {
  const Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  if (t_out) *t_out = t;
  return (a + t * ab - p).norm();
}

// Closed segments [a, b] and [c, d] share a point or come closer than tol.
bool SegmentsTouch(const Vector2d& a, const Vector2d& b, const Vector2d& c, const Vector2d& d,
                   double tol) {
  const double o1 = Cross(b - a, c - a), o2 = Cross(b - a, d - a);
  const double o3 = Cross(d - c, a - c), o4 = Cross(d - c, b - c);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  return SegmentDistance(c, a, b) <= tol || SegmentDistance(d, a, b) <= tol ||
         SegmentDistance(a, c, d) <= tol || SegmentDistance(b, c, d) <= tol;
}

// The pattern's outline: a circle of `radius` about the origin, or a counter-clockwise polygon.
struct Outline {
  bool is_disk = false;
  double radius = 0.0;
  Polyline2 polygon;    // #N×2, counter-clockwise, not closed (last != first)
  double diameter = 0;  // bounding-box diagonal [m]

  int num_edges() const { return static_cast<int>(polygon.rows()); }
  Vector2d Corner(int i) const { return polygon.row(i % polygon.rows()).transpose(); }

  double Area() const {
    if (is_disk) return std::numbers::pi * radius * radius;
    double a = 0;
    for (int i = 0; i < num_edges(); ++i) a += Cross(Corner(i), Corner(i + 1));
    return 0.5 * a;
  }
  double DistanceToBoundary(const Vector2d& p) const {
    if (is_disk) return std::abs(p.norm() - radius);
    double d = std::numeric_limits<double>::infinity();
    for (int i = 0; i < num_edges(); ++i)
      d = std::min(d, SegmentDistance(p, Corner(i), Corner(i + 1)));
    return d;
  }
  // Strictly inside or outside; points on the boundary may go either way (callers test distance
  // first).
  bool Contains(const Vector2d& p) const {
    if (is_disk) return p.norm() < radius;
    bool inside = false;
    for (int i = 0, n = num_edges(); i < n; ++i) {
      const Vector2d a = Corner(i), b = Corner(i + 1);
      if ((a.y() > p.y()) != (b.y() > p.y())) {
        const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        if (p.x() < x) inside = !inside;
      }
    }
    return inside;
  }
  Vector2d ProjectToBoundary(const Vector2d& p) const {
    if (is_disk) return p.norm() > 0 ? Vector2d(p * (radius / p.norm())) : Vector2d(radius, 0);
    double best = std::numeric_limits<double>::infinity();
    Vector2d q = p;
    for (int i = 0; i < num_edges(); ++i) {
      double t;
      const double d = SegmentDistance(p, Corner(i), Corner(i + 1), &t);
      if (d < best) best = d, q = Corner(i) + t * (Corner(i + 1) - Corner(i));
    }
    return q;
  }
};

void CheckOptions(const PatternMeshOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("pattern mesh: " + why);
}

Outline PolygonOutline(const Polyline2& outline_in) {
  Polyline2 outline = outline_in;
  for (int i = 0; i < outline.rows(); ++i) {
    if (!outline.row(i).allFinite()) {
      throw InputError("pattern mesh: outline point " + std::to_string(i) + " is NaN or infinite");
    }
  }
  if (outline.rows() >= 2 && outline.row(0) == outline.row(outline.rows() - 1)) {
    outline.conservativeResize(outline.rows() - 1, 2);  // an explicitly closed outline
  }
  const int n = static_cast<int>(outline.rows());
  if (n < 3) {
    throw InputError("pattern mesh: the outline has " + std::to_string(n) +
                     " points; a polygon needs at least 3");
  }
  Outline o;
  o.polygon = outline;
  o.diameter = (outline.colwise().maxCoeff() - outline.colwise().minCoeff()).norm();
  const double tol = 1e-9 * o.diameter;
  for (int i = 0; i < n; ++i) {
    if ((o.Corner(i + 1) - o.Corner(i)).norm() <= tol) {
      throw InputError("pattern mesh: outline points " + std::to_string(i) + " and " +
                       std::to_string((i + 1) % n) + " coincide (zero-length edge)");
    }
  }
  const double area = o.Area();
  if (!(std::abs(area) > 1e-9 * o.diameter * o.diameter)) {
    throw InputError("pattern mesh: the outline is degenerate (area " + NumberText(area) + " m²)");
  }
  // Simple polygon: non-adjacent edges do not touch; adjacent edges do not fold back.
  for (int i = 0; i < n; ++i) {
    const Vector2d a = o.Corner(i), b = o.Corner(i + 1), c = o.Corner(i + 2);
    if (SegmentDistance(c, a, b) <= tol || SegmentDistance(a, b, c) <= tol) {
      throw InputError("pattern mesh: the outline folds back on itself at point " +
                       std::to_string((i + 1) % n));
    }
    for (int j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (SegmentsTouch(a, b, o.Corner(j), o.Corner(j + 1), tol)) {
        throw InputError("pattern mesh: the outline intersects itself (edges " + std::to_string(i) +
                         " and " + std::to_string(j) + ")");
      }
    }
  }
  if (area < 0) o.polygon = o.polygon.colwise().reverse().eval();
  return o;
}

// Validates the seams against the outline and returns them with points within `snap` of the
// boundary moved onto it (so that Gmsh splits the boundary there instead of leaving a sliver).
std::vector<Polyline2> CheckedSeams(const std::vector<Polyline2>& seams, const Outline& outline,
                                    double snap) {
  std::vector<Polyline2> out = seams;
  for (int k = 0; k < static_cast<int>(seams.size()); ++k) {
    Polyline2& s = out[k];
    const std::string name = "pattern mesh: seam " + std::to_string(k);
    const int n = static_cast<int>(s.rows());
    if (n < 2)
      throw InputError(name + " has " + std::to_string(n) + " point(s); a seam needs at least 2");
    for (int i = 0; i < n; ++i) {
      Vector2d p = s.row(i).transpose();
      if (!p.allFinite())
        throw InputError(name + " point " + std::to_string(i) + " is NaN or infinite");
      const double d = outline.DistanceToBoundary(p);
      if (d <= snap) {
        p = outline.ProjectToBoundary(p);
      } else if (!outline.Contains(p)) {
        throw InputError(name + " point " + std::to_string(i) + " lies outside the pattern (" +
                         NumberText(d * 1e3) + " mm from its boundary)");
      }
      s.row(i) = p.transpose();
    }
    auto pt = [&](int i) -> Vector2d { return s.row(i).transpose(); };
    for (int i = 0; i + 1 < n; ++i) {
      if ((pt(i + 1) - pt(i)).norm() <= snap) {
        throw InputError(name + " segment " + std::to_string(i) + " has zero length (points " +
                         std::to_string(i) + " and " + std::to_string(i + 1) + " coincide within " +
                         NumberText(snap) + " m)");
      }
    }
    for (int i = 0; i + 1 < n; ++i) {
      const Vector2d a = pt(i), b = pt(i + 1);
      if (!outline.is_disk) {
        for (int e = 0; e < outline.num_edges(); ++e) {
          const Vector2d c = outline.Corner(e), d = outline.Corner(e + 1);
          const double o1 = Cross(b - a, c - a), o2 = Cross(b - a, d - a);
          const double o3 = Cross(d - c, a - c), o4 = Cross(d - c, b - c);
          const bool proper = ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) &&
                              ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
          const bool ends_here =
              SegmentDistance(a, c, d) <= snap || SegmentDistance(b, c, d) <= snap;
          const bool corner_on =
              (SegmentDistance(c, a, b) <= snap && (c - a).norm() > snap && (c - b).norm() > snap);
          if ((proper && !ends_here) || corner_on) {
            throw InputError(name + " segment " + std::to_string(i) +
                             " crosses the pattern boundary");
          }
        }
      }
      // Not crossing the boundary, the open segment is inside or outside as a whole.
      if (outline.DistanceToBoundary(0.5 * (a + b)) <= snap || !outline.Contains(0.5 * (a + b))) {
        throw InputError(name + " segment " + std::to_string(i) +
                         " runs outside or along the pattern boundary");
      }
      if (i + 2 < n &&
          (SegmentDistance(pt(i + 2), a, b) <= snap || SegmentDistance(a, b, pt(i + 2)) <= snap)) {
        throw InputError(name + " folds back on itself at point " + std::to_string(i + 1));
      }
      for (int j = i + 2; j + 1 < n; ++j) {
        if (SegmentsTouch(a, b, pt(j), pt(j + 1), snap)) {
          throw InputError(name + " crosses itself (segments " + std::to_string(i) + " and " +
                           std::to_string(j) + ")");
        }
      }
    }
  }
  return out;
}

// Edge length h / sqrt(⌈area_factor(d)⌉) at distance d from the nearest seam, at most max_size.
class SizeField {
 public:
  SizeField(const std::vector<Polyline2>& seams, const PatternMeshOptions& options)
      : options_(options) {
    const size_t refining =
        options.refining_lines < 0
            ? seams.size()
            : std::min(seams.size(), static_cast<size_t>(options.refining_lines));
    for (size_t k = 0; k < refining; ++k) {
      const Polyline2& s = seams[k];
      for (int i = 0; i + 1 < s.rows(); ++i)
        segments_.push_back({s.row(i).transpose(), s.row(i + 1).transpose()});
    }
  }
  double Distance(const Vector2d& p) const {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& [a, b] : segments_) d = std::min(d, SegmentDistance(p, a, b));
    return d;
  }
  // ⌈area_factor(d)⌉ ≥ 1; throws InputError when the factor is not a finite number.
  double AreaFactor(const Vector2d& p) const {
    if (!options_.area_factor || segments_.empty()) return 1.0;
    const double d = Distance(p);
    if (!(d < options_.refinement_range)) return 1.0;  // range 0: no refinement at all
    const double f = options_.area_factor(d);
    if (!std::isfinite(f)) {
      throw InputError("pattern mesh: area_factor(d = " + NumberText(d) + " m) returned " +
                       NumberText(f) + "; it must be a finite number");
    }
    return std::max(1.0, std::ceil(f));
  }
  // The seams' size, capped by options.max_size; throws InputError when the cap is not a length.
  double Size(const Vector2d& p) const {
    const double size = options_.element_size / std::sqrt(AreaFactor(p));
    if (!options_.max_size) return size;
    const double cap = options_.max_size(p.x(), p.y());
    if (!(std::isfinite(cap) && cap > 0.0)) {
      throw InputError("pattern mesh: max_size(" + NumberText(p.x()) + ", " + NumberText(p.y()) +
                       " m) returned " + NumberText(cap) + "; it must be a finite length > 0");
    }
    return std::min(size, cap);
  }

 private:
  const PatternMeshOptions& options_;
  std::vector<std::pair<Vector2d, Vector2d>> segments_;
};

// Triangles an equilateral mesh following the size field would have: ∫ dA / (√3/4 size²), by
// midpoint sampling on a grid over the bounding box.
double EstimateTriangleCount(const Outline& outline, const SizeField& field, double h) {
  Eigen::Vector2d lo, hi;
  if (outline.is_disk) {
    lo.setConstant(-outline.radius), hi.setConstant(outline.radius);
  } else {
    lo = outline.polygon.colwise().minCoeff().transpose(),
    hi = outline.polygon.colwise().maxCoeff().transpose();
  }
  const int n = 160;
  const Vector2d step = (hi - lo) / n;
  double inside_cells = 0, weighted = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Vector2d p = lo + Vector2d((i + 0.5) * step.x(), (j + 0.5) * step.y());
      if (!outline.Contains(p)) continue;
      inside_cells += 1;
      const double ratio = h / field.Size(p);  // = sqrt(AreaFactor) without max_size
      weighted += ratio * ratio;
    }
  }
  const double mean_factor = inside_cells > 0 ? weighted / inside_cells : 1.0;
  return std::abs(outline.Area()) * mean_factor / (std::sqrt(3.0) / 4.0 * h * h);
}

// Gmsh keeps global state: one caller at a time, each with a fresh, silent session.
std::mutex& GmshMutex() {
  static std::mutex m;
  return m;
}

// Gmsh's last logged error, or `fallback`.
std::string GmshError(const gmsh_api::Api& gmsh, const std::string& fallback) {
  char* last = nullptr;
  int ierr = 0;
  gmsh.logger_get_last_error(&last, &ierr);
  std::string message = ierr == 0 && last && *last ? last : fallback;
  if (last) gmsh.free(last);
  return "pattern mesh: Gmsh failed: " + message;
}

// A C API call's error flag -> ComputeError with Gmsh's message.
void Check(const gmsh_api::Api& gmsh, int ierr, const char* call) {
  if (ierr != 0) throw ComputeError(GmshError(gmsh, std::string(call) + " failed"));
}

class GmshSession {
 public:
  explicit GmshSession(const gmsh_api::Api& gmsh) : gmsh_(gmsh), lock_(GmshMutex()) {
    int ierr = 0;
    gmsh_.initialize(0, nullptr, /*readConfigFiles=*/0, &ierr);
    if (ierr != 0) throw ComputeError("pattern mesh: Gmsh failed to initialise");
    gmsh_.option_set_number("General.Terminal", 0, &ierr);
    Check(gmsh_, ierr, "option General.Terminal");
    gmsh_.logger_start(&ierr);
    Check(gmsh_, ierr, "logger start");
  }
  ~GmshSession() {  // errors here are ignored: Gmsh is left for the next initialize
    int ierr = 0;
    gmsh_.logger_stop(&ierr);
    gmsh_.finalize(&ierr);
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  const gmsh_api::Api& gmsh_;
  std::lock_guard<std::mutex> lock_;
};

// An array the C API allocated, freed with gmshFree.
template <class T>
struct GmshArray {
  const gmsh_api::Api& gmsh;
  T* data = nullptr;
  std::size_t size = 0;
  explicit GmshArray(const gmsh_api::Api& g) : gmsh(g) {}
  ~GmshArray() {
    if (data) gmsh.free(data);
  }
  GmshArray(const GmshArray&) = delete;
  GmshArray& operator=(const GmshArray&) = delete;
};

// Arrays of arrays (getElements, fragment's map), freed inner first.
template <class T>
struct GmshArrays {
  const gmsh_api::Api& gmsh;
  T** data = nullptr;
  std::size_t* sizes = nullptr;
  std::size_t count = 0;
  explicit GmshArrays(const gmsh_api::Api& g) : gmsh(g) {}
  ~GmshArrays() {
    for (std::size_t i = 0; data && i < count; ++i)
      if (data[i]) gmsh.free(data[i]);
    if (data) gmsh.free(data);
    if (sizes) gmsh.free(sizes);
  }
  GmshArrays(const GmshArrays&) = delete;
  GmshArrays& operator=(const GmshArrays&) = delete;
};

// The size field behind Gmsh's C callback; an exception must not cross Gmsh's frames, so it is
// kept and rethrown after generate.
struct SizeCallbackData {
  const SizeField* field;
  double h;
  std::exception_ptr error;
};

double SizeCallback(int, int, double x, double y, double, void* data) {
  auto* d = static_cast<SizeCallbackData*>(data);
  if (d->error) return d->h;
  try {
    return d->field->Size(Vector2d(x, y));
  } catch (...) {
    d->error = std::current_exception();
    return d->h;
  }
}

// What Gmsh hands back, before compaction.
struct RawMesh {
  std::vector<std::size_t> node_tags;
  std::vector<double> node_xyz;                      // 3 per node
  std::vector<std::size_t> triangle_nodes;           // 3 per triangle
  std::vector<std::vector<std::size_t>> seam_nodes;  // per seam: nodes on its curves
};

RawMesh RunGmsh(const Outline& outline, const std::vector<Polyline2>& seams, const SizeField& field,
                const PatternMeshOptions& options) {
  const double h = options.element_size;
  const gmsh_api::Api& gmsh = gmsh_api::Load();
  RawMesh raw;
  GmshSession session(gmsh);
  int ierr = 0;
  const auto check = [&](const char* call) { Check(gmsh, ierr, call); };
  gmsh.model_add("pattern", &ierr);
  check("model add");
  int surface;
  if (outline.is_disk) {
    surface = gmsh.occ_add_disk(0, 0, 0, outline.radius, outline.radius, -1, &ierr);
    check("add disk");
  } else {
    std::vector<int> points, lines;
    for (int i = 0; i < outline.num_edges(); ++i) {
      points.push_back(
          gmsh.occ_add_point(outline.polygon(i, 0), outline.polygon(i, 1), 0, 0, -1, &ierr));
      check("add point");
    }
    for (int i = 0; i < outline.num_edges(); ++i) {
      lines.push_back(gmsh.occ_add_line(points[i], points[(i + 1) % points.size()], -1, &ierr));
      check("add line");
    }
    int loop = gmsh.occ_add_curve_loop(lines.data(), lines.size(), -1, &ierr);
    check("add curve loop");
    surface = gmsh.occ_add_plane_surface(&loop, 1, -1, &ierr);
    check("add plane surface");
  }
  // Seam segments as lines; "fragment" embeds them, splits them where they cross each other and
  // splits the boundary where they end on it.
  std::vector<int> tools;  // (dim, tag) pairs
  std::vector<int> seam_of_tool;
  for (int k = 0; k < static_cast<int>(seams.size()); ++k) {
    std::vector<int> points;
    for (int i = 0; i < seams[k].rows(); ++i) {
      points.push_back(gmsh.occ_add_point(seams[k](i, 0), seams[k](i, 1), 0, 0, -1, &ierr));
      check("add point");
    }
    for (int i = 0; i + 1 < static_cast<int>(points.size()); ++i) {
      tools.push_back(1);
      tools.push_back(gmsh.occ_add_line(points[i], points[i + 1], -1, &ierr));
      check("add line");
      seam_of_tool.push_back(k);
    }
  }
  std::vector<std::vector<int>> seam_curves(seams.size());
  if (!tools.empty()) {
    int object[2] = {2, surface};
    GmshArray<int> out(gmsh);
    GmshArrays<int> pieces(gmsh);  // per input (the object, then each tool): (dim, tag) pairs
    gmsh.occ_fragment(object, 2, tools.data(), tools.size(), &out.data, &out.size, &pieces.data,
                      &pieces.sizes, &pieces.count, -1, 1, 1, &ierr);
    check("fragment");
    for (std::size_t t = 0; t < seam_of_tool.size(); ++t) {
      if (t + 1 >= pieces.count) throw ComputeError("pattern mesh: Gmsh's fragment map is short");
      for (std::size_t j = 0; j + 1 < pieces.sizes[t + 1]; j += 2) {
        if (pieces.data[t + 1][j] == 1)
          seam_curves[seam_of_tool[t]].push_back(pieces.data[t + 1][j + 1]);
      }
    }
  }
  gmsh.occ_synchronize(&ierr);
  check("synchronize");

  for (const auto& [name, value] :
       {std::pair<const char*, double>{"Mesh.Algorithm", options.gmsh_algorithm},
        {"Mesh.MeshSizeFromPoints", 0},
        {"Mesh.MeshSizeFromCurvature", 0},
        {"Mesh.MeshSizeExtendFromBoundary", 0},
        {"Mesh.MeshSizeMax", h}}) {
    gmsh.option_set_number(name, value, &ierr);
    check(name);
  }
  SizeCallbackData size{&field, h, nullptr};
  gmsh.mesh_set_size_callback(SizeCallback, &size, &ierr);
  check("set size callback");
  gmsh.mesh_generate(2, &ierr);
  if (size.error) std::rethrow_exception(size.error);
  check("generate");

  {
    GmshArray<std::size_t> tags(gmsh);
    GmshArray<double> xyz(gmsh), parametric(gmsh);
    gmsh.mesh_get_nodes(&tags.data, &tags.size, &xyz.data, &xyz.size, &parametric.data,
                        &parametric.size, -1, -1, 0, 0, &ierr);
    check("get nodes");
    raw.node_tags.assign(tags.data, tags.data + tags.size);
    raw.node_xyz.assign(xyz.data, xyz.data + xyz.size);
  }
  {
    GmshArray<int> types(gmsh);
    GmshArrays<std::size_t> element_tags(gmsh), element_nodes(gmsh);
    gmsh.mesh_get_elements(&types.data, &types.size, &element_tags.data, &element_tags.sizes,
                           &element_tags.count, &element_nodes.data, &element_nodes.sizes,
                           &element_nodes.count, 2, -1, &ierr);
    check("get elements");
    for (std::size_t i = 0; i < types.size && i < element_nodes.count; ++i) {
      if (types.data[i] != 2) {
        throw ComputeError("pattern mesh: Gmsh returned surface elements of type " +
                           std::to_string(types.data[i]) + ", not 3-node triangles");
      }
      raw.triangle_nodes.insert(raw.triangle_nodes.end(), element_nodes.data[i],
                                element_nodes.data[i] + element_nodes.sizes[i]);
    }
  }
  raw.seam_nodes.resize(seams.size());
  for (std::size_t k = 0; k < seams.size(); ++k) {
    for (int curve : seam_curves[k]) {
      GmshArray<std::size_t> tags(gmsh);
      GmshArray<double> xyz(gmsh), parametric(gmsh);
      gmsh.mesh_get_nodes(&tags.data, &tags.size, &xyz.data, &xyz.size, &parametric.data,
                          &parametric.size, 1, curve, /*includeBoundary=*/1, 0, &ierr);
      check("get seam nodes");
      raw.seam_nodes[k].insert(raw.seam_nodes[k].end(), tags.data, tags.data + tags.size);
    }
  }
  gmsh.mesh_remove_size_callback(&ierr);
  check("remove size callback");
  return raw;
}

// Compacts Gmsh's nodes to the ones triangles use, orients triangles counter-clockwise and
// orders each seam's vertices along the seam.
PatternMesh Assemble(const RawMesh& raw, const std::vector<Polyline2>& seams, double snap) {
  std::unordered_map<std::size_t, int> node_index;
  for (std::size_t i = 0; i < raw.node_tags.size(); ++i)
    node_index[raw.node_tags[i]] = static_cast<int>(i);
  const int num_triangles = static_cast<int>(raw.triangle_nodes.size() / 3);
  if (num_triangles == 0) throw ComputeError("pattern mesh: Gmsh returned no triangles");
  std::vector<int> vertex_of_node(raw.node_tags.size(), -1);
  std::vector<std::size_t> used;
  for (std::size_t tag : raw.triangle_nodes) used.push_back(tag);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());

  PatternMesh pm;
  pm.mesh.vertices.resize(static_cast<int>(used.size()), 3);
  for (int v = 0; v < static_cast<int>(used.size()); ++v) {
    const auto it = node_index.find(used[v]);
    if (it == node_index.end())
      throw ComputeError("pattern mesh: Gmsh returned a triangle with an unknown node");
    vertex_of_node[it->second] = v;
    pm.mesh.vertices.row(v) << raw.node_xyz[3 * it->second], raw.node_xyz[3 * it->second + 1], 0.0;
  }
  pm.mesh.triangles.resize(num_triangles, 3);
  for (int f = 0; f < num_triangles; ++f) {
    for (int c = 0; c < 3; ++c)
      pm.mesh.triangles(f, c) = vertex_of_node[node_index.at(raw.triangle_nodes[3 * f + c])];
    const Vector2d a = pm.mesh.vertices.row(pm.mesh.triangles(f, 0)).head<2>().transpose();
    const Vector2d b = pm.mesh.vertices.row(pm.mesh.triangles(f, 1)).head<2>().transpose();
    const Vector2d c = pm.mesh.vertices.row(pm.mesh.triangles(f, 2)).head<2>().transpose();
    if (Cross(b - a, c - a) < 0) std::swap(pm.mesh.triangles(f, 1), pm.mesh.triangles(f, 2));
  }
  try {
    CheckMesh(pm.mesh);
  } catch (const InputError& e) {
    throw ComputeError(std::string("pattern mesh: Gmsh produced an invalid mesh: ") + e.what());
  }

  // Seams: vertices sorted by arc length along the polyline, then checked to be an edge path.
  std::unordered_set<std::uint64_t> edges;
  auto key = [](int a, int b) {
    return (std::uint64_t(std::min(a, b)) << 32) | std::uint32_t(std::max(a, b));
  };
  for (int f = 0; f < num_triangles; ++f) {
    for (int c = 0; c < 3; ++c)
      edges.insert(key(pm.mesh.triangles(f, c), pm.mesh.triangles(f, (c + 1) % 3)));
  }
  pm.vertex_seam.assign(pm.mesh.num_vertices(), -1);
  pm.seam_paths.resize(seams.size());
  for (int k = 0; k < static_cast<int>(seams.size()); ++k) {
    const Polyline2& s = seams[k];
    std::vector<double> start(s.rows(), 0.0);
    for (int i = 1; i < s.rows(); ++i) start[i] = start[i - 1] + (s.row(i) - s.row(i - 1)).norm();
    std::vector<std::pair<double, int>> along;
    for (std::size_t tag : raw.seam_nodes[k]) {
      const auto it = node_index.find(tag);
      if (it == node_index.end() || vertex_of_node[it->second] < 0) continue;
      const int v = vertex_of_node[it->second];
      const Vector2d p = pm.mesh.vertices.row(v).head<2>().transpose();
      double best = std::numeric_limits<double>::infinity(), arc = 0;
      for (int i = 0; i + 1 < s.rows(); ++i) {
        double t;
        const double d = SegmentDistance(p, s.row(i).transpose(), s.row(i + 1).transpose(), &t);
        if (d < best) best = d, arc = start[i] + t * (start[i + 1] - start[i]);
      }
      along.push_back({arc, v});
    }
    std::sort(along.begin(), along.end());
    along.erase(std::unique(along.begin(), along.end(),
                            [](const auto& a, const auto& b) { return a.second == b.second; }),
                along.end());
    std::vector<int>& path = pm.seam_paths[k];
    for (const auto& [arc, v] : along) path.push_back(v);
    const std::string name = "pattern mesh: seam " + std::to_string(k);
    const bool ends_ok =
        path.size() >= 2 &&
        (pm.mesh.vertices.row(path.front()).head<2>() - s.row(0)).norm() <= snap &&
        (pm.mesh.vertices.row(path.back()).head<2>() - s.row(s.rows() - 1)).norm() <= snap;
    if (!ends_ok)
      throw ComputeError(name + " is not an edge path of the mesh (its ends have no vertices)");
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      if (!edges.count(key(path[i], path[i + 1]))) {
        throw ComputeError(name + " is not an edge path of the mesh (vertices " +
                           std::to_string(path[i]) + " and " + std::to_string(path[i + 1]) +
                           " share no edge)");
      }
    }
    for (int v : path) {
      if (pm.vertex_seam[v] < 0) pm.vertex_seam[v] = k;
    }
  }
  return pm;
}

PatternMesh MeshOutline(const Outline& outline, const std::vector<Polyline2>& seams_in,
                        const PatternMeshOptions& options) {
  const double h = options.element_size;
  // Seam points this close to the boundary are put on it; shorter seam segments are refused.
  const double snap = std::max(1e-3 * h, 1e-9 * outline.diameter);
  const std::vector<Polyline2> seams = CheckedSeams(seams_in, outline, snap);
  const SizeField field(seams, options);
  const double estimate = EstimateTriangleCount(outline, field, h);
  if (estimate > static_cast<double>(options.max_triangles)) {
    throw InputError("pattern mesh: about " + std::to_string(std::llround(estimate)) +
                     " triangles at element size " + NumberText(h * 1e3) +
                     " mm would exceed the limit of " + std::to_string(options.max_triangles) +
                     "; use a larger element size");
  }
  PatternMesh pm = Assemble(RunGmsh(outline, seams, field, options), seams, snap);
  if (pm.mesh.num_triangles() > options.max_triangles) {
    throw InputError("pattern mesh: " + std::to_string(pm.mesh.num_triangles()) +
                     " triangles exceed the limit of " + std::to_string(options.max_triangles) +
                     "; use a larger element size");
  }
  return pm;
}

}  // namespace

bool PatternMeshOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  if (!(element_size > 0) || !std::isfinite(element_size)) {
    return fail("element_size must be a positive length in metres, got " +
                NumberText(element_size));
  }
  if (!(refinement_range >= 0))
    return fail("refinement_range must be >= 0, got " + NumberText(refinement_range));
  if (refining_lines < -1)
    return fail("refining_lines must be >= -1, got " + std::to_string(refining_lines));
  if (max_triangles < 1)
    return fail("max_triangles must be >= 1, got " + std::to_string(max_triangles));
  if (gmsh_algorithm != 1 && gmsh_algorithm != 2 && gmsh_algorithm != 5 && gmsh_algorithm != 6) {
    return fail("gmsh_algorithm must be 1, 2, 5 or 6, got " + std::to_string(gmsh_algorithm));
  }
  return true;
}

PatternMesh MeshRectangle(double width, double height, const std::vector<Polyline2>& seams,
                          const PatternMeshOptions& options) {
  CheckOptions(options);
  if (!(width > 0) || !(height > 0) || !std::isfinite(width) || !std::isfinite(height)) {
    throw InputError("pattern mesh: rectangle sides must be positive lengths, got " +
                     NumberText(width) + " × " + NumberText(height) + " m");
  }
  Polyline2 corners(4, 2);
  corners << 0, 0, width, 0, width, height, 0, height;
  return MeshOutline(PolygonOutline(corners), seams, options);
}

PatternMesh MeshDisk(double radius, const std::vector<Polyline2>& seams,
                     const PatternMeshOptions& options) {
  CheckOptions(options);
  if (!(radius > 0) || !std::isfinite(radius)) {
    throw InputError("pattern mesh: disk radius must be a positive length, got " +
                     NumberText(radius) + " m");
  }
  Outline o;
  o.is_disk = true;
  o.radius = radius;
  o.diameter = 2 * std::sqrt(2.0) * radius;
  return MeshOutline(o, seams, options);
}

PatternMesh MeshPolygon(const Polyline2& outline, const std::vector<Polyline2>& seams,
                        const PatternMeshOptions& options) {
  CheckOptions(options);
  return MeshOutline(PolygonOutline(outline), seams, options);
}

}  // namespace textile
