#include "textile/sim/scenes/drape.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <sstream>

#include "drape_stages.h"
#include "textile/sim/scenes/drape_measure.h"
#include "textile/sim/solve/cloth_problem.h"
#include "textile/sim/elements/contact.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/mesh/pattern_mesh.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

bool Finite(double v) { return std::isfinite(v); }

// A chord of the specimen through the point at distance `offset` from the centre along
// `normal_angle`, running along the direction `angle` [rad]; its ends lie on the rim.
SeamLine Chord(double radius, double angle, double offset) {
  const double half = std::sqrt(radius * radius - offset * offset);
  const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
  const Eigen::Vector2d normal(-dir.y(), dir.x());
  SeamLine line(2, 2);
  line.row(0) = (offset * normal - half * dir).transpose();
  line.row(1) = (offset * normal + half * dir).transpose();
  return line;
}

// The frame angle reduced to (-π, π] (exactly: std::remainder is exact), so that a huge angle
// (1e17°) is a rotation like any other rather than cos/sin of a number with no digits left.
double Frame(const DrapeOptions& o) { return std::remainder(o.frame_angle, 2.0 * kPi); }

// The support circle as an open polyline covering all but one segment (so that no two embedded
// lines share an end point); starting half a segment off the axes, where seams run.
Polyline2 SupportCircle(double radius, int segments, double frame) {
  Polyline2 circle(segments, 2);
  const double step = 2.0 * kPi / segments;
  const double start = frame + 0.5 * step + 0.0123;
  for (int i = 0; i < segments; ++i) {
    circle(i, 0) = radius * std::cos(start + i * step);
    circle(i, 1) = radius * std::sin(start + i * step);
  }
  return circle;
}

int CircleSegments(const DrapeOptions& o, double element_size) {
  if (o.circle_segments > 0) return o.circle_segments;
  return std::max(24, static_cast<int>(std::ceil(2.0 * kPi * o.support_radius / element_size)));
}

struct Pattern {
  PatternMesh pm;
  std::vector<int> clamp;  // vertices held by the clamp (r ≤ R_s)
};

// The vertices within the support's circle (held by a clamped mount). The circle's polyline
// vertices lie at R_s up to round-off; midpoints of its chords (a split rim) lie inside.
std::vector<int> ClampedVertices(const TriangleMesh& mesh, const DrapeOptions& o) {
  std::vector<int> clamp;
  const double limit = o.support_radius * (1.0 + 1e-9);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (mesh.vertices.row(v).head<2>().norm() <= limit) clamp.push_back(v);
  return clamp;
}

// The mesh at `scale` × the options' sizes (1: the fine mesh; coarse_factor: the coarse one).
Pattern MeshPattern(const DrapeOptions& o, const std::vector<Seam>& seams, double scale) {
  const double element_size = scale * o.element_size;
  const double rim = scale * o.rim_element_size;  // 0: no rim band
  std::vector<Polyline2> lines;
  for (const Seam& s : seams) lines.push_back(Polyline2(s.line));
  lines.push_back(
      SupportCircle(o.support_radius, CircleSegments(o, rim > 0.0 ? rim : element_size), Frame(o)));
  PatternMeshOptions mo;
  mo.element_size = element_size;
  if (rim > 0.0) {
    // At most `rim` from one rim element inside the support out to rim_band beyond it, then
    // growing by half the distance (a grading the mesher follows without slivers).
    const double inner = o.support_radius - rim, outer = o.support_radius + o.rim_band;
    mo.max_size = [rim, inner, outer](double x, double y) {
      const double r = std::hypot(x, y);
      return rim + 0.5 * std::max({0.0, inner - r, r - outer});
    };
  }
  if (!seams.empty() && o.seam_refinement_range > 0.0) {
    std::vector<SeamProfile> profiles;
    for (const Seam& s : seams) profiles.push_back(s.profile);
    mo.area_factor = SeamAreaFactor(profiles);
    mo.refinement_range = o.seam_refinement_range;
    mo.refining_lines = static_cast<int>(seams.size());  // not near the support circle
  }
  Pattern p;
  p.pm = MeshDisk(o.specimen_radius, lines, mo);
  p.clamp = ClampedVertices(p.pm.mesh, o);
  return p;
}

// The rim band's triangles split in four (rim extrapolation): those whose centroid lies from
// 1.5 rim elements inside the support's circle to rim_band beyond it. Seam paths follow.
Pattern SplitRim(const Pattern& base, const DrapeOptions& o, RefinedMesh* refined) {
  const TriangleMesh& m = base.pm.mesh;
  std::vector<bool> marked(static_cast<size_t>(m.num_triangles()), false);
  const double inner = o.support_radius - 1.5 * o.rim_element_size;
  const double outer = o.support_radius + o.rim_band;
  for (int f = 0; f < m.num_triangles(); ++f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += m.vertices.row(m.triangles(f, k)).transpose() / 3.0;
    const double r = c.head<2>().norm();
    marked[static_cast<size_t>(f)] = r >= inner && r <= outer;
  }
  *refined = RefineTriangles(m, marked);
  Pattern p;
  p.pm.mesh = refined->mesh;
  std::map<std::pair<int, int>, int> midpoint;
  const int nv = m.num_vertices();
  for (size_t i = 0; i < refined->parents.size(); ++i)
    midpoint[{refined->parents[i][0], refined->parents[i][1]}] = nv + static_cast<int>(i);
  p.pm.vertex_seam = base.pm.vertex_seam;
  p.pm.vertex_seam.resize(static_cast<size_t>(p.pm.mesh.num_vertices()), -1);
  for (size_t k = 0; k < base.pm.seam_paths.size(); ++k) {
    const std::vector<int>& path = base.pm.seam_paths[k];
    std::vector<int> out;
    for (size_t i = 0; i < path.size(); ++i) {
      if (i > 0) {
        const auto it =
            midpoint.find({std::min(path[i - 1], path[i]), std::max(path[i - 1], path[i])});
        if (it != midpoint.end()) {
          out.push_back(it->second);
          if (p.pm.vertex_seam[static_cast<size_t>(it->second)] < 0)
            p.pm.vertex_seam[static_cast<size_t>(it->second)] = static_cast<int>(k);
        }
      }
      out.push_back(path[i]);
    }
    p.pm.seam_paths.push_back(std::move(out));
  }
  p.clamp = ClampedVertices(p.pm.mesh, o);
  return p;
}

