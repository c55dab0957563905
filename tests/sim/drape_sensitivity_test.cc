#include "textile/sim/scenes/drape_sensitivity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scenes/drape_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"
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
double OutlineDc(const DrapeResult& r) {
  const ShadowOutline o =
      TraceShadowOutline(r.per_seed[0].positions, r.mesh.triangles, kBins, Coarse().support_radius);
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

// σ² = gᵀ C g over b1, b2, c1; the table's changes over each parameter's uncertainty.
TEST(DrapeSensitivity, SigmaPropagatesTheFitCovarianceAndDefaultsAreNamed) {
  Material m = Fig8();
  m.fit["covariance_kes"] = {{1e-4, 2e-5, 0.0}, {2e-5, 4e-4, 0.0}, {0.0, 0.0, 1e-6}};
  DrapeResult r;
  r.converged = true;
  const std::vector<std::string> names = {"b1", "b2", "c1", "stretch.stiffness_N_per_m"};
  const std::vector<double> g = {1000.0, -500.0, 2e4, 1e-5};  // ∂DC/∂p [per SI unit]
  m.defaulted = {"stretch.stiffness_N_per_m"};
  drape_internal::SummariseSensitivities(m, names, {g}, &r);
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
