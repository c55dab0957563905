#include "textile/sim/scenes/drape_sensitivity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "scenes/drape_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/scenes/drape.h"

namespace textile {
namespace {

constexpr int kBins = 2048;

// A flat 0.2 m square centred on the origin.
TriangleMesh Square() {
  TriangleMesh m = CrissCrossGridMesh(0.2, 0.2, 8, 8);
  m.vertices.col(0).array() -= 0.1;
  m.vertices.col(1).array() -= 0.1;
  return m;
}

TEST(ShadowOutline, TracesAStarShapedShadowsAreaAndItsExactDerivative) {
  const TriangleMesh sq = Square();
  const ShadowOutline o = TraceShadowOutline(sq.vertices, sq.triangles, kBins, 0.05);
  EXPECT_NEAR(o.area, 0.04, 2e-5);  // polar area of the square's outline, 2048 rays
  // Growing by (1 + t) about the centre: dA/dt = 2A.
  EXPECT_NEAR(OutlineAreaDerivative(o, sq.vertices, sq.vertices), 2.0 * o.area, 1e-12);
  // A smooth random displacement against central differences of the traced area.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vertices x = sq.vertices;
  for (int v = 0; v < x.rows(); ++v) {
    x(v, 0) *= 1.0 + 0.05 * std::sin(3.0 * std::atan2(x(v, 1), x(v, 0)));
    x(v, 2) = 0.01 * u(rng);
  }
  Vertices dx(x.rows(), 3);
  for (int v = 0; v < x.rows(); ++v) dx.row(v) << u(rng), u(rng), u(rng);
  const ShadowOutline at = TraceShadowOutline(x, sq.triangles, kBins, 0.05);
  const double h = 1e-7;
  const double fd = (TraceShadowOutline(x + h * dx, sq.triangles, kBins, 0.05).area -
                     TraceShadowOutline(x - h * dx, sq.triangles, kBins, 0.05).area) /
                    (2.0 * h);
  EXPECT_NEAR(OutlineAreaDerivative(at, x, dx), fd, 1e-6 * std::abs(fd));
  // Its gradient moves nothing vertical.
  EXPECT_EQ(OutlineAreaGradient(at, x).col(2).norm(), 0.0);
  EXPECT_THROW(OutlineAreaDerivative(at, x, dx.topRows(3)), InputError);
  // The support's rim is the outline where the fabric lies inside it: fixed.
  const ShadowOutline inside = TraceShadowOutline(0.1 * sq.vertices, sq.triangles, kBins, 0.05);
  EXPECT_NEAR(inside.area, std::numbers::pi * 0.05 * 0.05, 1e-9);
  EXPECT_EQ(OutlineAreaDerivative(inside, 0.1 * sq.vertices, sq.vertices), 0.0);
  EXPECT_THROW(TraceShadowOutline(sq.vertices, sq.triangles, 4, 0.05), InputError);
}

// The Fig. 8 fabric on a coarse clamped drape, solved tight so that the full solves'
// differences below resolve a 1 % change.
Material Fig8() {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  return m;
}

DrapeOptions Coarse() {
  DrapeOptions o;
  o.element_size = 0.015;
  o.coarse_to_fine = false;
  o.raster_cell = 0.001;
  o.solver.tolerance = 1e-9;
  return o;
}

// The DC of a seed's state through the traced outline (no raster in the difference).
double OutlineDc(const DrapeResult& r, const DrapeOptions& options = Coarse()) {
  const ShadowOutline o =
      TraceShadowOutline(r.per_seed[0].positions, r.mesh.triangles, kBins, options.support_radius);
  return DrapeCoefficient(o.area, r.specimen_area, r.support_area);
}

// dDC/dln p against central differences of whole drapes (the same seed: the same folds),
// within 2 %.
TEST(DrapeSensitivity, MatchesDifferencesOfWholeDrapes) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  o.sensitivity_parameters = {"b1", "areal_density_gsm"};
  const Material m = Fig8();
  const DrapeResult r = SimulateDrape(m, o);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.sensitivities.size(), 2u);
  EXPECT_GE(r.sensitivities[0].change, r.sensitivities[1].change);  // largest first
  EXPECT_NEAR(OutlineDc(r), r.drape_coefficient, 0.01);  // the outline's DC is the raster's
  DrapeOptions plain = Coarse();
  constexpr double kStep = 0.01;
  for (const ParameterInfluence& s : r.sensitivities) {
    const double p = GetMaterialParameter(m, s.parameter).si;
    const DrapeResult up = SimulateDrape(WithMaterialParameter(m, s.parameter, p * std::exp(kStep)), plain);
    const DrapeResult down =
        SimulateDrape(WithMaterialParameter(m, s.parameter, p * std::exp(-kStep)), plain);
    ASSERT_TRUE(up.converged && down.converged);
    ASSERT_EQ(up.per_seed[0].nodes.angles.size(), down.per_seed[0].nodes.angles.size());
    const double fd = (OutlineDc(up) - OutlineDc(down)) / (2.0 * kStep);
    EXPECT_NEAR(s.d_q_d_ln_p, fd, 0.02 * std::abs(fd)) << s.parameter;
  }
  // Stiffer bends less, heavier hangs more.
  const auto find = [&](const char* name) {
    return *std::find_if(r.sensitivities.begin(), r.sensitivities.end(),
                         [&](const ParameterInfluence& s) { return s.parameter == name; });
  };
  EXPECT_GT(find("b1").d_q_d_ln_p, 0.0);
  EXPECT_LT(find("areal_density_gsm").d_q_d_ln_p, 0.0);
  EXPECT_FALSE(std::isfinite(r.drape_coefficient_sigma));  // no fit covariance
  EXPECT_NE(r.sigma_note.find("no fit covariance"), std::string::npos) << r.sigma_note;
}