// The seeded start: flat (resting: drop_height up) plus the smooth wave on the overhang.
Vertices StartState(const TriangleMesh& mesh, const DrapeOptions& o, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(-1.0, 1.0), phase(0.0, 2.0 * kPi);
  std::vector<double> c, phi;
  double total = 0.0;
  for (int k = o.min_harmonic; k <= o.max_harmonic; ++k) {
    c.push_back(weight(rng));
    phi.push_back(phase(rng));
    total += std::abs(c.back());
  }
  Vertices x = mesh.vertices;
  const double lift = o.mount == DrapeMount::kResting ? o.drop_height : 0.0;
  const double overhang = o.specimen_radius - o.support_radius;
  for (int v = 0; v < x.rows(); ++v) {
    const double r = std::hypot(x(v, 0), x(v, 1));
    x(v, 2) = lift;
    if (r <= o.support_radius || total == 0.0) continue;
    const double theta = std::atan2(x(v, 1), x(v, 0)) - Frame(o);
    double w = 0.0;
    for (size_t i = 0; i < c.size(); ++i)
      w += c[i] * std::cos((o.min_harmonic + static_cast<int>(i)) * theta + phi[i]);
    const double t = (r - o.support_radius) / overhang;
    const double s = r - o.support_radius;
    const double scale = (o.support_radius + s * std::cos(o.start_droop)) / r;
    x(v, 0) *= scale;
    x(v, 1) *= scale;
    x(v, 2) += -s * std::sin(o.start_droop) + o.perturbation * t * t * w / total;
  }
  return x;
}

// The resting mount's disk: its top face at z = 0, centred on the specimen.
Support RestingSupport(const DrapeOptions& o) {
  return Support::Disk(Eigen::Vector3d::Zero(), o.support_radius, o.support_thickness,
                       o.rim_rounding);
}

std::unique_ptr<ClothProblem> MakeProblem(const Pattern& p, const Material& material,
                                          const std::vector<Seam>& seams, const DrapeOptions& o) {
  ClothOptions co;
  co.contact.friction = material.friction;
  co.contact.sink_under_own_weight = o.contact_sink;
  // Resting mount: Coulomb friction as a potential with lagged normal forces (contact.h).
  // Slip between converged stretches (lagged_slip) settled only with μ = 3 and without the rim
  // band, per-step stick/slip switching not at all (docs/methods/drapemeter.md, "Limits").
  co.contact.friction_potential = o.mount == DrapeMount::kResting;
  auto problem = std::make_unique<ClothProblem>(p.pm.mesh, material, seams, co);
  if (o.mount == DrapeMount::kClamped) {
    Vertices held(static_cast<long>(p.clamp.size()), 3);
    for (size_t k = 0; k < p.clamp.size(); ++k) {
      held.row(static_cast<long>(k)) = p.pm.mesh.vertices.row(p.clamp[k]);
      held(static_cast<long>(k), 2) = 0.0;
    }
    problem->FixVertices(p.clamp, held);
  } else {
    problem->AddSupport(RestingSupport(o));
  }
  return problem;
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? kNaN : s / static_cast<double>(v.size());
}

double SampleSd(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = Mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

}  // namespace

std::string DrapeMountName(DrapeMount mount) {
  return mount == DrapeMount::kClamped ? "clamped" : "resting";
}

DrapeMount ParseDrapeMount(const std::string& name) {
  if (name == "clamped") return DrapeMount::kClamped;
  if (name == "resting") return DrapeMount::kResting;
  throw InputError("mount: '" + name + "' is not clamped or resting");
}

std::string DrapeSeamsName(DrapeSeams seams) {
  switch (seams) {
    case DrapeSeams::kNone:
      return "none";
    case DrapeSeams::kWeft:
      return "weft";
    case DrapeSeams::kWeftWarp:
      return "weft+warp";
    case DrapeSeams::kShifted:
      return "shifted";
  }
  return "none";
}

DrapeSeams ParseDrapeSeams(const std::string& name) {
  if (name == "none") return DrapeSeams::kNone;
  if (name == "weft") return DrapeSeams::kWeft;
  if (name == "weft+warp") return DrapeSeams::kWeftWarp;
  if (name == "shifted") return DrapeSeams::kShifted;
  throw InputError("seams: '" + name + "' is not none, weft, weft+warp or shifted");
}

void ParseStartModes(const std::string& text, DrapeOptions* o) {
  const std::string why =
      "start_modes: '" + text + "' is not MIN-MAX with 1 <= MIN <= MAX <= 64 (e.g. 3-8)";
  const size_t dash = text.find('-');
  if (dash == std::string::npos || dash == 0 || dash + 1 == text.size() ||
      text.find_first_not_of("0123456789-") != std::string::npos ||
      text.find('-', dash + 1) != std::string::npos || text.size() > 5) {
    throw InputError(why);
  }
  const int lo = std::stoi(text.substr(0, dash)), hi = std::stoi(text.substr(dash + 1));
  if (lo < 1 || hi < lo || hi > 64) throw InputError(why);
  o->min_harmonic = lo;
  o->max_harmonic = hi;
}

SolveOptions DefaultDrapeSolveOptions() {
  SolveOptions s;
  s.tolerance = 1e-4;
  s.max_iterations = 3000;
  s.max_seconds = 600.0;  // wall time: generous, the machine may be shared
  s.expand_steps = true;  // the same equilibria in 0.4-1× the steps (docs/methods/drapemeter.md, "Solver")
  // The exact Hessian tried from a relative residual of 10 down, not 1: soft in compression (the
  // default membrane) it is positive definite early, and the same drapes took 0.6-0.95× the base
  // steps (docs/methods/drapemeter.md, "Solver", item 1).
  s.exact_below = kDrapeExactBelow;
  return s;
}

