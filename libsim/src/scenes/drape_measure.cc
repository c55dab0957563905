#include "textile/sim/scenes/drape_measure.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "drape_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/io/json_fields.h"
#include "textile/sim/io/json_text.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
// Outline radii beyond the flat specimen's: up to this factor a note (threshold, stretch), past
// it a refusal (wrong scale or wrong specimen radius).
constexpr double kBeyondSpecimenNote = 1.02;
constexpr double kBeyondSpecimenRefuse = 1.10;

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

std::string Mm(double metres) { return NumberText(units::MToMm(metres), 4) + " mm"; }

void CheckGrid(const DrapeShadow& s, const std::string& source) {
  if (!(s.cell > 0.0) || !std::isfinite(s.cell) || !std::isfinite(s.origin_x) ||
      !std::isfinite(s.origin_y))
    throw InputError(source + ": shadow grid: the cell must be > 0 and the origin finite");
  if (s.width < 3 || s.height < 3 ||
      s.mask.size() != static_cast<size_t>(s.width) * static_cast<size_t>(s.height))
    throw InputError(source + ": shadow grid: need at least 3 × 3 cells and one mask value each");
}

// Stage 1: a covered cell on the grid's border means the shadow runs out of what was measured.
void CheckNotCut(const DrapeShadow& s, const std::string& source) {
  auto covered = [&s](int i, int j) { return s.mask[static_cast<size_t>(j) * s.width + i] != 0; };
  for (int i = 0; i < s.width; ++i)
    if (covered(i, 0) || covered(i, s.height - 1))
      throw ComputeError(source +
                         ": the outline is not a closed curve around the support: the shadow "
                         "runs out of the measured area (cut by the photo's border?)");
  for (int j = 0; j < s.height; ++j)
    if (covered(0, j) || covered(s.width - 1, j))
      throw ComputeError(source +
                         ": the outline is not a closed curve around the support: the shadow "
                         "runs out of the measured area (cut by the photo's border?)");
}

// Stage 2: in every direction the fabric must reach the support's edge (within two cells), or
// the specimen is torn, partial or off centre.
void CheckCoversSupport(const DrapeShadow& s, const DrapeMeasureOptions& o,
                        const std::string& source) {
  // Directions no finer than two cells along the support's edge, so that every one holds cell
  // centres there (finer outline bins may hold none: coarse cells, many bins).
  const int bins = std::clamp(static_cast<int>(2.0 * kPi * o.support_radius / (2.0 * s.cell)), 8,
                              o.outline_bins);
  std::vector<double> reach(bins, -1.0);
  for (int j = 0; j < s.height; ++j) {
    const double y = s.origin_y + j * s.cell;
    for (int i = 0; i < s.width; ++i) {
      if (!s.mask[static_cast<size_t>(j) * s.width + i]) continue;
      const double x = s.origin_x + i * s.cell;
      double theta = std::atan2(y, x);
      if (theta < 0.0) theta += 2.0 * kPi;
      const int b = std::min(bins - 1, static_cast<int>(theta / (2.0 * kPi) * bins));
      reach[b] = std::max(reach[b], std::hypot(x, y));
    }
  }
  const double needed = o.support_radius - 2.0 * s.cell;
  int short_bins = 0, first_short = -1;
  for (int b = 0; b < bins; ++b) {
    if (reach[b] >= needed) continue;
    if (first_short < 0) first_short = b;
    ++short_bins;
  }
  if (short_bins == 0) return;
  throw ComputeError(source + ": the outline is not a closed curve around the support: in " +
                     std::to_string(short_bins) + " of " + std::to_string(bins) +
                     " directions (the first at " +
                     NumberText((first_short + 0.5) * 360.0 / bins, 4) +
                     "°) the specimen does not reach the support's edge at " +
                     Mm(o.support_radius) +
                     " (a partial or torn specimen, or the wrong centre or scale)");
}