// The radial morphs: the specimen's moves its rim by 1 m/m and keeps the clamp; the
// support's moves the clamp's edge by 1 and keeps the rim; both keep diameters straight.
TEST(DrapeSensitivity, RadiusMorphsMoveOneRadiusAndKeepTheOther) {
  DrapeOptions o = Coarse();
  o.seeds = 1;
  const TriangleMesh mesh = SimulateDrape(Fig8(), o).mesh;
  using drape_internal::SceneRadius;
  const Vertices specimen = drape_internal::RadiusMorph(mesh, SceneRadius::kSpecimen, o);
  const Vertices support = drape_internal::RadiusMorph(mesh, SceneRadius::kSupport, o);
  int rim = 0, edge = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector2d p = mesh.vertices.row(v).head<2>().transpose();
    const double r = p.norm();
    const Eigen::Vector2d a = specimen.row(v).head<2>().transpose();
    const Eigen::Vector2d b = support.row(v).head<2>().transpose();
    EXPECT_NEAR(a.x() * p.y() - a.y() * p.x(), 0.0, 1e-12);  // radial
    EXPECT_NEAR(b.x() * p.y() - b.y() * p.x(), 0.0, 1e-12);
    if (r <= o.support_radius) {
      EXPECT_EQ(a.norm(), 0.0);
    }
    if (std::abs(r - o.specimen_radius) < 1e-9) {
      ++rim;
      EXPECT_NEAR(a.norm(), 1.0, 1e-6);
      EXPECT_NEAR(b.norm(), 0.0, 1e-6);
    }
    if (std::abs(r - o.support_radius) < 1e-9) {
      ++edge;
      EXPECT_NEAR(b.norm(), 1.0, 1e-6);
    }
  }
  EXPECT_GT(rim, 24);
  EXPECT_GT(edge, 24);
}