bool DrapeOptions::Check(std::string* why) const {
  if (!Finite(specimen_radius) || specimen_radius <= 0.0 || specimen_radius > 2.0)
    return Fail(why, "specimen_radius: must be in (0, 2] m");
  if (!Finite(support_radius) || support_radius <= 0.0)
    return Fail(why, "support_radius: must be > 0");
  if (specimen_radius <= support_radius)
    return Fail(why, "specimen_radius: the specimen (" + std::to_string(specimen_radius * 1e3) +
                         " mm) must be larger than the support (" +
                         std::to_string(support_radius * 1e3) + " mm)");
  if (!Finite(support_thickness) || support_thickness <= 0.0)
    return Fail(why, "support_thickness: must be > 0");
  if (!Finite(rim_rounding) || rim_rounding <= 0.0 || rim_rounding > 0.5 * support_thickness)
    return Fail(why, "rim_rounding: must be in (0, support_thickness / 2]");
  if (!Finite(drop_height) || drop_height < 0.0) return Fail(why, "drop_height: must be ≥ 0");
  // Softer than 3e-5 m the cloth fell through the disk (0.1 mm: 20 pattern diagonals deep).
  if (!Finite(contact_sink) || contact_sink < 1e-9 || contact_sink > 3e-5)
    return Fail(why, "contact_sink: must be in [1e-9, 3e-5] m");
  if (seeds < 1 || seeds > 1000) return Fail(why, "seeds: must be in 1..1000");
  if (!Finite(perturbation) || perturbation <= 0.0 || perturbation > specimen_radius)
    return Fail(why, "perturbation: must be in (0, specimen_radius]");
  if (min_harmonic < 1 || max_harmonic < min_harmonic || max_harmonic > 64)
    return Fail(why, "harmonics: need 1 ≤ min_harmonic ≤ max_harmonic ≤ 64");
  if (!Finite(start_droop) || start_droop < 0.0 || start_droop > 0.5 * kPi)
    return Fail(why, "start_droop: must be in [0, π/2]");
  if (!Finite(frame_angle)) return Fail(why, "frame_angle: must be finite");
  // The support circle's 24 or more chords must stay far above the mesher's snap (1e-3 of the
  // element size): at R_s = h/4 they are 0.065 h long.
  if (Finite(element_size) && support_radius < 0.25 * element_size)
    return Fail(why, "support_radius: must be at least a quarter of element_size");
  if (!Finite(element_size) || element_size <= 0.0 ||
      element_size > 0.5 * (specimen_radius - support_radius))
    return Fail(why, "element_size: must be in (0, half the overhang]");
  if (element_size < 1e-4) return Fail(why, "element_size: below 0.1 mm is not a drape mesh");
  if (!Finite(rim_element_size) || rim_element_size < 0.0 || rim_element_size > element_size)
    return Fail(why, "rim_element_size: must be 0 (off) or in [0.1 mm, element_size]");
  if (rim_element_size > 0.0 && rim_element_size < 1e-4)
    return Fail(why, "rim_element_size: below 0.1 mm is not a drape mesh");
  if (!Finite(rim_band) || rim_band < 0.0 || rim_band > specimen_radius - support_radius)
    return Fail(why, "rim_band: must be in [0, the overhang]");
  if (coarse_to_fine && mount == DrapeMount::kResting)
    return Fail(why,
                "coarse_to_fine: clamped mount only (the fine level would restart the friction)");
  if (rim_extrapolation && rim_element_size == 0.0)
    return Fail(why, "rim_extrapolation: needs a rim band (rim_element_size > 0)");
  if (rim_extrapolation && rim_band < rim_element_size)
    return Fail(why, "rim_extrapolation: needs a rim band at least one rim element wide");
  if (!Finite(coarse_factor) || coarse_factor < 1.0 || coarse_factor > 8.0)
    return Fail(why, "coarse_factor: must be in [1, 8]");
  if (coarse_to_fine && coarse_factor * element_size > 0.5 * (specimen_radius - support_radius))
    return Fail(why, "coarse_factor: the coarse mesh would be coarser than half the overhang");
  if (circle_segments != 0 && (circle_segments < 8 || circle_segments > 100000))
    return Fail(why, "circle_segments: must be 0 (automatic) or in 8..100000");
  if (seams != DrapeSeams::kNone) {
    std::string w;
    if (!seam_profile.Check(&w)) return Fail(why, "seam_profile: " + w);
  }
  if (!Finite(seam_shift) || std::abs(seam_shift) >= specimen_radius)
    return Fail(why, "seam_shift: must be inside the specimen");
  if (seams == DrapeSeams::kShifted && std::abs(seam_shift) > MaxSeamShift(*this) * (1.0 + 1e-12))
    return Fail(why,
                "seam_shift: the shifted seam must lie at least one element (element_size) "
                "inside the specimen's edge");
  if (!Finite(seam_refinement_range) || seam_refinement_range < 0.0)
    return Fail(why, "seam_refinement_range: must be ≥ 0");
  std::string w;
  if (!solver.Check(&w)) return Fail(why, "solver: " + w);
  if (!Finite(raster_cell) || raster_cell <= 0.0 || raster_cell > 0.05 * specimen_radius)
    return Fail(why, "raster_cell: must be in (0, specimen_radius / 20]");
  if (specimen_radius / raster_cell > 4000.0)
    return Fail(why, "raster_cell: too fine for this specimen (over 8000 cells across)");
  if (outline_bins < 8 || outline_bins > 100000)
    return Fail(why, "outline_bins: must be in 8..100000");
  if (smoothing_bins < 1 || smoothing_bins % 2 == 0 || smoothing_bins > outline_bins / 4)
    return Fail(why, "smoothing_bins: must be odd, ≥ 1 and at most a quarter of outline_bins");
  if (!Finite(node_prominence) || node_prominence < 0.0)
    return Fail(why, "node_prominence: must be ≥ 0");
  if (!Finite(node_prominence_relative) || node_prominence_relative < 0.0 ||
      node_prominence_relative >= 1.0)
    return Fail(why, "node_prominence_relative: must be in [0, 1)");
  if ((sensitivity || monte_carlo_samples > 0) && mount != DrapeMount::kClamped)
    return Fail(why,
                "sensitivity and Monte Carlo: clamped mount only (the resting mount's friction "
                "state has no derivative here)");
  if (monte_carlo_samples < 0 || monte_carlo_samples == 1 || monte_carlo_samples > 10000)
    return Fail(why, "Monte Carlo samples: must be 0 (none) or in 2..10000");
  return true;
}

namespace {

std::uint8_t& ShadowCell(DrapeShadow* s, int i, int j) {
  return s->mask[static_cast<size_t>(j) * s->width + i];
}

}  // namespace