// Stage 4: the outline against the flat specimen's radius.
void CheckWithinSpecimen(const MeasuredDrape& m, const std::string& source,
                         std::vector<Note>* notes) {
  const double r = m.specimen_radius;
  if (m.max_radius > kBeyondSpecimenRefuse * r)
    throw InputError(source + ": the outline reaches " + Mm(m.max_radius) +
                     " from the centre, beyond the specimen's radius " + Mm(r) +
                     ": check the specimen radius (--specimen-mm) and the scale (--units, "
                     "--mm-per-px or --rig)");
  if (m.max_radius > kBeyondSpecimenNote * r)
    notes->push_back({"beyond_specimen", "the outline reaches " + Mm(m.max_radius) +
                                             ", beyond the flat specimen's radius " + Mm(r) +
                                             ": a stretched specimen or a loose scale"});
}

}  // namespace

bool DrapeMeasureOptions::Check(std::string* why) const {
  if (!(std::isfinite(support_radius) && support_radius > 0.0))
    return Fail(why, "support radius: must be > 0");
  if (!(std::isfinite(specimen_radius) && specimen_radius > support_radius))
    return Fail(why, "specimen radius: must be larger than the support's");
  if (!(std::isfinite(raster_cell) && raster_cell > 0.0 && raster_cell <= 0.05 * support_radius))
    return Fail(why, "raster cell: must be > 0 and at most 5 % of the support radius");
  if (outline_bins < 8 || outline_bins > 100000)
    return Fail(why, "outline bins: must be between 8 and 100000");
  if (smoothing_bins < 1 || smoothing_bins % 2 == 0 || smoothing_bins > outline_bins)
    return Fail(why, "smoothing bins: must be odd and between 1 and the outline bins");
  if (!(std::isfinite(node_prominence) && node_prominence >= 0.0))
    return Fail(why, "node prominence: must be >= 0");
  if (!(std::isfinite(node_prominence_relative) && node_prominence_relative >= 0.0 &&
        node_prominence_relative < 1.0))
    return Fail(why, "relative node prominence: must lie in [0, 1)");
  return true;
}

DrapeMeasureOptions MeasureOptionsOf(const DrapeOptions& o) {
  DrapeMeasureOptions m;
  m.specimen_radius = o.specimen_radius;
  m.support_radius = o.support_radius;
  m.raster_cell = o.raster_cell;
  m.outline_bins = o.outline_bins;
  m.smoothing_bins = o.smoothing_bins;
  m.node_prominence = o.node_prominence;
  m.node_prominence_relative = o.node_prominence_relative;
  return m;
}

MeasuredDrape MeasureDrapeShadow(DrapeShadow fabric, const DrapeMeasureOptions& o,
                                 const std::string& source) {
  if (std::string why; !o.Check(&why)) throw InputError(source + ": " + why);
  CheckGrid(fabric, source);
  CheckNotCut(fabric, source);
  CheckCoversSupport(fabric, o, source);
  MeasuredDrape m;
  m.source = source;
  m.specimen_radius = o.specimen_radius;
  m.support_radius = o.support_radius;
  m.shadow = std::move(fabric);
  m.shadow.area = 0.0;
  m.shadow.bare_support_area = 0.0;
  drape_internal::AddSupportShadow(o.support_radius, &m.shadow);
  drape_internal::FloodFromBorder(&m.shadow);
  drape_internal::MeasureOutline(o.outline_bins, &m.shadow);
  drape_internal::FillEmptyBins(&m.shadow.radii);
  m.drape_coefficient = DrapeCoefficient(m.shadow.area, kPi * o.specimen_radius * o.specimen_radius,
                                         kPi * o.support_radius * o.support_radius);
  m.nodes = FindNodes(m.shadow.radii, o.smoothing_bins, o.node_prominence,
                      o.node_prominence_relative);
  m.min_radius = m.shadow.radii.minCoeff();
  m.max_radius = m.shadow.radii.maxCoeff();
  m.mean_radius = m.shadow.radii.mean();
  CheckWithinSpecimen(m, source, &m.notes);
  return m;
}

std::string MeshUpAxisName(MeshUpAxis up) { return up == MeshUpAxis::kY ? "y" : "z"; }

MeshUpAxis ParseMeshUpAxis(const std::string& s) {
  if (s == "z") return MeshUpAxis::kZ;
  if (s == "y") return MeshUpAxis::kY;
  throw InputError("vertical axis: '" + s + "' is not z or y");
}