// The DC's derivatives in the radii of the drape `o` (sensitivity on) against central
// differences of the drape on meshes morphed by ±0.2 mm of the radius (the same vertices, solved
// from the equilibrium: the same branch; a mesh made anew would jitter by ~0.003 against a change
// of ~0.002), through the traced outline: within 2 %. Returns the drape.
DrapeResult ExpectRadiiMatchMorphedDrapes(const Material& m, const DrapeOptions& o) {
  DrapeResult r = SimulateDrape(m, o);
  EXPECT_TRUE(r.converged) << r.message;
  if (r.scene_sensitivities.size() != 2u) {
    ADD_FAILURE() << "no radii";
    return r;
  }
  constexpr double kStep = 2e-4;
  for (const drape_internal::SceneRadius which :
       {drape_internal::SceneRadius::kSpecimen, drape_internal::SceneRadius::kSupport}) {
    const auto dc = [&](double t) {
      const drape_internal::MorphedSeed s =
          drape_internal::SolveMorphedSeed(m, o, which, t, r.per_seed[0].positions);
      EXPECT_TRUE(s.summary.converged) << s.summary.message;
      const ShadowOutline outline =
          TraceShadowOutline(s.positions, s.mesh.triangles, kBins, s.support_radius);
      return DrapeCoefficient(outline.area, TriangleAreas(s.mesh).sum(),
                              std::numbers::pi * s.support_radius * s.support_radius);
    };
    const double fd = (dc(kStep) - dc(-kStep)) / (2.0 * kStep);
    const ParameterInfluence& row = r.scene_sensitivities[static_cast<size_t>(which)];
    EXPECT_NEAR(row.d_q_d_p, fd, 0.02 * std::abs(fd)) << row.parameter;
  }
  return r;
}

TEST(DrapeSensitivity, SceneRadiiMatchDifferencesOfMorphedDrapes) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  const Material m = Fig8();
  const DrapeResult r = ExpectRadiiMatchMorphedDrapes(m, o);
  ASSERT_EQ(r.scene_sensitivities.size(), 2u);
  EXPECT_EQ(r.scene_sensitivities[0].parameter, "specimen_radius");
  EXPECT_EQ(r.scene_sensitivities[1].parameter, "support_radius");
  EXPECT_DOUBLE_EQ(r.scene_sensitivities[0].value, 150.0);
  EXPECT_EQ(r.scene_sensitivities[0].unit, "mm");
  // A longer overhang hangs lower; a wider support holds more up.
  EXPECT_LT(r.scene_sensitivities[0].d_q_d_p, 0.0);
  EXPECT_GT(r.scene_sensitivities[1].d_q_d_p, 0.0);
  // A list of parameters leaves the radii out.
  o.sensitivity_parameters = {"b1"};
  EXPECT_TRUE(SimulateDrape(m, o).scene_sensitivities.empty());
  o.rim_extrapolation = true;
  EXPECT_THROW(drape_internal::SolveMorphedSeed(m, o, drape_internal::SceneRadius::kSpecimen, 0.0,
                                                r.per_seed[0].positions),
               InputError);
}

// Seams through the centre (turned by the frame) move with the morph: their ends stay on the
// rim, their bands on the fabric.
TEST(DrapeSensitivity, SceneRadiiWithSeamsThroughTheCentre) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  o.seams = DrapeSeams::kWeftWarp;
  o.frame_angle = 30.0 * std::numbers::pi / 180.0;
  ExpectRadiiMatchMorphedDrapes(Fig8(), o);
}

// With the rim split (the CLI's default), the radii are extrapolated like the parameters; shifted
// seams leave them out, with a note.
TEST(DrapeSensitivity, SceneRadiiThroughTheRimSplitAndNotWithShiftedSeams) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  o.rim_element_size = 0.005;
  o.rim_extrapolation = true;
  o.seams = DrapeSeams::kWeft;
  const DrapeResult split = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(split.converged) << split.message;
  EXPECT_EQ(split.sensitivity_equilibria, 2);
  ASSERT_EQ(split.scene_sensitivities.size(), 2u);
  ASSERT_EQ(split.seam_sensitivities.size(), 4u);
  // The extrapolation 1.5 D_split − 0.5 D_base stays near the base mesh's own derivatives.
  o.rim_extrapolation = false;
  const DrapeResult base = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(base.converged) << base.message;
  EXPECT_EQ(base.sensitivity_equilibria, 1);
  for (size_t k = 0; k < 2; ++k) {
    const double d = split.scene_sensitivities[k].d_q_d_p;
    const double b = base.scene_sensitivities[k].d_q_d_p;
    EXPECT_GT(d * b, 0.0) << k;  // the same sign
    EXPECT_NEAR(d, b, 0.1 * std::abs(b)) << split.scene_sensitivities[k].parameter;
  }
  EXPECT_NEAR(split.seam_sensitivities[3].d_q_d_ln_p, base.seam_sensitivities[3].d_q_d_ln_p,
              0.1 * std::abs(base.seam_sensitivities[3].d_q_d_ln_p));
  DrapeOptions shifted = Coarse();
  shifted.sensitivity = true;
  shifted.seams = DrapeSeams::kShifted;
  shifted.seam_shift = 0.03;
  const DrapeResult r = SimulateDrape(Fig8(), shifted);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_FALSE(r.sensitivities.empty());
  EXPECT_TRUE(r.scene_sensitivities.empty());
  EXPECT_TRUE(HasNote(r.notes, "scene_radii_skipped"));
}