namespace drape_internal {

// Shadow stage 3: the support casts its own shadow (the drapemeter's disk is opaque): a
// specimen that leaves part of it bare (a resting fabric that passed through it, drape.h) still
// shades all of it, so A_shadow ≥ A_support and the DC ≥ 0.
void AddSupportShadow(double support_radius, DrapeShadow* s) {
  if (!(support_radius > 0.0)) return;
  const double r2 = support_radius * support_radius;
  for (int j = 0; j < s->height; ++j) {
    const double py = s->origin_y + j * s->cell;
    for (int i = 0; i < s->width; ++i) {
      const double px = s->origin_x + i * s->cell;
      if (px * px + py * py > r2) continue;
      if (ShadowCell(s, i, j) == 0) s->bare_support_area += s->cell * s->cell;
      ShadowCell(s, i, j) = 1;
    }
  }
}

// Shadow stage 4: holes filled: the empty cells flooded from the border (marked 2); what the
// flood does not reach is shadow.
void FloodFromBorder(DrapeShadow* s) {
  std::deque<std::pair<int, int>> queue;
  auto seed = [&](int i, int j) {
    if (ShadowCell(s, i, j) == 0) {
      ShadowCell(s, i, j) = 2;
      queue.emplace_back(i, j);
    }
  };
  for (int i = 0; i < s->width; ++i) seed(i, 0), seed(i, s->height - 1);
  for (int j = 0; j < s->height; ++j) seed(0, j), seed(s->width - 1, j);
  while (!queue.empty()) {
    const auto [i, j] = queue.front();
    queue.pop_front();
    if (i > 0) seed(i - 1, j);
    if (i + 1 < s->width) seed(i + 1, j);
    if (j > 0) seed(i, j - 1);
    if (j + 1 < s->height) seed(i, j + 1);
  }
}

// Shadow stage 5: the mask made 0/1 (flooded cells are outside), the area, and each angle bin's
// largest radius of a shadow cell centre (-1 where none falls).
void MeasureOutline(int bins, DrapeShadow* s) {
  long count = 0;
  s->angles.resize(bins);
  s->radii = Eigen::VectorXd::Constant(bins, -1.0);
  for (int b = 0; b < bins; ++b) s->angles(b) = (b + 0.5) * 2.0 * kPi / bins;
  for (int j = 0; j < s->height; ++j) {
    for (int i = 0; i < s->width; ++i) {
      std::uint8_t& m = ShadowCell(s, i, j);
      m = m == 2 ? 0 : 1;
      if (!m) continue;
      ++count;
      const double px = s->origin_x + i * s->cell, py = s->origin_y + j * s->cell;
      double theta = std::atan2(py, px);
      if (theta < 0.0) theta += 2.0 * kPi;
      const int b = std::min(bins - 1, static_cast<int>(theta / (2.0 * kPi) * bins));
      s->radii(b) = std::max(s->radii(b), std::hypot(px, py));
    }
  }
  s->area = static_cast<double>(count) * s->cell * s->cell;
}

// Shadow stage 6: bins no cell centre reached (a tiny shadow, or fine bins near the centre)
// interpolated between the nearest filled bins on either side, circularly.
void FillEmptyBins(Eigen::VectorXd* radii) {
  const int bins = static_cast<int>(radii->size());
  std::vector<int> filled;
  for (int b = 0; b < bins; ++b)
    if ((*radii)(b) >= 0.0) filled.push_back(b);
  if (filled.empty()) {
    radii->setZero();
    return;
  }
  if (static_cast<int>(filled.size()) == bins) return;
  const Eigen::VectorXd raw = *radii;
  for (size_t k = 0; k < filled.size(); ++k) {
    const int from = filled[k], to = filled[(k + 1) % filled.size()];
    const int gap = (to - from + bins) % bins == 0 ? bins : (to - from + bins) % bins;
    for (int g = 1; g < gap; ++g) {
      const double t = static_cast<double>(g) / gap;
      (*radii)((from + g) % bins) = (1.0 - t) * raw(from) + t * raw(to);
    }
  }
}

}  // namespace drape_internal

using drape_internal::AddSupportShadow;
using drape_internal::FillEmptyBins;
using drape_internal::FloodFromBorder;
using drape_internal::MeasureOutline;

DrapeShadow MeasureShadow(const Vertices& x, const Triangles& triangles, double cell, int bins,
                          double support_radius) {
  if (!(cell > 0.0) || !Finite(cell)) throw InputError("shadow: raster cell must be > 0");
  if (!(support_radius >= 0.0) || !Finite(support_radius))
    throw InputError("shadow: support radius must be >= 0");
  if (bins < 8) throw InputError("shadow: need at least 8 angle bins");
  if (x.rows() == 0 || triangles.rows() == 0) throw InputError("shadow: empty mesh");
  if (!x.allFinite()) throw InputError("shadow: non-finite vertex positions");
  if (triangles.minCoeff() < 0 || triangles.maxCoeff() >= x.rows())
    throw InputError("shadow: triangle index out of range");
  // Stages 1-2, shared with measured drapes: the grid over the projection and the support, and
  // the cells whose centres a projected triangle covers.
  DrapeShadow s = RasteriseFabric(x, triangles, Eigen::Vector2d::Zero(), cell, support_radius);
  AddSupportShadow(support_radius, &s);
  FloodFromBorder(&s);
  MeasureOutline(bins, &s);
  FillEmptyBins(&s.radii);
  return s;
}

DrapeNodes FindNodes(const Eigen::VectorXd& radii, int smoothing_bins, double min_prominence,
                     double relative_prominence) {
  const int n = static_cast<int>(radii.size());
  if (n < 3) throw InputError("nodes: need at least 3 outline bins");
  if (smoothing_bins < 1 || smoothing_bins % 2 == 0 || smoothing_bins > n)
    throw InputError("nodes: smoothing_bins must be odd and between 1 and the number of bins");
  if (!radii.allFinite()) throw InputError("nodes: non-finite outline radius");
  Eigen::VectorXd s(n);
  const int half = smoothing_bins / 2;
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (int k = -half; k <= half; ++k) sum += radii(((i + k) % n + n) % n);
    s(i) = sum / smoothing_bins;
  }
  const double lo = s.minCoeff(), hi = s.maxCoeff();
  const double threshold = std::max(min_prominence, relative_prominence * (hi - lo));
  DrapeNodes nodes;
  if (hi - lo <= 0.0) return nodes;
  for (int i = 0; i < n; ++i) {
    const double v = s(i);
    // Strict on the left, non-strict on the right: a plateau counts once, at its first bin.
    if (!(v > s((i - 1 + n) % n) && v >= s((i + 1) % n))) continue;
    double left_min = v, right_min = v;
    bool higher = false;
    for (int k = 1; k < n; ++k) {
      const double u = s(((i - k) % n + n) % n);
      if (u > v) {
        higher = true;
        break;
      }
      left_min = std::min(left_min, u);
    }
    for (int k = 1; k < n; ++k) {
      const double u = s((i + k) % n);
      if (u > v) break;
      right_min = std::min(right_min, u);
    }
    const double prominence = higher ? v - std::max(left_min, right_min) : v - lo;
    if (prominence < threshold || prominence <= 0.0) continue;
    nodes.angles.push_back((i + 0.5) * 2.0 * kPi / n);
    nodes.radii.push_back(radii(i));
    nodes.prominences.push_back(prominence);
  }
  return nodes;
}