bool DrapeMeshOptions::Check(std::string* why) const {
  if (!measure.Check(why)) return false;
  if (!(std::isfinite(metres_per_unit) && metres_per_unit > 0.0))
    return Fail(why, "unit: must be > 0 metres");
  if (centre && !centre->allFinite()) return Fail(why, "centre: must be finite");
  if (!(std::isfinite(plateau_tolerance) && plateau_tolerance > 0.0))
    return Fail(why, "plateau tolerance: must be > 0");
  if (!(std::isfinite(max_tilt) && max_tilt > 0.0 && max_tilt < kPi / 2.0))
    return Fail(why, "largest tilt: must lie in (0, 90°)");
  return true;
}

Vertices MeshInMeasureFrame(const TriangleMesh& draped, const DrapeMeshOptions& o,
                            const std::string& source) {
  if (draped.num_triangles() == 0)
    throw InputError(source + ": the mesh has no faces (" + std::to_string(draped.num_vertices()) +
                     " vertices): nothing casts a shadow");
  for (int v = 0; v < draped.num_vertices(); ++v)
    if (!draped.vertices.row(v).allFinite())
      throw InputError(source + ": vertex " + std::to_string(v) +
                       " has a NaN or infinite coordinate");
  if (draped.triangles.minCoeff() < 0 || draped.triangles.maxCoeff() >= draped.num_vertices())
    throw InputError(source + ": a face's vertex index is out of range (" +
                     std::to_string(draped.num_vertices()) + " vertices)");
  Vertices f(draped.num_vertices(), 3);
  const double s = o.metres_per_unit;
  for (int v = 0; v < draped.num_vertices(); ++v) {
    const double x = draped.vertices(v, 0), y = draped.vertices(v, 1), z = draped.vertices(v, 2);
    if (o.up == MeshUpAxis::kZ)
      f.row(v) << s * x, s * y, s * z;
    else
      f.row(v) << s * x, -s * z, s * y;
  }
  return f;
}

void CheckMeshScale(const Vertices& f, const DrapeMeshOptions& o, const std::string& source) {
  const double span = std::max(f.col(0).maxCoeff() - f.col(0).minCoeff(),
                               f.col(1).maxCoeff() - f.col(1).minCoeff());
  const double diameter = 2.0 * o.measure.specimen_radius;
  const bool metres = o.metres_per_unit == 1.0;
  if (span > 3.0 * diameter)
    throw InputError(source + ": the mesh spans " + Mm(span) + " across, " +
                     NumberText(span / diameter, 3) + " times the specimen's diameter " +
                     Mm(diameter) +
                     (metres ? ": is it in millimetres (--units mm)?"
                             : ": check its units (--units) and the specimen (--specimen-mm)"));
  if (span < o.measure.support_radius)
    throw InputError(source + ": the mesh spans only " + Mm(span) +
                     " across, under half the support's diameter " +
                     Mm(2.0 * o.measure.support_radius) +
                     (metres ? ": check its units (--units) and the support (--support-mm)"
                             : ": is it in metres (--units m)?"));
}