// dDC/dln p of seam rows `names` against central differences of drapes with the seams'
// coefficients scaled by e^(±step) (the same mesh, solved from the equilibrium: the same
// branch), through the traced outline: within 2 %.
void ExpectSeamRowsMatchDrapes(const Material& m, const DrapeOptions& o, const DrapeResult& r,
                               const std::vector<std::string>& names, double step) {
  const auto dc = [&](const std::string& name, double s) {
    SeamProfile p = o.seam_profile;
    p.type = "fitted";
    for (size_t k = 0; k < p.coefficients_mm.size(); ++k)
      if (name == "seam.scale" || name == std::string("seam.a") + "210"[k])
        p.coefficients_mm[k] *= std::exp(s);
    const drape_internal::MorphedSeed seed = drape_internal::SolveMorphedSeed(
        m, o, drape_internal::SceneRadius::kSpecimen, 0.0, r.per_seed[0].positions, &p);
    EXPECT_TRUE(seed.summary.converged) << seed.summary.message;
    const ShadowOutline outline =
        TraceShadowOutline(seed.positions, seed.mesh.triangles, kBins, o.support_radius);
    return DrapeCoefficient(outline.area, r.specimen_area, r.support_area);
  };
  for (const std::string& name : names) {
    const auto row = std::find_if(r.seam_sensitivities.begin(), r.seam_sensitivities.end(),
                                  [&](const ParameterInfluence& s) { return s.parameter == name; });
    ASSERT_NE(row, r.seam_sensitivities.end()) << name;
    const double fd = (dc(name, step) - dc(name, -step)) / (2.0 * step);
    ASSERT_GT(std::abs(fd), 1e-4) << name << " does not move the drape";
    EXPECT_NEAR(row->d_q_d_ln_p, fd, 0.02 * std::abs(fd)) << name;
  }
}

// The seam's coefficients as parameters: a2, a1, a0 and B_f as a whole, against drapes with
// stepped coefficients; a stiffer seam holds the drape up. Shifted seams take them too (no
// morph), but not the radii.
TEST(DrapeSensitivity, SeamCoefficientsMatchDifferencesOfDrapes) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  o.seams = DrapeSeams::kWeft;
  const Material m = Fig8();
  const DrapeResult r = SimulateDrape(m, o);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.seam_sensitivities.size(), 4u);
  EXPECT_EQ(r.seam_sensitivities[0].parameter, "seam.a2");
  EXPECT_EQ(r.seam_sensitivities[2].unit, "-");
  EXPECT_DOUBLE_EQ(r.seam_sensitivities[2].value, 9.07);  // C-plain's a0
  EXPECT_EQ(r.scene_sensitivities.size(), 2u);
  EXPECT_GT(r.seam_sensitivities[3].d_q_d_ln_p, 0.0);
  EXPECT_GT(r.scene_sensitivity_seconds, 0.0);
  EXPECT_LT(r.scene_sensitivity_seconds, r.sensitivity_seconds);
  ExpectSeamRowsMatchDrapes(m, o, r, {"seam.scale", "seam.a2", "seam.a1"}, 0.02);

  o.seams = DrapeSeams::kShifted;
  o.seam_shift = 0.03;
  const DrapeResult shifted = SimulateDrape(m, o);
  ASSERT_TRUE(shifted.converged) << shifted.message;
  EXPECT_TRUE(shifted.scene_sensitivities.empty());
  ExpectSeamRowsMatchDrapes(m, o, shifted, {"seam.a0"}, 0.02);
  EXPECT_THROW(drape_internal::SolveMorphedSeed(m, o, drape_internal::SceneRadius::kSpecimen,
                                                0.001, shifted.per_seed[0].positions),
               InputError);  // a morph would bend shifted seams
  // A list of parameters: no seam rows.
  o.seams = DrapeSeams::kWeft;
  o.sensitivity_parameters = {"b1"};
  EXPECT_TRUE(SimulateDrape(m, o).seam_sensitivities.empty());
}