RimExtrapolation ExtrapolateRim(double base_dc, double split_dc) {
  const double step = split_dc - base_dc;
  return {split_dc + 0.5 * step, 0.5 * std::abs(step), step < 0.0};
}

double DrapeCoefficient(double shadow_area, double specimen_area, double support_area) {
  if (!(support_area > 0.0) || !(specimen_area > support_area) || !Finite(specimen_area))
    throw InputError("drape coefficient: need specimen area > support area > 0");
  if (!Finite(shadow_area) || shadow_area < 0.0)
    throw InputError("drape coefficient: shadow area must be finite and ≥ 0");
  return (shadow_area - support_area) / (specimen_area - support_area);
}

double MaxSeamShift(const DrapeOptions& o) { return o.specimen_radius - o.element_size; }

std::vector<SeamLine> DrapeSeamLines(const DrapeOptions& o) {
  // The pattern's x axis is the warp (bending_element.h), y the weft.
  const double weft = Frame(o) + 0.5 * kPi, warp = Frame(o);
  const double r = o.specimen_radius;
  switch (o.seams) {
    case DrapeSeams::kNone:
      return {};
    case DrapeSeams::kWeft:
      return {Chord(r, weft, 0.0)};
    case DrapeSeams::kWeftWarp:
      return {Chord(r, weft, 0.0), Chord(r, warp, 0.0)};
    case DrapeSeams::kShifted:
      return {Chord(r, weft, -o.seam_shift)};
  }
  return {};
}

namespace drape_internal {

std::vector<Seam> DrapeSeamList(const DrapeOptions& o) {
  std::vector<Seam> seams;
  for (const SeamLine& line : DrapeSeamLines(o)) seams.push_back(Seam{o.seam_profile, line});
  return seams;
}

}  // namespace drape_internal

double RimTurnDownLength(const Material& material, const DrapeOptions& o) {
  const double overhang = o.specimen_radius - o.support_radius;
  if (!(material.areal_density > 0.0) || !Finite(material.areal_density))
    throw InputError("rim turn-down length: the material needs an areal density > 0");
  if (!(overhang > 0.0) || !Finite(overhang))
    throw InputError("rim turn-down length: the specimen must be larger than the support");
  const BendingLaw warp = material.EffectiveLaw(), weft = material.EffectiveWeftLaw();
  double b = std::min(warp.MinStiffness(), weft.MinStiffness());  // the softest B
  if (const std::optional<BendingLaw> bias = material.EffectiveBiasLaw())
    b = std::min(b, bias->MinStiffness());
  const double g = ClothOptions{}.gravity.norm();  // [m/s²]
  return std::sqrt(b / (material.areal_density * g * overhang));
}

double AutoRimElementSize(const Material& material, const DrapeOptions& o, bool extrapolate,
                          bool* capped) {
  const double turn_down = RimTurnDownLength(material, o);
  // Vertices of the band (from the rim to rim_band past it) at element e: about 1.155 A / e²
  // on equilateral triangles. A limp fabric's ℓ/2 (0.5 mm) gave 67k vertices (251k split) and
  // minutes of solving without a word; the cap keeps auto under kAutoRimMaxVertices there.
  const double outer = o.support_radius + o.rim_band;
  const double band_area = kPi * (outer * outer - o.support_radius * o.support_radius);
  const double smallest = std::sqrt(2.0 / std::sqrt(3.0) * band_area / kAutoRimMaxVertices);
  const double wanted = std::max(turn_down / (extrapolate ? 2.0 : 3.0), 0.0005);
  if (capped) *capped = wanted < smallest && smallest < o.element_size;
  return std::min(std::max(wanted, smallest), o.element_size);
}

void ChooseDrapeRim(const Material& material, bool rim_auto, DrapeExtrapolation extrapolation,
                    DrapeOptions* o) {
  RimTurnDownLength(material, *o);  // throws for a material or scene without one
  // `--rim-mm auto` meshes the rim with ℓ/2 when extrapolating (within 0.01 of the converged
  // DC in about 5 s), else ℓ/3 (an expected shortfall over 0.02 gets a note); at least 0.5 mm,
  // at most the element size (which may itself be under 0.5 mm when the overhang is tiny).
  const double rim_if_extrapolating =
      rim_auto ? AutoRimElementSize(material, *o, true) : o->rim_element_size;
  const bool possible = o->mount == DrapeMount::kClamped && rim_if_extrapolating > 0.0 &&
                        o->rim_band >= rim_if_extrapolating;
  o->rim_extrapolation = extrapolation == DrapeExtrapolation::kOn ||
                         (extrapolation == DrapeExtrapolation::kDefault && possible);
  o->rim_auto = rim_auto;
  if (rim_auto) o->rim_element_size = AutoRimElementSize(material, *o, o->rim_extrapolation);
}