namespace {

// The top's height: the highest h such that the faces whose highest corner lies at h or above
// cover kTopArea of the support's area (projected), so that a scan's stray faces and spikes
// (a few small faces) above the fabric do not set it, while a coarse mesh's large faces do.
constexpr double kTopArea = 0.02;
double TopHeight(const Vertices& f, const Triangles& triangles, double support_radius) {
  std::vector<std::pair<double, double>> faces(static_cast<size_t>(triangles.rows()));
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const auto a = f.row(triangles(t, 0)), b = f.row(triangles(t, 1)), c = f.row(triangles(t, 2));
    const double area =
        0.5 * std::abs((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
    faces[t] = {std::max({a.z(), b.z(), c.z()}), area};
  }
  if (faces.empty()) return f.col(2).maxCoeff();
  const auto higher = [](const auto& p, const auto& q) { return p.first > q.first; };
  // The highest tenth of the faces in order first (they nearly always reach kTopArea); the rest
  // only when they do not: a full sort of 500k faces took about 0.01 s of each call.
  const auto tenth =
      faces.begin() + static_cast<std::ptrdiff_t>(std::max<size_t>(1, faces.size() / 10));
  std::nth_element(faces.begin(), tenth - 1, faces.end(), higher);
  std::sort(faces.begin(), tenth, higher);
  const double wanted = kTopArea * kPi * support_radius * support_radius;
  double covered = 0.0;
  for (auto it = faces.begin(); it != faces.end(); ++it) {
    if (it == tenth) std::sort(tenth, faces.end(), higher);
    covered += it->second;
    if (covered >= wanted) return it->first;
  }
  return faces.back().first;
}

// The top's vertices: at most `tolerance` below the top's height, and at most as far above it
// (a spike's tip is left out of the plane fit; `all_above` keeps it, for the top's faces).
std::vector<int> TopVertices(const Vertices& f, double top, double tolerance, bool all_above) {
  std::vector<int> vertices;
  for (int v = 0; v < f.rows(); ++v)
    if (f(v, 2) >= top - tolerance && (all_above || f(v, 2) <= top + tolerance))
      vertices.push_back(v);
  return vertices;
}

// The plane h = a x + b y + c through `top` by least squares: its upward unit normal and the
// vertices' mean; false when they do not span a plane.
bool FitTopPlane(const Vertices& f, const std::vector<int>& top, Eigen::Vector3d* normal,
                 Eigen::Vector3d* mean) {
  if (top.size() < 3) return false;
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (int v : top) m += f.row(v).transpose();
  m /= static_cast<double>(top.size());
  Eigen::Matrix3d normal_eq = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int v : top) {
    const Eigen::Vector3d d = f.row(v).transpose() - m;
    const Eigen::Vector3d row(d.x(), d.y(), 1.0);
    normal_eq += row * row.transpose();
    rhs += row * d.z();
  }
  Eigen::LDLT<Eigen::Matrix3d> ldlt(normal_eq);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12)) return false;
  const Eigen::Vector3d abc = ldlt.solve(rhs);
  if (!abc.allFinite()) return false;
  *normal = Eigen::Vector3d(-abc.x(), -abc.y(), 1.0).normalized();
  *mean = m;
  return true;
}

std::string Settle() {
  return " (a tilted mesh, or one whose vertical axis is y: --up y; or give the support's centre "
         "with --centre-mm)";
}

}  // namespace