// The drape's seam rows come from the seeds' mean derivatives and the options' profile:
// ±10 % without a covariance, its sds with one (SeamInfluences' own cases: input_influence_test);
// B_f as a whole is the coefficients' sum, a_k ∂DC/∂a_k. A profile a step from its bounds is
// refused before any solve.
TEST(DrapeSensitivity, SeamRowsTakeTheSeamFilesCovariance) {
  DrapeOptions o;
  o.seams = DrapeSeams::kWeft;
  const std::vector<double> g = {100.0, -2.0, 0.01};  // ∂DC/∂a_k [per 1/mm², 1/mm, 1]
  drape_internal::DcDerivativeSet seed;
  seed.seam = g;
  DrapeResult plain;
  drape_internal::SummariseSensitivities(Fig8(), {}, {seed}, o, &plain);
  ASSERT_EQ(plain.seam_sensitivities.size(), 4u);
  const std::array<double, 3>& a = o.seam_profile.coefficients_mm;
  double sum = 0.0;
  for (size_t k = 0; k < 3; ++k) {
    const ParameterInfluence& row = plain.seam_sensitivities[k];
    EXPECT_FALSE(row.defaulted);  // a measured seam; its uncertainty is the default
    EXPECT_NE(row.uncertainty_source.find("default: ±10 %"), std::string::npos);
    EXPECT_NEAR(row.change, 0.1 * std::abs(a[k] * g[k]), 1e-15);
    EXPECT_NEAR(row.d_q_d_ln_p, a[k] * g[k], 1e-15);
    sum += a[k] * g[k];
  }
  EXPECT_NEAR(plain.seam_sensitivities[3].d_q_d_ln_p, sum, 1e-15);
  EXPECT_NEAR(plain.seam_sensitivities[3].change, 0.1 * std::abs(sum), 1e-15);
  o.seam_profile.covariance = Eigen::Vector3d(1e-10, 4e-6, 0.25).asDiagonal();
  DrapeResult fitted;
  drape_internal::SummariseSensitivities(Fig8(), {}, {seed}, o, &fitted);
  ASSERT_EQ(fitted.seam_sensitivities.size(), 4u);
  EXPECT_NEAR(fitted.seam_sensitivities[1].change, 2.0 * 2e-3, 1e-15);
  EXPECT_NEAR(fitted.seam_sensitivities[2].change, 0.01 * 0.5, 1e-15);
  EXPECT_NE(fitted.seam_sensitivities[0].uncertainty_source.find("covariance"), std::string::npos);
  EXPECT_TRUE(fitted.scene_sensitivities.empty());
  DrapeOptions edge = Coarse();
  edge.sensitivity = true;
  edge.seams = DrapeSeams::kWeft;
  edge.seam_profile.type = "fitted";
  edge.seam_profile.coefficients_mm = {0.0, -0.09, 9.0 + 1e-9};  // B_f(100 mm) = 1e-9
  EXPECT_THROW(drape_internal::TakenSceneInputs(edge), InputError);
  EXPECT_THROW(SimulateDrape(Fig8(), edge), InputError);
  edge.sensitivity_parameters = {"b1"};  // the seam left out
  EXPECT_FALSE(drape_internal::TakenSceneInputs(edge).seam);
}