namespace {

void Say(const DrapeOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

// The meshes of a run: the fine pattern, the coarse one of a cascade, the split rim's.
struct DrapeScene {
  std::vector<Seam> seams;
  Pattern fine;
  std::unique_ptr<Pattern> coarse;  // coarse_to_fine only
  std::unique_ptr<Pattern> split;   // rim_extrapolation only
  RefinedMesh refined;              // fine → split
  const Pattern& last() const { return split ? *split : fine; }
};

// Stage 1: the seams, the meshes and the result's scene figures.
DrapeScene BuildScene(const DrapeOptions& o, DrapeResult* result) {
  DrapeScene scene;
  result->seam_lines = DrapeSeamLines(o);
  scene.seams = drape_internal::DrapeSeamList(o);
  scene.fine = MeshPattern(o, scene.seams, 1.0);
  if (o.coarse_to_fine) {
    scene.coarse = std::make_unique<Pattern>(MeshPattern(o, scene.seams, o.coarse_factor));
    result->coarse_vertices = scene.coarse->pm.mesh.num_vertices();
  }
  if (o.rim_extrapolation)
    scene.split = std::make_unique<Pattern>(SplitRim(scene.fine, o, &scene.refined));
  result->base_vertices = scene.fine.pm.mesh.num_vertices();
  result->mesh = scene.last().pm.mesh;
  result->seam_paths = scene.last().pm.seam_paths;
  result->seam_paths.pop_back();  // the support circle is not a seam
  result->specimen_area = TriangleAreas(scene.fine.pm.mesh).sum();
  result->support_area = kPi * o.support_radius * o.support_radius;
  return scene;
}

std::string SceneReport(const DrapeScene& scene, const DrapeResult& result) {
  const TriangleMesh& fine = scene.fine.pm.mesh;
  std::ostringstream line;
  line << "mesh: " << fine.num_vertices() << " vertices, " << fine.num_triangles() << " triangles"
       << (scene.coarse ? " (coarse " + std::to_string(result.coarse_vertices) + " vertices)" : "")
       << ", " << scene.fine.clamp.size() << " on the support";
  if (scene.split)
    line << "; split at the rim: " << scene.split->pm.mesh.num_vertices() << " vertices, "
         << scene.split->pm.mesh.num_triangles() << " triangles";
  return line.str();
}

// One seed on its way through the stages.
struct SeedState {
  DrapeSeedResult seed;
  std::unique_ptr<ClothProblem> fine_problem;  // the split's friction anchors come from it
  std::string failure;                         // why this seed has no DC
  // With a rim split: the base mesh's equilibrium and the split mesh's problem (sensitivities).
  Vertices base_positions;
  std::unique_ptr<ClothProblem> split_problem;
  // With options.sensitivity: ∂DC/∂p per parameter [per SI unit], per scene radius [per m] and
  // per seam coefficient.
  drape_internal::DcDerivativeSet d_dc;
};

// What a Monte Carlo sample of a seed starts from: the seed's nominal equilibrium on the base
// mesh, and its node count.
struct SeedStart {
  unsigned seed = 0;
  Vertices base_positions;
  size_t nodes = 0;
};

// The shadow of x on `mesh` into *shadow, and its DC.
double MeasureDrape(const Vertices& x, const TriangleMesh& mesh, const DrapeOptions& o,
                    const DrapeResult& result, DrapeShadow* shadow) {
  *shadow = MeasureShadow(x, mesh.triangles, o.raster_cell, o.outline_bins, o.support_radius);
  return DrapeCoefficient(shadow->area, result.specimen_area, result.support_area);
}

// Stage 2: the seeded start settled on the fine mesh (through the coarse one when cascadic).
SeedState SettleBase(const Material& material, const DrapeOptions& o, const DrapeScene& scene,
                     unsigned seed_number, DrapeResult* result) {
  SeedState st;
  DrapeSeedResult& seed = st.seed;
  seed.seed = seed_number;
  st.fine_problem = MakeProblem(scene.fine, material, scene.seams, o);
  result->mass = st.fine_problem->total_mass();
  if (scene.coarse) {
    auto coarse_problem = MakeProblem(*scene.coarse, material, scene.seams, o);
    Vertices xc = StartState(scene.coarse->pm.mesh, o, seed.seed);
    seed.summary = SolveCascadic(coarse_problem.get(), st.fine_problem.get(), &xc,
                                 &seed.positions, o.solver);
  } else {
    seed.positions = StartState(scene.fine.pm.mesh, o, seed.seed);
    seed.summary = SolveStatic(st.fine_problem.get(), &seed.positions, o.solver);
  }
  seed.converged = seed.summary.converged;
  seed.drape_coefficient = seed.base_drape_coefficient = seed.split_drape_coefficient = kNaN;
  seed.extrapolation_bound = kNaN;
  st.failure = seed.summary.message;
  // #V of the split mesh (a failed coarse level of a cascade leaves no positions).
  if (scene.split && !seed.converged &&
      seed.positions.rows() == scene.fine.pm.mesh.num_vertices())
    seed.positions = scene.refined.Prolong(seed.positions);
  return st;
}

// Stage 3 (rim extrapolation): the base equilibrium measured, carried over to the split mesh
// (the same surface) and settled there.
void SettleSplit(const Material& material, const DrapeOptions& o, const DrapeScene& scene,
                 const DrapeResult& result, SeedState* st) {
  DrapeSeedResult& seed = st->seed;
  if (!scene.split || !seed.converged) return;
  seed.base_drape_coefficient =
      MeasureDrape(seed.positions, scene.fine.pm.mesh, o, result, &seed.shadow);
  {
    std::ostringstream line;
    line << "seed " << seed.seed << ": base " << seed.summary.BriefReport() << "; DC "
         << seed.base_drape_coefficient;
    Say(o, line.str());
  }
  auto split_problem = MakeProblem(*scene.split, material, scene.seams, o);
  st->base_positions = seed.positions;
  seed.positions = scene.refined.Prolong(seed.positions);
  // Resting: the friction goes on from where each node landed on the base mesh.
  if (o.mount == DrapeMount::kResting)
    split_problem->CarryAnchorsFrom(*st->fine_problem, scene.refined.parents);
  // The carried-over drape is near the split mesh's equilibrium: the exact Hessian from the
  // first step (taken where it is positive definite) halved the steps (seed 2 of the Fig. 8
  // fabric: 104 → 52; docs/methods/drapemeter.md, "Extrapolated DC").
  SolveOptions split_solver = o.solver;
  if (split_solver.exact_below > 0.0) split_solver.exact_below = kInf;
  seed.split_summary = SolveStatic(split_problem.get(), &seed.positions, split_solver);
  seed.converged = seed.split_summary.converged;
  if (!seed.converged) {
    st->failure = "rim split: " + seed.split_summary.message;
    seed.shadow = DrapeShadow{};
    seed.base_drape_coefficient = kNaN;
  }
  st->split_problem = std::move(split_problem);
}

// Stage 5 (sensitivity): ∂DC/∂p of a converged seed, through each equilibrium it was measured
// on; with a split rim the extrapolation's DC_split + (DC_split - DC_base)/2. The scene's radii
// and the seam's coefficients too when the run takes them (SceneInputs): the radii
// through a morph of the rest mesh, the coefficients through the seams' own change.
void SeedSensitivities(const Material& material, const DrapeOptions& o,
                       drape_internal::SceneInputs scene_inputs,
                       const DrapeScene& scene, const DrapeResult& result,
                       const std::vector<std::string>& parameters, SeedState* st) {
  if (!o.sensitivity || !st->seed.converged) return;
  const auto derivatives = [&](ClothProblem* problem, const Vertices& x) {
    return drape_internal::DcDerivatives(problem, x, material, o, result, parameters,
                                         scene_inputs);
  };
  if (!scene.split) {
    st->d_dc = derivatives(st->fine_problem.get(), st->seed.positions);
    return;
  }
  const drape_internal::DcDerivativeSet base =
      derivatives(st->fine_problem.get(), st->base_positions);
  st->d_dc = derivatives(st->split_problem.get(), st->seed.positions);
  const auto extrapolate = [](std::vector<double>* split, const std::vector<double>& base_d) {
    for (size_t k = 0; k < base_d.size(); ++k) (*split)[k] = 1.5 * (*split)[k] - 0.5 * base_d[k];
  };
  extrapolate(&st->d_dc.material, base.material);
  extrapolate(&st->d_dc.radii, base.radii);
  extrapolate(&st->d_dc.seam, base.seam);
  st->d_dc.scene_seconds += base.scene_seconds;
}

// How deep the deepest node lies inside the resting mount's disk [m].
double MaxPenetration(const Vertices& x, const DrapeOptions& o) {
  const Support disk = RestingSupport(o);
  double deepest = 0.0;
  for (int i = 0; i < x.rows(); ++i)
    deepest = std::max(deepest, -disk.SignedDistance(x.row(i).transpose(), nullptr));
  return deepest;
}

// Stage 4: a converged seed's DC (extrapolated with a split rim), nodes and outline figures.
void MeasureSeed(const DrapeOptions& o, const DrapeScene& scene, const DrapeResult& result,
                 DrapeSeedResult* seed) {
  if (!seed->converged) return;
  seed->drape_coefficient =
      MeasureDrape(seed->positions, scene.last().pm.mesh, o, result, &seed->shadow);
  if (scene.split) {
    // Between the split rim's DC and its first-order extrapolation: the middle, and half
    // the bracket as the bound (docs/methods/drapemeter.md, "Extrapolated DC").
    seed->split_drape_coefficient = seed->drape_coefficient;
    const RimExtrapolation e =
        ExtrapolateRim(seed->base_drape_coefficient, seed->split_drape_coefficient);
    seed->drape_coefficient = e.drape_coefficient;
    seed->extrapolation_bound = e.bound;
    seed->extrapolation_reversed = e.reversed;
  }
  seed->nodes = FindNodes(seed->shadow.radii, o.smoothing_bins, o.node_prominence,
                          o.node_prominence_relative);
  if (o.mount == DrapeMount::kResting) seed->max_penetration = MaxPenetration(seed->positions, o);
  seed->min_radius = seed->shadow.radii.minCoeff();
  seed->max_radius = seed->shadow.radii.maxCoeff();
  seed->mean_radius = seed->shadow.radii.mean();
}

// Stage 6 (Monte Carlo): a drawn material's drape for one seed, solved from the seed's nominal
// equilibrium (so on its branch) and measured like the seed; *nodes its node count. NaN when
// it fails.
double SampleSeedDc(const Material& sample, const DrapeOptions& o, const DrapeScene& scene,
                    const DrapeResult& result, const SeedStart& start, size_t* nodes) {
  SeedState st;
  st.seed.seed = start.seed;
  st.fine_problem = MakeProblem(scene.fine, sample, scene.seams, o);
  st.seed.positions = start.base_positions;
  st.seed.summary = SolveStatic(st.fine_problem.get(), &st.seed.positions, o.solver);
  st.seed.converged = st.seed.summary.converged;
  SettleSplit(sample, o, scene, result, &st);
  MeasureSeed(o, scene, result, &st.seed);
  if (!st.seed.converged) return kNaN;
  *nodes = st.seed.nodes.angles.size();
  return st.seed.drape_coefficient;
}

// Stage 7 (Monte Carlo): the DC's spread over materials drawn from the fit's covariance, each
// the mean over the seeds, beside the linear σ; into result->monte_carlo.
void MonteCarloDc(const CovarianceSamples& draws, const DrapeOptions& options,
                  const DrapeScene& scene, const std::vector<SeedStart>& starts,
                  DrapeResult* result) {
  const auto start = std::chrono::steady_clock::now();
  DrapeOptions o = options;
  o.progress = nullptr;  // a line a sample's seed would drown the run's own
  std::vector<double> dcs;
  for (size_t i = 0; i < draws.materials.size(); ++i) {
    double sum = 0.0;
    bool changed = false;
    for (const SeedStart& s : starts) {
      size_t nodes = 0;
      const double dc = SampleSeedDc(draws.materials[i], o, scene, *result, s, &nodes);
      sum += dc;  // NaN for the sample when a seed failed
      changed = changed || (std::isfinite(dc) && nodes != s.nodes);
    }
    dcs.push_back(sum / static_cast<double>(starts.size()));
    if (changed) ++result->monte_carlo_node_changes;
    Say(options, "Monte Carlo: sample " + std::to_string(i + 1) + " of " +
                     std::to_string(draws.materials.size()) + ": DC " + NumberText(dcs.back(), 4));
  }
  result->monte_carlo =
      SummariseMonteCarlo(dcs, draws.rejected, result->drape_coefficient_sigma);
  if (result->monte_carlo_node_changes > 0)
    result->monte_carlo->note += "; " + std::to_string(result->monte_carlo_node_changes) +
                                 " samples changed the node count (another branch)";
  result->monte_carlo->seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string SeedReport(const DrapeSeedResult& seed, bool split) {
  std::ostringstream line;
  line << "seed " << seed.seed << ": "
       << (split && seed.summary.converged ? "split " + seed.split_summary.BriefReport()
                                           : seed.summary.BriefReport());
  if (seed.converged) {
    if (split)
      line << "; split DC " << seed.split_drape_coefficient << "; extrapolated";
    else
      line << ";";
    line << " DC " << seed.drape_coefficient << ", " << seed.nodes.angles.size() << " nodes";
  }
  return line.str();
}

}  // namespace

namespace drape_internal {

void SummariseSeeds(DrapeResult* result) {
  result->message.clear();
  std::vector<double> dcs, node_counts, mins, maxs, means;
  for (const DrapeSeedResult& seed : result->per_seed) {
    if (!seed.converged) continue;
    dcs.push_back(seed.drape_coefficient);
    node_counts.push_back(static_cast<double>(seed.nodes.angles.size()));
    mins.push_back(seed.min_radius);
    maxs.push_back(seed.max_radius);
    means.push_back(seed.mean_radius);
  }
  result->converged = dcs.size() == result->per_seed.size();
  if (!result->converged) {
    result->drape_coefficient = result->drape_coefficient_sd = kNaN;
    result->nodes = result->nodes_sd = kNaN;
    result->min_radius = result->max_radius = result->mean_radius = kNaN;
    result->min_radius_sd = result->max_radius_sd = result->mean_radius_sd = kNaN;
    return;
  }
  result->message = "converged";
  result->drape_coefficient = Mean(dcs);
  result->drape_coefficient_sd = SampleSd(dcs);
  result->nodes = Mean(node_counts);
  result->nodes_sd = SampleSd(node_counts);
  result->min_radius = Mean(mins);
  result->max_radius = Mean(maxs);
  result->mean_radius = Mean(means);
  result->min_radius_sd = SampleSd(mins);
  result->max_radius_sd = SampleSd(maxs);
  result->mean_radius_sd = SampleSd(means);
}

MorphedSeed SolveMorphedSeed(const Material& material, const DrapeOptions& options,
                             SceneRadius which, double t, const Vertices& start,
                             const SeamProfile* seam_profile) {
  if (options.rim_extrapolation || options.coarse_to_fine || options.mount != DrapeMount::kClamped)
    throw InputError("morphed seed: one clamped equilibrium only (no rim split, no cascade)");
  if (options.seams == DrapeSeams::kShifted && t != 0.0)
    throw InputError("morphed seed: no shifted seams (the radial morph would bend them)");
  DrapeResult nominal;
  DrapeScene scene = BuildScene(options, &nominal);
  const Vertices morph = RadiusMorph(scene.fine.pm.mesh, which, options);
  if (start.rows() != morph.rows()) throw InputError("morphed seed: the start is of another mesh");
  scene.fine.pm.mesh.vertices += t * morph;
  DrapeOptions o = options;
  (which == SceneRadius::kSpecimen ? o.specimen_radius : o.support_radius) += t;
  if (seam_profile) o.seam_profile = *seam_profile;  // the mesh stays refined for options'
  scene.seams = DrapeSeamList(o);  // diameters: moved with the rim (the support's morph keeps it)
  MorphedSeed m;
  m.mesh = scene.fine.pm.mesh;
  m.support_radius = o.support_radius;
  m.positions = start + t * morph;
  const std::unique_ptr<ClothProblem> problem = MakeProblem(scene.fine, material, scene.seams, o);
  m.summary = SolveStatic(problem.get(), &m.positions, o.solver);
  return m;
}

}  // namespace drape_internal

DrapeResult SimulateDrape(const Material& material, const DrapeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (std::string why; !options.Check(&why)) throw InputError("drape options: " + why);
  DrapeOptions o = options;
  if (o.monte_carlo_samples > 0) o.sensitivity = true;  // the linear σ beside the sampled one
  // The radii and the seam's coefficients: asked for, not implied by Monte Carlo.
  const drape_internal::SceneInputs scene_inputs = drape_internal::TakenSceneInputs(options);
  DrapeResult result;
  result.rim_turn_down = RimTurnDownLength(material, o);
  // Sensitivities and Monte Carlo draws: the names and the covariance checked before any work
  // (InputError).
  const std::vector<std::string> parameters = drape_internal::SensitivityParameters(material, o);
  const CovarianceSamples draws =
      o.monte_carlo_samples > 0
          ? SampleFitCovariance(material, o.monte_carlo_samples, o.monte_carlo_seed)
          : CovarianceSamples{};
  std::vector<SeedStart> starts;
  const DrapeScene scene = BuildScene(o, &result);
  Say(o, SceneReport(scene, result));
  std::string failure;  // the first failing seed's
  std::vector<drape_internal::DcDerivativeSet> seed_derivatives;
  for (int k = 0; k < o.seeds; ++k) {
    SeedState st = SettleBase(material, o, scene, o.first_seed + static_cast<unsigned>(k), &result);
    SettleSplit(material, o, scene, result, &st);
    MeasureSeed(o, scene, result, &st.seed);
    const auto sensitivity_start = std::chrono::steady_clock::now();
    SeedSensitivities(material, o, scene_inputs, scene, result, parameters, &st);
    if (!st.d_dc.material.empty() || !st.d_dc.radii.empty() || !st.d_dc.seam.empty()) {
      result.sensitivity_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - sensitivity_start).count();
      result.scene_sensitivity_seconds += st.d_dc.scene_seconds;
      result.sensitivity_equilibria += scene.split ? 2 : 1;
      seed_derivatives.push_back(std::move(st.d_dc));
    }
    if (o.monte_carlo_samples > 0 && st.seed.converged)
      starts.push_back({st.seed.seed, scene.split ? st.base_positions : st.seed.positions,
                        st.seed.nodes.angles.size()});
    Say(o, SeedReport(st.seed, scene.split != nullptr));
    if (!st.seed.converged && failure.empty())
      failure = "seed " + std::to_string(st.seed.seed) + ": " + st.failure;
    result.per_seed.push_back(std::move(st.seed));
  }
  drape_internal::SummariseSeeds(&result);
  if (!result.converged) result.message = failure;
  if (o.sensitivity && result.converged)
    drape_internal::SummariseSensitivities(material, parameters, seed_derivatives, o, &result);
  if (o.monte_carlo_samples > 0 && result.converged) MonteCarloDc(draws, o, scene, starts, &result);
  bool rim_capped = false;
  if (o.rim_auto) AutoRimElementSize(material, o, o.rim_extrapolation, &rim_capped);
  result.notes = drape_internal::DrapeNotes(options, result, rim_capped);  // as asked
  // A membrane the file did not give is a guess the DC depends on: the run says which parts.
  for (Note& n : MaterialDefaultNotes(material)) result.notes.push_back(std::move(n));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace textile