MeshLevelling LevelMeshTop(Vertices* f, const Triangles& triangles, const DrapeMeshOptions& o,
                           const std::string& source) {
  MeshLevelling l;
  Eigen::Vector3d normal, mean;
  for (int round = 0; round < 6; ++round) {
    const double top = TopHeight(*f, triangles, o.measure.support_radius);
    if (!FitTopPlane(*f, TopVertices(*f, top, o.plateau_tolerance, false), &normal, &mean)) break;
    const double slope = std::acos(std::clamp(normal.z(), -1.0, 1.0));
    if (round == 0 && slope < kLevelBelow) return l;  // level enough: the input's own frame
    if (slope < 1e-9) break;
    // Turn the top's normal to vertical about the top's mean.
    const Eigen::Matrix3d q =
        Eigen::Quaterniond::FromTwoVectors(normal, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    for (Eigen::Index v = 0; v < f->rows(); ++v)
      f->row(v) = (mean + q * (f->row(v).transpose() - mean)).transpose();
    l.rotation = q * l.rotation;
    l.translation = q * (l.translation - mean) + mean;
    l.levelled = true;
  }
  l.tilt = std::acos(std::clamp(l.rotation(2, 2), -1.0, 1.0));
  if (l.tilt > o.max_tilt)
    throw InputError(source + ": the mesh's flat top slopes by " + NumberText(l.tilt / kDegree, 3) +
                     "°, over " + NumberText(o.max_tilt / kDegree, 3) + "°" + Settle());
  return l;
}

MeshSupportCentre FindMeshSupportCentre(const Vertices& f, const Triangles& triangles,
                                        const DrapeMeshOptions& o, const std::string& source) {
  MeshSupportCentre c;
  if (o.centre) {
    c.centre = *o.centre;
    c.from = "given";
    return c;
  }
  std::vector<char> on_top(static_cast<size_t>(f.rows()), 0);
  const double top = TopHeight(f, triangles, o.measure.support_radius);
  for (int v : TopVertices(f, top, o.plateau_tolerance, true)) on_top[v] = 1;
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  for (int t = 0; t < triangles.rows(); ++t) {
    const int a = triangles(t, 0), b = triangles(t, 1), d = triangles(t, 2);
    if (!on_top[a] || !on_top[b] || !on_top[d]) continue;
    const Eigen::Vector2d pa = f.row(a).head<2>(), pb = f.row(b).head<2>(), pd = f.row(d).head<2>();
    const Eigen::Vector2d u = pb - pa, w = pd - pa;
    const double area = 0.5 * std::abs(u.x() * w.y() - u.y() * w.x());
    c.plateau_area += area;
    moment += area * (pa + pb + pd) / 3.0;
  }
  const double support_area = kPi * o.measure.support_radius * o.measure.support_radius;
  if (c.plateau_area < 0.5 * support_area)
    throw InputError(source + ": no flat top the size of the support: the faces within " +
                     Mm(o.plateau_tolerance) + " of the top cover " +
                     NumberText(c.plateau_area * 1e6, 5) + " mm², under half the support's " +
                     NumberText(support_area * 1e6, 5) + " mm²" + Settle());
  c.centre = moment / c.plateau_area;
  c.from = "plateau";
  if (c.centre.norm() <= kOriginSnap) {
    c.centre.setZero();
    c.from = "origin";
  }
  return c;
}

namespace {

// The cells whose centres the projected triangle (a, b, c) covers (edge functions, inclusive:
// a cell centre on a shared edge belongs to both triangles), with the grid's frame.
void CoverTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   DrapeShadow* s) {
  const double area2 = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  if (area2 == 0.0) return;  // edge-on: its neighbours cover its line
  const double sign = area2 > 0.0 ? 1.0 : -1.0;
  const double inv = 1.0 / s->cell;
  auto index = [inv](double v, double origin) { return (v - origin) * inv; };
  const int i0 =
      std::max(0, static_cast<int>(std::ceil(index(std::min({a.x(), b.x(), c.x()}), s->origin_x))));
  const int i1 =
      std::min(s->width - 1,
               static_cast<int>(std::floor(index(std::max({a.x(), b.x(), c.x()}), s->origin_x))));
  const int j0 =
      std::max(0, static_cast<int>(std::ceil(index(std::min({a.y(), b.y(), c.y()}), s->origin_y))));
  const int j1 =
      std::min(s->height - 1,
               static_cast<int>(std::floor(index(std::max({a.y(), b.y(), c.y()}), s->origin_y))));
  auto edge = [sign](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double px, double py) {
    return sign * ((q.x() - p.x()) * (py - p.y()) - (q.y() - p.y()) * (px - p.x()));
  };
  for (int j = j0; j <= j1; ++j) {
    const double py = s->origin_y + j * s->cell;
    std::uint8_t* row = s->mask.data() + static_cast<size_t>(j) * s->width;
    for (int i = i0; i <= i1; ++i) {
      const double px = s->origin_x + i * s->cell;
      if (edge(a, b, px, py) >= 0.0 && edge(b, c, px, py) >= 0.0 && edge(c, a, px, py) >= 0.0)
        row[i] = 1;
    }
  }
}

}  // namespace

DrapeShadow RasteriseFabric(const Vertices& f, const Triangles& triangles,
                            const Eigen::Vector2d& centre, double cell, double support_radius) {
  DrapeShadow s;
  s.cell = cell;
  const double lo_x = std::min(f.col(0).minCoeff() - centre.x(), -support_radius);
  const double hi_x = std::max(f.col(0).maxCoeff() - centre.x(), support_radius);
  const double lo_y = std::min(f.col(1).minCoeff() - centre.y(), -support_radius);
  const double hi_y = std::max(f.col(1).maxCoeff() - centre.y(), support_radius);
  const double cells_x = (hi_x - lo_x) / cell, cells_y = (hi_y - lo_y) / cell;
  if (!(cells_x * cells_y <= 1e8))
    throw InputError("shadow: the projection spans over 1e8 raster cells");
  s.width = static_cast<int>(std::ceil(cells_x)) + 5;
  s.height = static_cast<int>(std::ceil(cells_y)) + 5;
  s.origin_x = lo_x - 2.0 * cell;
  s.origin_y = lo_y - 2.0 * cell;
  s.mask.assign(static_cast<size_t>(s.width) * s.height, 0);
  auto at = [&](int v) { return Eigen::Vector2d(f(v, 0) - centre.x(), f(v, 1) - centre.y()); };
  for (int t = 0; t < triangles.rows(); ++t)
    CoverTriangle(at(triangles(t, 0)), at(triangles(t, 1)), at(triangles(t, 2)), &s);
  return s;
}

