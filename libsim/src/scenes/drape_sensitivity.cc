#include "textile/sim/scenes/drape_sensitivity.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <utility>

#include "drape_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/law/input_influence.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/solve/sensitivity.h"

namespace textile {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

double Angle(const Eigen::Vector2d& p) {
  const double a = std::atan2(p.y(), p.x());
  return a < 0.0 ? a + kTwoPi : a;
}

// Each edge of the mesh once (i < j).
std::vector<std::array<int, 2>> UniqueEdges(const Triangles& triangles) {
  std::vector<std::array<int, 2>> edges;
  edges.reserve(3 * static_cast<size_t>(triangles.rows()));
  for (int f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int a = triangles(f, k), b = triangles(f, (k + 1) % 3);
      if (a > b) std::swap(a, b);
      edges.push_back({a, b});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

Eigen::Vector2d Projected(const Vertices& x, int v) { return {x(v, 0), x(v, 1)}; }

}  // namespace

ShadowOutline TraceShadowOutline(const Vertices& x, const Triangles& triangles, int bins,
                                 double support_radius) {
  if (bins < 8) throw InputError("shadow outline: need at least 8 angle bins");
  if (!x.allFinite()) throw InputError("shadow outline: non-finite vertex positions");
  if (triangles.rows() == 0 || triangles.minCoeff() < 0 || triangles.maxCoeff() >= x.rows())
    throw InputError("shadow outline: no triangles, or a vertex id out of range");
  const double step = kTwoPi / bins;
  ShadowOutline o;
  o.radii.assign(bins, support_radius);
  o.edge.assign(bins, {-1, -1});
  o.along.assign(bins, 0.0);
  for (const auto& [i, j] : UniqueEdges(triangles)) {
    const Eigen::Vector2d p = Projected(x, i), q = Projected(x, j), e = q - p;
    if (std::max(p.norm(), q.norm()) <= support_radius) continue;  // inside the support's disk
    // The bins whose rays the edge's angular span (the short way round) holds.
    double from = Angle(p), span = Angle(q) - from;
    if (span > std::numbers::pi) span -= kTwoPi;
    if (span < -std::numbers::pi) span += kTwoPi;
    if (span < 0.0) from += span, span = -span;
    const long first = static_cast<long>(std::ceil(from / step - 0.5));
    const long last = static_cast<long>(std::floor((from + span) / step - 0.5));
    for (long k = first; k <= last; ++k) {
      const int b = static_cast<int>(((k % bins) + bins) % bins);
      const double theta = (b + 0.5) * step;
      const Eigen::Vector2d u(std::cos(theta), std::sin(theta));
      const double denominator = Cross(u, e);
      if (std::abs(denominator) <= 1e-300) continue;  // the edge runs along the ray
      const double s = Cross(p, u) / denominator, r = Cross(p, e) / denominator;
      if (s < 0.0 || s > 1.0 || !(r > o.radii[b])) continue;
      o.radii[b] = r;
      o.edge[b] = {i, j};
      o.along[b] = s;
    }
  }
  for (double r : o.radii) o.area += 0.5 * r * r * step;
  return o;
}

Vertices OutlineAreaGradient(const ShadowOutline& outline, const Vertices& x) {
  const int bins = static_cast<int>(outline.radii.size());
  const double step = kTwoPi / bins;
  Vertices g = Vertices::Zero(x.rows(), 3);
  for (int b = 0; b < bins; ++b) {
    const auto [i, j] = outline.edge[b];
    if (i < 0) continue;  // the support's rim: fixed
    const double theta = (b + 0.5) * step, s = outline.along[b];
    const Eigen::Vector2d u(std::cos(theta), std::sin(theta));
    const Eigen::Vector2d e = Projected(x, j) - Projected(x, i), n(-e.y(), e.x());
    const double un = u.dot(n);
    if (std::abs(un) <= 1e-12 * n.norm()) continue;  // grazing: no first-order change
    // The ray's crossing moves by (v · n) / (u · n) along u, v the edge's displacement there.
    const Eigen::Vector2d w = (outline.radii[b] * step / un) * n;
    g.block<1, 2>(i, 0) += (1.0 - s) * w.transpose();
    g.block<1, 2>(j, 0) += s * w.transpose();
  }
  return g;
}

double OutlineAreaDerivative(const ShadowOutline& outline, const Vertices& x, const Vertices& dx) {
  if (dx.rows() != x.rows() || dx.cols() != 3)
    throw InputError("outline area: the displacements must have one row a vertex");
  return (OutlineAreaGradient(outline, x).array() * dx.array()).sum();
}

namespace drape_internal {

// EquilibriumSensitivity's relative step (sensitivity.cc), for the checks before the solve.
constexpr double kSensitivityStep = 1e-4;

// The outline's bins for the sensitivity: fine enough that the polar area is the raster's within
// its cells whatever options.outline_bins (which is for the node count).
constexpr int kSensitivityBins = 2048;

std::vector<std::string> SensitivityParameters(const Material& material, const DrapeOptions& o) {
  if (!o.sensitivity) return {};
  MaterialFitCovariance(material);  // a malformed covariance is refused now, not after the solve
  std::vector<std::string> names = o.sensitivity_parameters.empty()
                                       ? MaterialParameterNames(material)
                                       : o.sensitivity_parameters;
  CheckSensitivityParameters(material, names, kSensitivityStep);
  return names;
}

bool TakesSceneParameters(const DrapeOptions& o) {
  return o.sensitivity && o.sensitivity_parameters.empty();
}

bool TakesSceneRadii(const DrapeOptions& o) {
  return TakesSceneParameters(o) && o.seams != DrapeSeams::kShifted;
}

bool TakesSeamCoefficients(const DrapeOptions& o) {
  return TakesSceneParameters(o) && o.seams != DrapeSeams::kNone;
}

Vertices RadiusMorph(const TriangleMesh& rest, SceneRadius which, const DrapeOptions& o) {
  const double rs = o.support_radius, r_max = o.specimen_radius, overhang = r_max - rs;
  Vertices d = Vertices::Zero(rest.num_vertices(), 3);
  for (int v = 0; v < rest.num_vertices(); ++v) {
    const Eigen::Vector2d p = rest.vertices.row(v).head<2>().transpose();
    const double r = p.norm();
    if (r == 0.0) continue;
    const double u = which == SceneRadius::kSpecimen
                         ? std::max(0.0, r - rs) / overhang
                         : (r <= rs ? r / rs : std::max(0.0, r_max - r) / overhang);
    d.block<1, 2>(v, 0) = (u / r) * p.transpose();
  }
  return d;
}

namespace {

// The rest morph's central-difference step, relative to the specimen's radius (1.5 nm): below
// the strains at which a membrane soft in compression switches (RestShapeResidualChange); at
// 1e-4 the DC's derivatives came out 6-8 % low, from 1e-7 to 1e-9 within 0.2 % of morphed drapes.
constexpr double kRadiusStep = 1e-8;

// The radii's stated uncertainties (docs/methods/sensitivity.md, "Scene radii"): a specimen cut
// to a template, a machined support disk.
constexpr double kSpecimenRadiusUncertainty = 1e-3;  // [m]
constexpr double kSupportRadiusUncertainty = 1e-4;   // [m]

// The drape's seams at the specimen's radius R + t (the support's morph keeps the rim, and so
// the seams' ends); none without seams. A diameter stays one under either morph.
EquilibriumSensitivity::SeamsAt MorphedSeams(SceneRadius which, const DrapeOptions& o) {
  if (o.seams == DrapeSeams::kNone) return {};
  return [which, o](double t) {
    DrapeOptions moved = o;
    if (which == SceneRadius::kSpecimen) moved.specimen_radius += t;
    return DrapeSeamList(moved);
  };
}

// ∂DC/∂R of one radius: the shadow's area through the adjoint (g · morph + λ · T,
// RestShapeResidualChange) and the support's rim where it is the outline; the specimen's area
// through the morphed mesh, the support's as π R_s².
double RadiusDcDerivative(const EquilibriumSensitivity& sensitivity, const Vertices& adjoint,
                          const Vertices& area_gradient, const ShadowOutline& outline,
                          const TriangleMesh& rest, SceneRadius which,
                          const DrapeOptions& o, const DrapeResult& result) {
  const Vertices morph = RadiusMorph(rest, which, o);
  const double h = kRadiusStep * o.specimen_radius;
  const Vertices force = sensitivity.RestShapeResidualChange(morph, h, MorphedSeams(which, o));
  double d_shadow = (adjoint.array() * force.array()).sum() +
                    (area_gradient.array() * morph.array()).sum();
  double d_support = 0.0;
  if (which == SceneRadius::kSupport) {
    const double step = kTwoPi / static_cast<double>(outline.radii.size());
    for (size_t b = 0; b < outline.radii.size(); ++b)
      if (outline.edge[b][0] < 0) d_shadow += o.support_radius * step;
    d_support = kTwoPi * o.support_radius;
  }
  TriangleMesh up = rest, down = rest;
  up.vertices += h * morph;
  down.vertices -= h * morph;
  const double d_specimen = (TriangleAreas(up).sum() - TriangleAreas(down).sum()) / (2.0 * h);
  const double span = result.specimen_area - result.support_area;
  const double dc = DrapeCoefficient(outline.area, result.specimen_area, result.support_area);
  return ((d_shadow - d_support) - dc * (d_specimen - d_support)) / span;
}

// The seam coefficients' relative step (SeamCoefficientStep): B_f moves by 1e-6 of B_f(0) at
// d_max. B_f is linear in its coefficients, and S follows it but for its kink at 1
// (SeamProfile::Multiplier), which no Table 2 seam reaches within d_max.
constexpr double kSeamCoefficientStep = 1e-6;

// The drape's seams with coefficient k of their profile moved by t (a "fitted" profile then: a
// preset's coefficients are Table 2's).
EquilibriumSensitivity::SeamsAt SteppedSeams(int k, const DrapeOptions& o) {
  return [k, o](double t) {
    DrapeOptions stepped = o;
    stepped.seam_profile = SteppedSeamProfile(o.seam_profile, k, t);
    return DrapeSeamList(stepped);
  };
}

// ∂DC/∂a_k: the seams' change of the bending forces (the only ones a profile moves: the
// membrane and the seams' masses do not see it) at the fixed rest and state, through the
// adjoint. The areas do not move.
double SeamCoefficientDcDerivative(const EquilibriumSensitivity& sensitivity,
                                   const Vertices& adjoint, int k, const DrapeOptions& o,
                                   const DrapeResult& result) {
  const Vertices still = Vertices::Zero(adjoint.rows(), 3);
  const double h = SeamCoefficientStep(o.seam_profile, k, kSeamCoefficientStep);
  const Vertices force = sensitivity.RestShapeResidualChange(still, h, SteppedSeams(k, o),
                                                             ClothProblem::kBendingPart);
  return (adjoint.array() * force.array()).sum() / (result.specimen_area - result.support_area);
}

}  // namespace

SceneInputs TakenSceneInputs(const DrapeOptions& o) {
  const SceneInputs taken{TakesSceneRadii(o), TakesSeamCoefficients(o)};
  if (taken.seam) CheckSeamCoefficientSteps(o.seam_profile, kSeamCoefficientStep);
  return taken;
}

namespace {

// The mean over the seeds of one of their derivative lists (each as long as the first seed's).
std::vector<double> SeedMean(const std::vector<DcDerivativeSet>& seeds,
                             std::vector<double> DcDerivativeSet::*list) {
  std::vector<double> mean((seeds.front().*list).size(), 0.0);
  for (const DcDerivativeSet& d : seeds)
    for (size_t k = 0; k < mean.size(); ++k)
      mean[k] += (d.*list)[k] / static_cast<double>(seeds.size());
  return mean;
}

ParameterInfluence RadiusInfluence(SceneRadius which, const DrapeOptions& o, double d_dc_d_r) {
  const double mm = units::MToMm(1.0);
  return which == SceneRadius::kSpecimen
             ? SceneInfluence("specimen_radius", o.specimen_radius, mm, "mm", d_dc_d_r,
                              kSpecimenRadiusUncertainty,
                              "default: a specimen cut to a template, ±1 mm")
             : SceneInfluence("support_radius", o.support_radius, mm, "mm", d_dc_d_r,
                              kSupportRadiusUncertainty,
                              "default: a machined support disk, ±0.1 mm");
}

}  // namespace

DcDerivativeSet DcDerivatives(ClothProblem* problem, const Vertices& x,
                              const Material& material, const DrapeOptions& o,
                              const DrapeResult& result, const std::vector<std::string>& parameters,
                              SceneInputs scene) {
  // The solve stops at o.solver.tolerance; a state 100 times further off is no equilibrium.
  const EquilibriumSensitivity sensitivity(problem, x, material,
                                           std::max(100.0 * o.solver.tolerance, 1e-6));
  const TriangleMesh& rest = problem->rest();
  const ShadowOutline outline =
      TraceShadowOutline(x, rest.triangles, kSensitivityBins, o.support_radius);
  const double scale = result.specimen_area - result.support_area;
  // The adjoint form: one back-substitution for all the parameters.
  const Vertices area_gradient = OutlineAreaGradient(outline, x);
  const Vertices adjoint = sensitivity.Adjoint(area_gradient);
  DcDerivativeSet d;
  for (const std::string& p : parameters)
    d.material.push_back(sensitivity.QuantityDerivativePerUnit(adjoint, p) / scale);
  if (!scene.radii && !scene.seam) return d;
  const auto start = std::chrono::steady_clock::now();
  if (scene.radii)
    for (SceneRadius which : {SceneRadius::kSpecimen, SceneRadius::kSupport})
      d.radii.push_back(RadiusDcDerivative(sensitivity, adjoint, area_gradient, outline, rest,
                                           which, o, result));
  if (scene.seam)
    for (int k = 0; k < kSeamCoefficients; ++k)
      d.seam.push_back(SeamCoefficientDcDerivative(sensitivity, adjoint, k, o, result));
  d.scene_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

void SummariseSensitivities(const Material& material, const std::vector<std::string>& parameters,
                            const std::vector<DcDerivativeSet>& seed_derivatives,
                            const DrapeOptions& o, DrapeResult* result) {
  if (seed_derivatives.empty()) return;
  InfluenceTable table =
      MakeInfluenceTable(material, parameters,
                         SeedMean(seed_derivatives, &DcDerivativeSet::material));
  result->sensitivities = std::move(table.rows);
  result->drape_coefficient_sigma = table.sigma;
  result->sigma_note = std::move(table.sigma_note);
  const std::vector<double> radii = SeedMean(seed_derivatives, &DcDerivativeSet::radii);
  if (radii.size() == kSceneRadii)
    for (int k = 0; k < kSceneRadii; ++k)
      result->scene_sensitivities.push_back(
          RadiusInfluence(static_cast<SceneRadius>(k), o, radii[static_cast<size_t>(k)]));
  const std::vector<double> seam = SeedMean(seed_derivatives, &DcDerivativeSet::seam);
  if (seam.size() == kSeamCoefficients)
    result->seam_sensitivities = SeamInfluences(o.seam_profile, seam);
}

}  // namespace drape_internal
}  // namespace textile
