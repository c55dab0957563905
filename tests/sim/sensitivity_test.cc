#include "textile/sim/solve/sensitivity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/seam.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/solve/static_solver.h"

namespace textile {
namespace {

// The Fig. 8 fabric on an isotropic membrane, and a parsed file with the orthotropic defaults.
Material Fig8() {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  return m;
}

// An 80 × 40 mm strip clamped flat along its first 6.7 mm (two columns of vertices: a single
// pinned row would let it hang straight down, unbent), under its weight: the bending length
// (17 mm) is well inside it, so every law constant, the density and the membrane move it.
struct HangingStrip {
  TriangleMesh mesh = CrissCrossGridMesh(0.08, 0.04, 12, 6);
  std::vector<int> held;
  HangingStrip() {
    for (int v = 0; v < mesh.num_vertices(); ++v)
      if (mesh.vertices(v, 0) < 0.08 / 12 + 1e-12) held.push_back(v);
  }
  std::unique_ptr<ClothProblem> Problem(const Material& m,
                                        const std::vector<Seam>& seams = {}) const {
    auto p = std::make_unique<ClothProblem>(mesh, m, seams, ClothOptions{});
    Vertices fixed(static_cast<long>(held.size()), 3);
    for (size_t k = 0; k < held.size(); ++k) fixed.row(static_cast<long>(k)) = mesh.vertices.row(held[k]);
    p->FixVertices(held, fixed);
    return p;
  }
  // The rest state tilted down, far from equilibrium, and the equilibrium solved from it.
  Vertices Tilted() const {
    Vertices x = mesh.vertices;
    for (int v = 0; v < x.rows(); ++v) x(v, 2) = -0.3 * x(v, 0);
    return x;
  }
  Vertices Equilibrium(const Material& m) const { return Solve(m, Tilted()); }
  // The equilibrium from `start`, solved tight (the differences below need it).
  Vertices Solve(const Material& m, const Vertices& start) const {
    auto p = Problem(m);
    Vertices x = start;
    SolveOptions o;
    o.tolerance = 1e-11;
    o.max_iterations = 400;
    const SolveSummary s = SolveStatic(p.get(), &x, o);
    EXPECT_TRUE(s.converged) << s.message;
    return x;
  }
};

// The strip's equilibrium for the Fig. 8 fabric, its problem and their sensitivity.
class StripSensitivity : public ::testing::Test {
 protected:
  const HangingStrip strip;
  const Material m = Fig8();
  const Vertices x = strip.Equilibrium(m);
  const std::unique_ptr<ClothProblem> problem = strip.Problem(m);
  const EquilibriumSensitivity sensitivity{problem.get(), x, m};
};

// ∂x/∂ln p by one back-substitution against central differences of full solves (started from
// the equilibrium, so they stay on its branch): within 2 % for every parameter that moves it.
TEST_F(StripSensitivity, MatchesDifferencesOfFullSolvesForEachParameter) {
  constexpr double kStep = 1e-3;  // relative
  for (const std::string name :
       {"b1", "b2", "c1", "beta", "areal_density_gsm", "stretch.stiffness_N_per_m"}) {
    const double p = GetMaterialParameter(m, name).si;
    const Vertices up = strip.Solve(WithMaterialParameter(m, name, p * std::exp(kStep)), x);
    const Vertices down = strip.Solve(WithMaterialParameter(m, name, p * std::exp(-kStep)), x);
    const Vertices expected = (up - down) / (2.0 * kStep);
    const Vertices got = sensitivity.Displacement(name);
    ASSERT_GT(expected.norm(), 1e-9) << name << " does not move the strip";
    EXPECT_LT((got - expected).norm(), 0.02 * expected.norm())
        << name << ": |dx| " << got.norm() << " against " << expected.norm();
    for (int v : strip.held) EXPECT_EQ(got.row(v).norm(), 0.0);
  }
  // β scales the law, M_β = β M: its sensitivity is the sum of the three constants'.
  const Vertices sum = sensitivity.Displacement("b1") + sensitivity.Displacement("b2") +
                       sensitivity.Displacement("c1");
  EXPECT_LT((sensitivity.Displacement("beta") - sum).norm(), 1e-6 * sum.norm());
}

// The adjoint form gives g · ∂x/∂p for a quantity's gradient g, every parameter, with one
// back-substitution; a gradient on the held vertices counts for nothing (they do not move).
TEST_F(StripSensitivity, TheAdjointFormIsTheDirectOne) {
  Vertices g(x.rows(), 3);
  for (int v = 0; v < g.rows(); ++v)
    g.row(v) << std::sin(1.0 + v), std::cos(2.0 * v), 0.5 + 0.01 * v;
  const Vertices adjoint = sensitivity.Adjoint(g);
  for (int v : strip.held) EXPECT_EQ(adjoint.row(v).norm(), 0.0);
  for (const std::string& name : MaterialParameterNames(m)) {
    const double direct = (g.array() * sensitivity.DisplacementPerUnit(name).array()).sum();
    EXPECT_NEAR(sensitivity.QuantityDerivativePerUnit(adjoint, name), direct,
                1e-8 * std::abs(direct) + 1e-300)
        << name;
  }
  EXPECT_THROW(sensitivity.Adjoint(Vertices::Zero(3, 3)), InputError);
  g(0, 0) = std::nan("");
  EXPECT_THROW(sensitivity.Adjoint(g), InputError);
  EXPECT_THROW(sensitivity.QuantityDerivativePerUnit(Vertices::Zero(3, 3), "b1"), InputError);
}

// A rest-shape morph as a parameter: (1) the whole strip and its clamp moved sideways move the
// equilibrium with them, exactly (no correction); (2) the overhang lengthened (the free part's
// rest stretched along the strip, the clamp kept) against central differences of full solves
// of the morphed strip, within 2 %.
TEST_F(StripSensitivity, RestShapeMorphsMatchTranslationsAndFullSolves) {
  Vertices sideways = Vertices::Zero(x.rows(), 3);
  sideways.col(1).setOnes();
  const Vertices moved =
      sideways + sensitivity.Solve(sensitivity.RestShapeResidualChange(sideways, 1e-9));
  EXPECT_LT((moved - sideways).norm(), 1e-9 * sideways.norm());

  const double edge = 0.08 / 12;
  Vertices longer = Vertices::Zero(x.rows(), 3);
  for (int v = 0; v < x.rows(); ++v)
    longer(v, 0) = std::max(0.0, strip.mesh.vertices(v, 0) - edge) / (0.08 - edge);  // tip: 1 m/m
  const Vertices got =
      longer + sensitivity.Solve(sensitivity.RestShapeResidualChange(longer, 1e-9));
  const double h = 1e-4;  // 0.1 mm of overhang
  const auto solved = [&](double t) {
    HangingStrip morphed;
    morphed.mesh.vertices += t * longer;
    return morphed.Solve(m, x + t * longer);
  };
  const Vertices expected = (solved(h) - solved(-h)) / (2.0 * h);
  ASSERT_GT(expected.norm(), 1e-6);
  EXPECT_LT((got - expected).norm(), 0.02 * expected.norm())
      << "|dx| " << got.norm() << " against " << expected.norm();
  EXPECT_THROW(sensitivity.RestShapeResidualChange(longer.topRows(3), 1e-9),
               InputError);
  EXPECT_THROW(sensitivity.RestShapeResidualChange(longer, 0.0), InputError);
  const TriangleMesh other = CrissCrossGridMesh(0.08, 0.04, 6, 3);  // another mesh
  EXPECT_THROW(problem->MaterialGradient(x, m, ClothProblem::kAllParts, &other), InputError);
}

// Other seams in MaterialGradient (a seam sensitivity's stepped profile) give the gradient of a
// problem built with them: their bands' multipliers and their masses; as many as the problem's.
TEST_F(StripSensitivity, MaterialGradientWithOtherSeamsIsTheirProblems) {
  SeamLine line(2, 2);
  line << 0.04, 0.0, 0.04, 0.04;  // across the strip, in the overhang
  const auto problem_a = strip.Problem(m, {Seam{SeamPreset("A-plain"), line}});
  const std::vector<Seam> c{Seam{SeamPreset("C-plain"), line}};
  Vertices expected;
  strip.Problem(m, c)->EnergyGradient(x, &expected);
  const Vertices got = problem_a->MaterialGradient(x, m, ClothProblem::kAllParts, nullptr, &c);
  EXPECT_LT((got - expected).norm(), 1e-12 * expected.norm());
  EXPECT_GT((got - problem_a->MaterialGradient(x, m)).norm(), 1e-3 * expected.norm());
  const std::vector<Seam> two{c[0], c[0]};
  EXPECT_THROW(problem_a->MaterialGradient(x, m, ClothProblem::kAllParts, nullptr, &two),
               InputError);
}

TEST(EquilibriumSensitivity, RefusesAStateThatIsNoEquilibriumAndUnknownParameters) {
  const HangingStrip strip;
  const Material m = Fig8();
  auto problem = strip.Problem(m);
  const Vertices bent = strip.Tilted();
  try {
    EquilibriumSensitivity s(problem.get(), bent, m);
    FAIL() << "took a state far from equilibrium";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("not an equilibrium"), std::string::npos) << e.what();
  }
  const Vertices x = strip.Solve(m, bent);
  const EquilibriumSensitivity s(problem.get(), x, m);
  try {
    s.Displacement("b3");
    FAIL() << "took an unknown parameter";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'b3' is not a parameter"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("areal_density_gsm"), std::string::npos);
  }
}

// A strip compressed between its held ends past Euler's load is an equilibrium (flat, by
// symmetry) but no minimum: its stiffness has negative out-of-plane modes.
TEST(EquilibriumSensitivity, RefusesAStiffnessThatIsNotPositiveDefinite) {
  const HangingStrip strip;
  const Material m = Fig8();
  ClothOptions weightless;
  weightless.gravity.setZero();
  ClothProblem p(strip.mesh, m, {}, weightless);
  // Compressed along x by 1 %: the membrane's compressive stress makes out-of-plane modes
  // negative against the bending (an Euler strut past its load).
  Vertices x = strip.mesh.vertices;
  x.col(0) *= 0.99;
  std::vector<int> ends;
  for (int v = 0; v < x.rows(); ++v)
    if (strip.mesh.vertices(v, 0) < 1e-12 || strip.mesh.vertices(v, 0) > 0.08 - 1e-12) ends.push_back(v);
  Vertices fixed(static_cast<long>(ends.size()), 3);
  for (size_t k = 0; k < ends.size(); ++k) fixed.row(static_cast<long>(k)) = x.row(ends[k]);
  p.FixVertices(ends, fixed);
  EXPECT_THROW(EquilibriumSensitivity(&p, x, m, 1e30), ComputeError);
}

}  // namespace
}  // namespace textile