namespace {

// The vertices some face uses, the faces renumbered: a scan's stray points (no face) cast no
// shadow and must not set the span, the top or the grid.
TriangleMesh UsedPart(const TriangleMesh& mesh) {
  std::vector<int> id(static_cast<size_t>(mesh.num_vertices()), -1);
  int used = 0;
  for (int t = 0; t < mesh.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.triangles(t, c);
      if (v >= 0 && v < mesh.num_vertices() && id[v] < 0) id[v] = used++;
    }
  if (used == mesh.num_vertices()) return mesh;
  TriangleMesh part;
  part.vertices.resize(used, 3);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (id[v] >= 0) part.vertices.row(id[v]) = mesh.vertices.row(v);
  part.triangles.resize(mesh.num_triangles(), 3);
  for (int t = 0; t < mesh.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) part.triangles(t, c) = id[mesh.triangles(t, c)];
  return part;
}

}  // namespace

MeasuredDrape MeasureDrapeMesh(const TriangleMesh& input, const DrapeMeshOptions& o,
                               const std::string& source) {
  if (std::string why; !o.Check(&why)) throw InputError(source + ": " + why);
  if (input.num_triangles() > 0 &&
      (input.triangles.minCoeff() < 0 || input.triangles.maxCoeff() >= input.num_vertices()))
    throw InputError(source + ": a face's vertex index is out of range (" +
                     std::to_string(input.num_vertices()) + " vertices)");
  const TriangleMesh draped = UsedPart(input);
  Vertices frame = MeshInMeasureFrame(draped, o, source);
  CheckMeshScale(frame, o, source);
  const MeshLevelling level =
      o.centre ? MeshLevelling{} : LevelMeshTop(&frame, draped.triangles, o, source);
  const MeshSupportCentre c = FindMeshSupportCentre(frame, draped.triangles, o, source);
  MeasuredDrape m =
      MeasureDrapeShadow(RasteriseFabric(frame, draped.triangles, c.centre, o.measure.raster_cell,
                                         o.measure.support_radius),
                         o.measure, source);
  m.input_kind = "mesh";
  m.centre = c.centre;
  m.centre_from = c.from;
  if (level.levelled)
    m.notes.push_back({"levelled", "the mesh's flat top sloped by " +
                                       NumberText(level.tilt / kDegree, 3) +
                                       "°: it was levelled about the top's centre before the "
                                       "projection (centre_mm is in the levelled frame)"});
  return m;
}

TriangleMesh SyntheticDrapeMesh(double R, double Rs, int rings, int sectors,
                                const std::function<double(double)>& outline_radius) {
  if (!(Rs > 0.0 && R > Rs) || rings < 2 || sectors < 8 || sectors > 1000000 || rings > 100000)
    throw InputError("synthetic drape: need 0 < R_s < R, at least 2 rings and 8 sectors");
  const int inside = std::clamp(static_cast<int>(std::lround(rings * Rs / R)), 1, rings - 1);
  auto ring_radius = [&](int k) {
    return k <= inside ? Rs * k / inside : Rs + (R - Rs) * (k - inside) / (rings - inside);
  };
  TriangleMesh m;
  m.vertices.resize(1 + static_cast<Eigen::Index>(rings) * sectors, 3);
  m.vertices.row(0).setZero();
  for (int s = 0; s < sectors; ++s) {
    const double theta = 2.0 * kPi * s / sectors;
    const double rim = outline_radius(theta);
    if (!(rim > Rs && rim <= R))
      throw InputError("synthetic drape: the outline must lie in (R_s, R] at every angle");
    const double drop = std::sqrt(std::max(0.0, (R - Rs) * (R - Rs) - (rim - Rs) * (rim - Rs)));
    for (int k = 1; k <= rings; ++k) {
      const double r = ring_radius(k);
      const double t = r <= Rs ? 0.0 : (r - Rs) / (R - Rs);  // along the skirt, 0 .. 1
      const double rho = r <= Rs ? r : Rs + t * (rim - Rs);
      m.vertices.row(1 + static_cast<Eigen::Index>(k - 1) * sectors + s) << rho * std::cos(theta),
          rho * std::sin(theta), -t * drop;
    }
  }
  auto id = [sectors](int k, int s) { return 1 + (k - 1) * sectors + (s % sectors); };
  m.triangles.resize(static_cast<Eigen::Index>(sectors) * (2 * rings - 1), 3);
  Eigen::Index f = 0;
  for (int s = 0; s < sectors; ++s) m.triangles.row(f++) << 0, id(1, s), id(1, s + 1);
  for (int k = 1; k < rings; ++k)
    for (int s = 0; s < sectors; ++s) {
      m.triangles.row(f++) << id(k, s), id(k + 1, s), id(k + 1, s + 1);
      m.triangles.row(f++) << id(k, s), id(k + 1, s + 1), id(k, s + 1);
    }
  return m;
}