// σ² = gᵀ C g over b1, b2, c1; the table's changes over each parameter's uncertainty.
TEST(DrapeSensitivity, SigmaPropagatesTheFitCovarianceAndDefaultsAreNamed) {
  Material m = Fig8();
  m.fit["covariance_kes"] = {{1e-4, 2e-5, 0.0}, {2e-5, 4e-4, 0.0}, {0.0, 0.0, 1e-6}};
  DrapeResult r;
  r.converged = true;
  const std::vector<std::string> names = {"b1", "b2", "c1", "stretch.stiffness_N_per_m"};
  const std::vector<double> g = {1000.0, -500.0, 2e4, 1e-5};  // ∂DC/∂p [per SI unit]
  m.defaulted = {"stretch.stiffness_N_per_m"};
  drape_internal::DcDerivativeSet seed;
  seed.material = g;
  drape_internal::SummariseSensitivities(m, names, {seed}, DrapeOptions{}, &r);
  EXPECT_TRUE(r.scene_sensitivities.empty());  // no radii in the seeds' derivatives
  const Eigen::Matrix3d c = *MaterialFitCovariance(m);
  const Eigen::Vector3d v(g[0], g[1], g[2]);
  EXPECT_NEAR(r.drape_coefficient_sigma, std::sqrt(v.dot(c * v)), 1e-15);
  ASSERT_EQ(r.sensitivities.size(), 4u);
  for (size_t k = 1; k < r.sensitivities.size(); ++k)
    EXPECT_GE(r.sensitivities[k - 1].change, r.sensitivities[k].change);
  const auto stretch = std::find_if(r.sensitivities.begin(), r.sensitivities.end(),
                                    [](const ParameterInfluence& s) { return s.defaulted; });
  ASSERT_NE(stretch, r.sensitivities.end());
  EXPECT_EQ(stretch->parameter, "stretch.stiffness_N_per_m");
  EXPECT_NEAR(stretch->uncertainty_ln, std::log(10.0), 1e-12);
  EXPECT_NEAR(stretch->change, 1e-5 * 1000.0 * std::log(10.0), 1e-12);
  EXPECT_NE(stretch->uncertainty_source.find("unmeasured default"), std::string::npos);
}

// --monte-carlo: each sample is solved from the seed's equilibrium; with a covariance tiny
// against the law the samples are the nominal drape, and the spread is the linear σ's.
TEST(DrapeSensitivity, MonteCarloSamplesStartFromTheSeedsEquilibrium) {
  DrapeOptions o = Coarse();
  o.monte_carlo_samples = 6;
  Material m = Fig8();
  m.fit["covariance_kes"] = {{1e-8, 0.0, 0.0}, {0.0, 1e-8, 0.0}, {0.0, 0.0, 1e-10}};
  const DrapeResult r = SimulateDrape(m, o);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_TRUE(r.monte_carlo.has_value());
  EXPECT_FALSE(r.sensitivities.empty());  // implied
  EXPECT_TRUE(r.scene_sensitivities.empty());  // not asked for
  EXPECT_EQ(r.monte_carlo->samples, 6);
  EXPECT_EQ(r.monte_carlo->failed, 0);
  EXPECT_EQ(r.monte_carlo_node_changes, 0);
  EXPECT_DOUBLE_EQ(r.monte_carlo->linear_sigma, r.drape_coefficient_sigma);
  // b1, b2 within 0.1 % (sd 1e-4 gf·cm): the samples' mean is the nominal DC within its
  // sampling error (a sample on another branch, or measured otherwise, would be far off).
  EXPECT_NEAR(r.monte_carlo->mean, r.drape_coefficient,
              3.0 * r.drape_coefficient_sigma / std::sqrt(6.0) + 1e-6);
  EXPECT_GT(r.monte_carlo->sigma, 0.0);
  EXPECT_LT(r.monte_carlo->sigma, 3.0 * r.drape_coefficient_sigma);
  o.monte_carlo_samples = 4;
  EXPECT_THROW(SimulateDrape(Fig8(), o), InputError);  // no covariance: before any solve
  o.monte_carlo_samples = 1;
  EXPECT_THROW(SimulateDrape(m, o), InputError);
}

TEST(DrapeSensitivity, BadRequestsAreRefusedBeforeAnySolve) {
  DrapeOptions o = Coarse();
  o.sensitivity = true;
  o.sensitivity_parameters = {"b7"};
  EXPECT_THROW(SimulateDrape(Fig8(), o), InputError);
  o.sensitivity_parameters = {};
  Material bad = Fig8();
  bad.fit["covariance_kes"] = {{1.0, 2.0, 0.0}, {2.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};  // eigenvalue -1
  try {
    SimulateDrape(bad, o);
    FAIL() << "took a covariance that is not positive semi-definite";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not positive semi-definite"), std::string::npos);
  }
  o.mount = DrapeMount::kResting;
  o.coarse_to_fine = false;
  std::string why;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_NE(why.find("clamped mount only"), std::string::npos) << why;
}

}  // namespace
}  // namespace textile