std::string OutlineCsv(const DrapeShadow& s) {
  std::ostringstream out;
  out.precision(10);
  out << "theta_deg,r_mm,x_mm,y_mm\n";
  for (int b = 0; b < s.angles.size(); ++b) {
    const double t = s.angles(b), r = s.radii(b);
    out << t / kDegree << "," << units::MToMm(r) << "," << units::MToMm(r * std::cos(t)) << ","
        << units::MToMm(r * std::sin(t)) << "\n";
  }
  return out.str();
}

std::string MeasuredDrapeJson(const MeasuredDrape& m) {
  nlohmann::json j;
  j["format"] = "textile-measured-drape";
  j["version"] = 1;
  j["source"] = m.source;
  j["input"] = m.input_kind;
  j["drape_coefficient"] = m.drape_coefficient;
  j["nodes"] = m.nodes.angles.size();
  nlohmann::json nodes = nlohmann::json::array();
  for (size_t k = 0; k < m.nodes.angles.size(); ++k)
    nodes.push_back({{"angle_deg", m.nodes.angles[k] / kDegree},
                     {"radius_mm", units::MToMm(m.nodes.radii[k])},
                     {"prominence_mm", units::MToMm(m.nodes.prominences[k])}});
  j["node_list"] = nodes;
  j["shadow_area_mm2"] = m.shadow.area * 1e6;
  j["min_radius_mm"] = units::MToMm(m.min_radius);
  j["max_radius_mm"] = units::MToMm(m.max_radius);
  j["mean_radius_mm"] = units::MToMm(m.mean_radius);
  j["specimen_radius_mm"] = units::MToMm(m.specimen_radius);
  j["support_radius_mm"] = units::MToMm(m.support_radius);
  j["raster_cell_mm"] = units::MToMm(m.shadow.cell);
  j["centre_mm"] = {units::MToMm(m.centre.x()), units::MToMm(m.centre.y())};
  j["centre_from"] = m.centre_from;
  j["notes"] = NotesJson(m.notes);
  nlohmann::json theta = nlohmann::json::array(), radius = nlohmann::json::array();
  for (int b = 0; b < m.shadow.angles.size(); ++b) {
    theta.push_back(m.shadow.angles(b) / kDegree);
    radius.push_back(units::MToMm(m.shadow.radii(b)));
  }
  j["outline"] = {{"theta_deg", theta}, {"r_mm", radius}};
  return j.dump(2) + "\n";
}

MeasuredDrape ParseMeasuredDrapeJson(const std::string& text, const std::string& source) {
  const nlohmann::json root = ParseJsonText(text, source);
  const JsonFields f(source);
  f.RequireObject(root);
  const std::string format = f.String(
      f.Require(root, "format", "a measured drape from `textile drape-measure`"), "format");
  if (format != "textile-measured-drape")
    f.Unknown("format", "format", format, "\"textile-measured-drape\"");
  const double version = f.Number(f.Require(root, "version"), "version");
  if (version != 1.0) f.Must("version", "be 1", root["version"]);

  MeasuredDrape m;
  m.source = root.contains("source") ? f.String(root["source"], "source") : source;
  m.input_kind = root.contains("input") ? f.String(root["input"], "input") : "";
  m.drape_coefficient = f.Number(f.Require(root, "drape_coefficient"), "drape_coefficient");
  if (!(m.drape_coefficient >= 0.0 && m.drape_coefficient <= 1.2))
    f.Must("drape_coefficient", "lie in [0, 1.2]", root["drape_coefficient"]);
  m.specimen_radius =
      units::MmToM(f.Number(f.Require(root, "specimen_radius_mm"), "specimen_radius_mm"));
  m.support_radius =
      units::MmToM(f.Number(f.Require(root, "support_radius_mm"), "support_radius_mm"));
  if (!(m.support_radius > 0.0))
    f.Must("support_radius_mm", "be > 0", root["support_radius_mm"]);
  if (!(m.specimen_radius > m.support_radius))
    f.Must("specimen_radius_mm", "be larger than support_radius_mm", root["specimen_radius_mm"]);

  const nlohmann::json& list = f.Require(root, "node_list");
  if (!list.is_array()) f.Must("node_list", "be an array of nodes", list);
  for (size_t k = 0; k < list.size(); ++k) {
    const std::string at = JsonFields::Element("node_list", k);
    const nlohmann::json& n = f.Object(list[k], at, "{\"angle_deg\", \"radius_mm\", ...}");
    m.nodes.angles.push_back(f.Number(f.Require(n, "angle_deg", "", at + ".angle_deg"),
                                      at + ".angle_deg") *
                             kDegree);
    m.nodes.radii.push_back(
        units::MmToM(f.Number(f.Require(n, "radius_mm", "", at + ".radius_mm"), at + ".radius_mm")));
    m.nodes.prominences.push_back(
        n.contains("prominence_mm") ? units::MmToM(f.Number(n["prominence_mm"], at + ".prominence_mm"))
                                    : 0.0);
  }

  const nlohmann::json& outline =
      f.Object(f.Require(root, "outline"), "outline", "{\"theta_deg\", \"r_mm\"}");
  const std::vector<double> theta =
      f.Numbers(f.Require(outline, "theta_deg", "", "outline.theta_deg"), "outline.theta_deg");
  const std::vector<double> radius =
      f.Numbers(f.Require(outline, "r_mm", "", "outline.r_mm"), "outline.r_mm");
  if (theta.size() < 8 || theta.size() != radius.size())
    f.Must("outline", "hold at least 8 angles and as many radii", outline);
  const double step = 360.0 / static_cast<double>(theta.size());
  m.shadow.angles.resize(static_cast<Eigen::Index>(theta.size()));
  m.shadow.radii.resize(static_cast<Eigen::Index>(theta.size()));
  for (size_t b = 0; b < theta.size(); ++b) {
    // Uniform bins from 0 (FindNodes' and the comparison's convention).
    if (std::abs(theta[b] - (static_cast<double>(b) + 0.5) * step) > 1e-6 * step)
      f.Must(JsonFields::Element("outline.theta_deg", b),
             "be the centre of uniform bins from 0° (" + NumberText((b + 0.5) * step) + ")",
             outline["theta_deg"][b]);
    if (!(radius[b] > 0.0))
      f.Must(JsonFields::Element("outline.r_mm", b), "be > 0", outline["r_mm"][b]);
    m.shadow.angles(static_cast<Eigen::Index>(b)) = theta[b] * kDegree;
    m.shadow.radii(static_cast<Eigen::Index>(b)) = units::MmToM(radius[b]);
  }
  m.min_radius = m.shadow.radii.minCoeff();
  m.max_radius = m.shadow.radii.maxCoeff();
  m.mean_radius = m.shadow.radii.mean();
  if (root.contains("shadow_area_mm2"))
    m.shadow.area = f.Number(root["shadow_area_mm2"], "shadow_area_mm2") * 1e-6;
  if (root.contains("centre_mm")) {
    const auto c = f.FixedNumbers<2>(root["centre_mm"], "centre_mm", "[x, y]");
    m.centre = {units::MmToM(c[0]), units::MmToM(c[1])};
  }
  if (root.contains("centre_from")) m.centre_from = f.String(root["centre_from"], "centre_from");
  if (root.contains("notes")) {
    const nlohmann::json& notes = root["notes"];
    if (!notes.is_array()) f.Must("notes", "be an array of {\"code\", \"text\"}", notes);
    for (size_t k = 0; k < notes.size(); ++k) {
      const std::string at = JsonFields::Element("notes", k);
      const nlohmann::json& n = f.Object(notes[k], at, "{\"code\", \"text\"}");
      m.notes.push_back({f.String(f.Require(n, "code", "", at + ".code"), at + ".code"),
                         f.String(f.Require(n, "text", "", at + ".text"), at + ".text")});
    }
  }
  return m;
}

}  // namespace textile
