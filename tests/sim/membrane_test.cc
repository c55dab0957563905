#include "textile/sim/elements/membrane.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <random>

#include "textile/sim/core/error.h"
#include "textile/sim/law/membrane_law.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/mesh/pattern_mesh.h"

namespace textile {
namespace {

constexpr double kStiffness = 1000.0;  // docs/spec/physics.md default [N/m]
constexpr double kPoisson = 0.3;
const MembraneModel kModels[] = {MembraneModel::kCorotationalLinear, MembraneModel::kStVK};

std::string Name(MembraneModel m) { return m == MembraneModel::kStVK ? "StVK" : "corotational"; }

// A 10 cm criss-cross patch with its interior vertices jittered: irregular rest triangles.
TriangleMesh IrregularPatch(unsigned seed) {
  TriangleMesh m = CrissCrossGridMesh(0.1, 0.1, 3, 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.vertices(v, 0), y = m.vertices(v, 1);
    if (x > 1e-9 && x < 0.1 - 1e-9 && y > 1e-9 && y < 0.1 - 1e-9)
      m.vertices.row(v) += Eigen::RowVector3d(u(rng), u(rng), 0);
  }
  return m;
}

Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  const Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

// The rest shape rotated and moved in 3D, each vertex displaced by up to `noise` [m] (vertex
// spacing ~25 mm): a mix of stretched, compressed and sheared triangles.
Vertices RandomConfiguration(const TriangleMesh& rest, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  const Eigen::Matrix3d r = RandomRotation(rng);
  Vertices x = rest.vertices * r.transpose();
  for (int v = 0; v < x.rows(); ++v)
    x.row(v) += Eigen::RowVector3d(0.3 + u(rng), -0.2 + u(rng), 0.1 + u(rng));
  return x;
}

Vertices Gradient(const MembraneElements& m, const Vertices& x) {
  Vertices g = Vertices::Zero(x.rows(), 3);
  m.AddGradient(x, g);
  return g;
}

Eigen::MatrixXd DenseHessian(const MembraneElements& m, const Vertices& x, bool project_psd) {
  std::vector<Eigen::Triplet<double>> triplets;
  m.AddHessianTriplets(x, &triplets, project_psd);
  Eigen::SparseMatrix<double> h(3 * x.rows(), 3 * x.rows());
  h.setFromTriplets(triplets.begin(), triplets.end());
  return Eigen::MatrixXd(h);
}

// Central difference of f (the energy, or the gradient as a 3V vector) along coordinate c of
// vertex v. Step 1e-7 m: truncation ~ (1e-7)² · ψ''' and round-off ~ 1e-16 · E / 1e-7 both far
// below 1e-6 of the largest force (~10 N).
template <typename F>
auto CentralDifference(Vertices& x, int v, int c, F f) {
  const double step = 1e-7, keep = x(v, c);
  x(v, c) = keep + step;
  const auto plus = f(x);
  x(v, c) = keep - step;
  const auto minus = f(x);
  x(v, c) = keep;
  return decltype(plus)((plus - minus) / (2 * step));
}

// The largest gap between the gradient and central differences of the energy, over the
// gradient's largest entry.
double RelativeGradientError(const MembraneElements& m, Vertices x) {
  const Vertices g = Gradient(m, x);
  const auto energy = [&](const Vertices& y) { return m.Energy(y); };
  double max_err = 0;
  for (int v = 0; v < x.rows(); ++v)
    for (int c = 0; c < 3; ++c)
      max_err = std::max(max_err, std::abs(CentralDifference(x, v, c, energy) - g(v, c)));
  return max_err / g.cwiseAbs().maxCoeff();
}

// The same for the raw Hessian against central differences of the gradient, which must also be
// symmetric.
double RelativeHessianError(const MembraneElements& m, Vertices x) {
  const Eigen::MatrixXd h = DenseHessian(m, x, /*project_psd=*/false);
  EXPECT_LT((h - h.transpose()).cwiseAbs().maxCoeff(), 1e-10 * h.cwiseAbs().maxCoeff());
  const auto gradient = [&](const Vertices& y) {
    const Vertices g = Gradient(m, y);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(g.data(), g.size()));
  };
  double max_err = 0;
  for (int v = 0; v < x.rows(); ++v)
    for (int c = 0; c < 3; ++c)
      max_err = std::max(
          max_err, (CentralDifference(x, v, c, gradient) - h.col(3 * v + c)).cwiseAbs().maxCoeff());
  return max_err / h.cwiseAbs().maxCoeff();
}

TEST(Membrane, GradientMatchesCentralDifferences) {
  const TriangleMesh rest = IrregularPatch(1);
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    for (unsigned seed = 0; seed < 3; ++seed)
      EXPECT_LT(RelativeGradientError(m, RandomConfiguration(rest, 0.006, seed)), 1e-6)
          << Name(model) << " seed " << seed;
  }
}

TEST(Membrane, HessianMatchesCentralDifferencesOfTheGradient) {
  const TriangleMesh rest = IrregularPatch(2);
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    for (unsigned seed = 0; seed < 3; ++seed)
      EXPECT_LT(RelativeHessianError(m, RandomConfiguration(rest, 0.006, 10 + seed)), 1e-6)
          << Name(model) << " seed " << seed;
  }
}

// StVK soft in compression (compression ratio c < 1): its own energy, gradient and Hessian on
// the same mix of stretched, compressed and sheared triangles (principal strains of both signs;
// the C¹ energy's stiffness jumps where one changes sign, which these states do not straddle).
TEST(Membrane, SoftCompressionGradientAndHessianMatchCentralDifferences) {
  const TriangleMesh rest = IrregularPatch(3);
  for (const double c : {0.2, 0.01}) {
    const MembraneElements m(rest, kStiffness, kPoisson, MembraneModel::kStVK, c);
    for (unsigned seed = 0; seed < 3; ++seed) {
      EXPECT_LT(RelativeGradientError(m, RandomConfiguration(rest, 0.006, 20 + seed)), 1e-6)
          << "c " << c << " seed " << seed;
      EXPECT_LT(RelativeHessianError(m, RandomConfiguration(rest, 0.006, 30 + seed)), 1e-6)
          << "c " << c << " seed " << seed;
    }
  }
}

TEST(Membrane, ZeroEnergyAndForceAtRestAndAfterRigidMotion) {
  const TriangleMesh rest = IrregularPatch(3);
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    const Vertices moved = RandomConfiguration(rest, 0.0, 7);  // rotated out of the plane, moved
    for (const Vertices& x : {rest.vertices, moved}) {
      // Round-off: strains ~1e-16 give energies ~ k ε² A ~ 1e-32 J and forces ~ k ε L ~ 1e-14 N.
      EXPECT_LT(std::abs(m.Energy(x)), 1e-20) << Name(model);
      EXPECT_LT(Gradient(m, x).cwiseAbs().maxCoeff(), 1e-10) << Name(model);
    }
  }
}

TEST(Membrane, InvariantUnderRigidMotion) {
  const TriangleMesh rest = IrregularPatch(4);
  std::mt19937 rng(5);
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    const Vertices x = RandomConfiguration(rest, 0.006, 21);
    const Eigen::Matrix3d r = RandomRotation(rng);
    Vertices y = x * r.transpose();
    y.rowwise() += Eigen::RowVector3d(1.0, -2.0, 0.5);
    EXPECT_NEAR(m.Energy(y), m.Energy(x), 1e-12 * m.Energy(x)) << Name(model);
    const Vertices gx = Gradient(m, x), gy = Gradient(m, y);
    EXPECT_LT((gy - gx * r.transpose()).cwiseAbs().maxCoeff(), 1e-9 * gx.cwiseAbs().maxCoeff())
        << Name(model);
  }
}

TEST(Membrane, ForcesSumToZeroWithNoNetTorque) {
  const TriangleMesh rest = IrregularPatch(5);
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    for (unsigned seed = 0; seed < 5; ++seed) {
      const Vertices x = RandomConfiguration(rest, 0.008, 30 + seed);
      const Vertices g = Gradient(m, x);
      Eigen::Vector3d torque = Eigen::Vector3d::Zero();
      for (int v = 0; v < x.rows(); ++v)
        torque += Eigen::Vector3d(x.row(v)).cross(Eigen::Vector3d(g.row(v)));
      const double scale = g.cwiseAbs().maxCoeff();
      EXPECT_LT(g.colwise().sum().cwiseAbs().maxCoeff(), 1e-12 * scale * x.rows()) << Name(model);
      EXPECT_LT(torque.cwiseAbs().maxCoeff(), 1e-12 * scale * x.rows()) << Name(model);
    }
  }
}

// A deformation gradient applied to a whole mesh (x = A X, A 3×2 acting on (X, Y)).
Vertices Affine(const TriangleMesh& rest, const Eigen::Matrix<double, 3, 2>& a) {
  Vertices x(rest.num_vertices(), 3);
  for (int v = 0; v < rest.num_vertices(); ++v)
    x.row(v) = (a * rest.vertices.row(v).head<2>().transpose()).transpose();
  return x;
}

// ψ = k / (2 (1 - ν²)) (e11² + e22² + 2 ν e11 e22 + 2 (1 - ν) e12²), the plane-stress law.
double PlaneStressDensity(double k, double nu, const Eigen::Matrix2d& e) {
  return k / (2 * (1 - nu * nu)) *
         (e(0, 0) * e(0, 0) + e(1, 1) * e(1, 1) + 2 * nu * e(0, 0) * e(1, 1) +
          2 * (1 - nu) * e(0, 1) * e(0, 1));
}

TEST(Membrane, PatchTestUniformStrainGivesTheAnalyticEnergyAndNoInteriorForce) {
  // An unstructured Gmsh mesh of a 20 × 10 cm strip.
  PatternMeshOptions options;
  options.element_size = 0.02;
  const TriangleMesh rest = MeshRectangle(0.2, 0.1, {}, options).mesh;
  const double area = TriangleAreas(rest).sum();
  std::vector<bool> boundary(rest.num_vertices(), false);
  for (const auto& e : BoundaryEdges(rest)) boundary[e[0]] = boundary[e[1]] = true;
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  // Corotational: principal stretches along x and y (rotation-free strain diag(ε1, ε2)), rotated.
  {
    const double e1 = 0.02, e2 = -0.005;
    const MembraneElements m(rest, kStiffness, kPoisson, MembraneModel::kCorotationalLinear);
    const Eigen::Matrix<double, 3, 2> a =
        r.leftCols<2>() * Eigen::Vector2d(1 + e1, 1 + e2).asDiagonal();
    const Vertices x = Affine(rest, a);
    const Eigen::Matrix2d strain = Eigen::Vector2d(e1, e2).asDiagonal();
    EXPECT_NEAR(m.Energy(x), area * PlaneStressDensity(kStiffness, kPoisson, strain),
                1e-12 * m.Energy(x));
    const Vertices g = Gradient(m, x);
    for (int v = 0; v < rest.num_vertices(); ++v) {
      if (!boundary[v]) {
        EXPECT_LT(g.row(v).norm(), 1e-10 * g.cwiseAbs().maxCoeff()) << "vertex " << v;
      }
    }
    // The right edge carries the traction σ11 · height = k (ε1 + ν ε2) / (1 - ν²) · 0.1, along R x̂.
    Eigen::Vector3d right = Eigen::Vector3d::Zero();
    for (int v = 0; v < rest.num_vertices(); ++v) {
      if (rest.vertices(v, 0) > 0.2 - 1e-12) right += g.row(v).transpose();
    }
    const double sigma11 = kStiffness * (e1 + kPoisson * e2) / (1 - kPoisson * kPoisson);
    // The corner vertices also carry half an edge of the top/bottom edges' zero shear traction.
    EXPECT_LT((right - sigma11 * 0.1 * r.col(0)).norm(), 1e-9 * sigma11 * 0.1);
  }
  // StVK: any uniform F, Green strain E = ½(FᵀF - I).
  {
    Eigen::Matrix2d f2;
    f2 << 1.03, 0.02, -0.01, 0.98;
    const MembraneElements m(rest, kStiffness, kPoisson, MembraneModel::kStVK);
    const Eigen::Matrix<double, 3, 2> a = r.leftCols<2>() * f2;
    const Vertices x = Affine(rest, a);
    const Eigen::Matrix2d green = 0.5 * (f2.transpose() * f2 - Eigen::Matrix2d::Identity());
    EXPECT_NEAR(m.Energy(x), area * PlaneStressDensity(kStiffness, kPoisson, green),
                1e-12 * m.Energy(x));
    const Vertices g = Gradient(m, x);
    for (int v = 0; v < rest.num_vertices(); ++v) {
      if (!boundary[v]) {
        EXPECT_LT(g.row(v).norm(), 1e-10 * g.cwiseAbs().maxCoeff()) << "vertex " << v;
      }
    }
  }
}

TEST(Membrane, StripStretchedOnePercentStoresHalfKEpsilonSquaredArea) {
  const TriangleMesh strip = RegularGridMesh(0.2, 0.05, 8, 2);
  const double eps = 0.01, area = 0.2 * 0.05;
  Eigen::Matrix<double, 3, 2> a = Eigen::Matrix<double, 3, 2>::Zero();
  a(0, 0) = 1 + eps;
  a(1, 1) = 1;  // lateral size held (ν = 0, so no lateral stress either way)
  const Vertices x = Affine(strip, a);
  const double expected = 0.5 * kStiffness * eps * eps * area;  // 5e-4 J
  const MembraneElements linear(strip, kStiffness, 0.0, MembraneModel::kCorotationalLinear);
  EXPECT_NEAR(linear.Energy(x), expected, 1e-12 * expected);
  // Green strain E11 = ε + ε²/2: StVK stores ½ k (ε + ε²/2)² A, 1.0025 % more.
  const MembraneElements stvk(strip, kStiffness, 0.0, MembraneModel::kStVK);
  EXPECT_NEAR(stvk.Energy(x), 0.5 * kStiffness * std::pow(eps + eps * eps / 2, 2) * area,
              1e-12 * expected);
  EXPECT_NEAR(stvk.Energy(x) / expected, 1.0, 0.011);
  // Tiny strains are not lost in round-off: ε = 1e-7 still gives ½ k ε² A to 1e-6.
  a(0, 0) = 1 + 1e-7;
  const Vertices tiny = Affine(strip, a);
  const double tiny_expected = 0.5 * kStiffness * 1e-14 * area;
  EXPECT_NEAR(linear.Energy(tiny), tiny_expected, 1e-6 * tiny_expected);
  EXPECT_NEAR(stvk.Energy(tiny), tiny_expected, 1e-6 * tiny_expected);
}

double MinEigenvalue(const Eigen::MatrixXd& h) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(h).eigenvalues().minCoeff();
}

TEST(Membrane, StabilisedHessianIsPsdWhenCompressed) {
  const TriangleMesh rest = IrregularPatch(6);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  Vertices x =
      Affine(rest, (Eigen::Matrix<double, 3, 2>() << 0.7, 0.0, 0.05, 0.9, 0.0, 0.0).finished());
  for (int v = 0; v < x.rows(); ++v) x.row(v) += Eigen::RowVector3d(u(rng), u(rng), u(rng));
  for (MembraneModel model : kModels) {
    const MembraneElements m(rest, kStiffness, kPoisson, model);
    const Eigen::MatrixXd raw = DenseHessian(m, x, false);
    const Eigen::MatrixXd stable = DenseHessian(m, x, true);
    const double scale = raw.cwiseAbs().maxCoeff();
    EXPECT_LT(MinEigenvalue(raw), -1e-3 * scale)
        << Name(model) << ": compression makes the raw Hessian indefinite";
    // Eigen-solver round-off on a matrix of norm ~scale.
    EXPECT_GT(MinEigenvalue(stable), -1e-10 * scale) << Name(model);
    // The energy and gradient are those of the unstabilised element: the equilibria are unchanged.
  }
}

// The elements' projection comes from their eigensystem in closed form; it must be the
// eigen-solve's: ∂P/∂F recovered from the raw 9×9 Hessian (H = A Gᵀ h G, G = ∂vec(F)/∂x of full
// row rank), its negative eigenvalues clamped, mapped back. Over random triangles that are
// stretched, compressed, sheared, nearly collapsed or equally stretched both ways, for both
// models and three Poisson ratios.
TEST(Membrane, ProjectionIsTheEigenSolvesClampedMatrix) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int indefinite = 0, cases = 0;
  for (const MembraneModel model : kModels) {
    for (const double poisson : {0.3, -0.5, 0.45}) {
      const MembraneLame lame = MembraneLame::FromStretch(kStiffness, poisson);
      for (int trial = 0; trial < 60; ++trial) {
        const Eigen::Vector2d p[3] = {{0, 0},
                                      {0.01 + 0.002 * unit(rng), 0.001 * unit(rng)},
                                      {0.004 * unit(rng), 0.01 + 0.002 * unit(rng)}};
        Eigen::Matrix2d dm;
        dm << p[1] - p[0], p[2] - p[0];
        const Eigen::Matrix2d b = dm.inverse();
        const double area = 0.5 * std::abs(dm.determinant());
        // F = R diag(σ1, σ2) Vᵀ: σ from 0.5 to 1.2, nearly 0 or equal in some trials.
        double s1 = 0.85 + 0.35 * unit(rng), s2 = 0.85 + 0.35 * unit(rng);
        if (trial % 10 == 3) s2 = 1e-3;
        if (trial % 10 == 5) s2 = trial < 30 ? 1e-5 : 2e-6;  // nearly collapsed
        if (trial % 10 == 9) s2 = trial < 30 ? 0.0 : 5e-7;   // collapsed: the eigen-solve
        if (trial % 10 == 7) s2 = s1;
        const Eigen::Matrix3d r =
            Eigen::AngleAxisd(3.0 * unit(rng),
                              Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized())
                .toRotationMatrix();
        const Eigen::Matrix2d v = Eigen::Rotation2Dd(3.0 * unit(rng)).toRotationMatrix();
        const Eigen::Matrix<double, 3, 2> f =
            r.leftCols<2>() * Eigen::Vector2d(s1, s2).asDiagonal() * v.transpose();
        Eigen::Matrix3d x;
        for (int a = 0; a < 3; ++a)
          x.row(a) = (f * p[a]).transpose() + Eigen::RowVector3d(0.1, -0.2, 0.3);
        const Eigen::Matrix<double, 9, 9> raw = MembraneHessian(model, lame, b, area, x, false);
        const Eigen::Matrix<double, 9, 9> projected =
            MembraneHessian(model, lame, b, area, x, true);
        Eigen::Matrix<double, 6, 9> g = Eigen::Matrix<double, 6, 9>::Zero();
        for (int j = 0; j < 2; ++j) {
          const double c[3] = {-(b(0, j) + b(1, j)), b(0, j), b(1, j)};
          for (int a = 0; a < 3; ++a)
            g.block<3, 3>(3 * j, 3 * a) = c[a] * Eigen::Matrix3d::Identity();
        }
        const Eigen::Matrix<double, 6, 6> left = (g * g.transpose()).inverse();
        const Eigen::Matrix<double, 6, 6> h = left * g * raw * g.transpose() * left / area;
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(0.5 *
                                                                             (h + h.transpose()));
        if (eig.eigenvalues().minCoeff() < -1e-6 * eig.eigenvalues().cwiseAbs().maxCoeff())
          ++indefinite;
        ++cases;
        const Eigen::Matrix<double, 6, 6> clamped = eig.eigenvectors() *
                                                    eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
                                                    eig.eigenvectors().transpose();
        const Eigen::Matrix<double, 9, 9> expected = area * g.transpose() * clamped * g;
        EXPECT_LT((projected - expected).cwiseAbs().maxCoeff(), 1e-9 * raw.cwiseAbs().maxCoeff())
            << Name(model) << ", ν " << poisson << ", trial " << trial << ", σ " << s1 << ", "
            << s2;
      }
    }
  }
  EXPECT_GT(indefinite, cases / 4);  // the clamping was exercised, not just the identity
}

// Under uniform strain the soft membrane stores StVK's energy where both principal strains
// and the area grow (there it hands over to StVK's own closed forms, so that case checks the
// hand-over), c times it where all of them shrink, and in between where the sheet is stretched
// one way and compressed the other; its projected Hessian is positive semi-definite and equals
// the raw one where that already is.
TEST(Membrane, SoftCompressionIsStvkInTensionAndCTimesItInCompression) {
  const TriangleMesh rest = IrregularPatch(8);
  const double c = 0.01;
  const MembraneElements stvk(rest, kStiffness, kPoisson, MembraneModel::kStVK);
  const MembraneElements soft(rest, kStiffness, kPoisson, MembraneModel::kStVK, c);
  const auto strained = [&](double a, double b) {
    return Affine(rest, (Eigen::Matrix<double, 3, 2>() << a, 0.0, 0.0, b, 0.0, 0.0).finished());
  };
  const Vertices stretched = strained(1.05, 1.02), compressed = strained(0.95, 0.97),
                 mixed = strained(1.01, 0.95);
  EXPECT_NEAR(soft.Energy(stretched), stvk.Energy(stretched), 1e-12 * stvk.Energy(stretched));
  EXPECT_NEAR(soft.Energy(compressed), c * stvk.Energy(compressed),
              1e-12 * stvk.Energy(compressed));
  EXPECT_GT(soft.Energy(mixed), c * stvk.Energy(mixed));
  EXPECT_LT(soft.Energy(mixed), 0.5 * stvk.Energy(mixed));
  for (const Vertices* x : {&stretched, &compressed, &mixed}) {
    const Eigen::MatrixXd raw = DenseHessian(soft, *x, false);
    const Eigen::MatrixXd projected = DenseHessian(soft, *x, true);
    const double scale = raw.cwiseAbs().maxCoeff();
    EXPECT_GT(MinEigenvalue(projected), -1e-10 * scale);
    if (MinEigenvalue(raw) > -1e-10 * scale) {
      EXPECT_LT((projected - raw).cwiseAbs().maxCoeff(), 1e-9 * scale);
    }
  }
  // Compressed, the raw Hessian is indefinite (the geometric stiffness of a compressive
  // stress, as in StVK, c times smaller); the projection above took that out.
  const Eigen::MatrixXd compressed_raw = DenseHessian(soft, compressed, false);
  EXPECT_LT(MinEigenvalue(compressed_raw), -1e-6 * compressed_raw.cwiseAbs().maxCoeff());
}

// The soft membrane's eigensystem against StVK's Hessian, raw and projected, without finite
// differences: just below c = 1 on compressed and mixed triangles (every weight about 1: the
// eigenvalue formulas and eigenvectors), and at c = 0.3 on triangles compressed both ways, where
// ψ is exactly c times StVK's (the weights).
TEST(Membrane, SoftCompressionJustBelowOneIsStvk) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const MembraneLame stvk = MembraneLame::FromStretch(kStiffness, kPoisson);
  Eigen::Matrix2d dm;
  dm << 0.01, 0.004, 0.0, 0.009;
  const Eigen::Matrix2d b = dm.inverse();
  for (int trial = 0; trial < 100; ++trial) {
    const bool both = trial >= 50;  // compressed both ways, c = 0.3
    const double c = both ? 0.3 : 1.0 - 1e-12;
    const MembraneLame soft = MembraneLame::FromStretch(kStiffness, kPoisson, c);
    const Eigen::Vector2d sigma(both ? 0.85 + 0.1 * unit(rng) : 0.85 + 0.3 * unit(rng),
                                0.75 + 0.2 * unit(rng));  // σ2 < 1, and σ1 < 1 when both
    const Eigen::Matrix3d r = RandomRotation(rng);
    const Eigen::Matrix2d v = Eigen::Rotation2Dd(3.0 * unit(rng)).toRotationMatrix();
    const Eigen::Matrix<double, 3, 2> f = r.leftCols<2>() * sigma.asDiagonal() * v.transpose();
    Eigen::Matrix3d x;
    x.row(0).setZero();
    x.row(1) = (f * dm.col(0)).transpose();
    x.row(2) = (f * dm.col(1)).transpose();
    for (const bool project : {false, true}) {
      const Eigen::Matrix<double, 9, 9> expected =
          (both ? c : 1.0) * MembraneHessian(MembraneModel::kStVK, stvk, b, 4.5e-5, x, project);
      const Eigen::Matrix<double, 9, 9> got =
          MembraneHessian(MembraneModel::kStVK, soft, b, 4.5e-5, x, project);
      EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff())
          << "trial " << trial << ", σ " << sigma.transpose()
          << (project ? ", projected" : ", raw");
    }
  }
}

// The soft StVK with a buckling strain: its own energy, gradient and Hessian against central
// differences (compressed past ε_b, within it, and mixed), and under uniform strain the plain
// StVK energy while every principal strain and the area stay above -ε_b.
TEST(Membrane, SoftCompressionWithBucklingStrain) {
  const TriangleMesh rest = IrregularPatch(21);
  const double eb = 0.01;
  const MembraneElements m(rest, kStiffness, kPoisson, MembraneModel::kStVK, 0.1, eb);
  for (unsigned seed = 0; seed < 3; ++seed) {
    EXPECT_LT(RelativeGradientError(m, RandomConfiguration(rest, 0.006, 60 + seed)), 1e-6) << seed;
    EXPECT_LT(RelativeHessianError(m, RandomConfiguration(rest, 0.006, 70 + seed)), 1e-6) << seed;
  }
  const auto strained = [&](double a, double b) {
    return Affine(rest, (Eigen::Matrix<double, 3, 2>() << a, 0.0, 0.0, b, 0.0, 0.0).finished());
  };
  for (const auto& x : {strained(0.95, 0.93), strained(1.02, 0.96), strained(0.96, 0.97)}) {
    EXPECT_LT(RelativeGradientError(m, x), 1e-6);
    EXPECT_LT(RelativeHessianError(m, x), 1e-6);
  }
  const MembraneElements stvk(rest, kStiffness, kPoisson, MembraneModel::kStVK);
  const MembraneElements no_buckling(rest, kStiffness, kPoisson, MembraneModel::kStVK, 0.1);
  // Both principal strains -0.2 %, the area -0.4 %: within ε_b, StVK's energy.
  const Vertices within = strained(0.998, 0.998);
  EXPECT_NEAR(m.Energy(within), stvk.Energy(within), 1e-12 * stvk.Energy(within));
  EXPECT_LT(no_buckling.Energy(within), 0.2 * stvk.Energy(within));
  // Past it, softer than StVK but stiffer than without the buckling strain.
  const Vertices past = strained(0.95, 0.96);
  EXPECT_LT(m.Energy(past), 0.5 * stvk.Energy(past));
  EXPECT_GT(m.Energy(past), no_buckling.Energy(past));
  const Eigen::MatrixXd projected = DenseHessian(m, past, true);
  EXPECT_GT(MinEigenvalue(projected), -1e-10 * projected.cwiseAbs().maxCoeff());
}

TEST(Membrane, CompressionRatioOutsideItsRangeIsRefused) {
  const TriangleMesh rest = RegularGridMesh(0.1, 0.1, 2, 2);
  for (const double c : {0.0, 5e-4, 1.5, std::nan("")}) {
    try {
      MembraneElements(rest, 1000.0, 0.3, MembraneModel::kStVK, c);
      ADD_FAILURE() << "compression " << c << " was taken";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).substr(0, 50),
                "membrane: compression ratio must lie in [0.001, 1]");
    }
  }
}

TEST(Membrane, StabilisationLeavesStretchedStvkElementsAlone) {
  const TriangleMesh rest = IrregularPatch(7);
  const Vertices x =
      Affine(rest, (Eigen::Matrix<double, 3, 2>() << 1.05, 0.01, 0.0, 1.02, 0.0, 0.0).finished());
  const MembraneElements m(rest, kStiffness, kPoisson, MembraneModel::kStVK);
  const Eigen::MatrixXd raw = DenseHessian(m, x, false);
  EXPECT_EQ(raw, DenseHessian(m, x, true));
  EXPECT_GT(MinEigenvalue(raw), -1e-10 * raw.cwiseAbs().maxCoeff());
}

TEST(Membrane, SingleElementFunctionsAgreeWithTheMesh) {
  TriangleMesh tri;
  tri.vertices.resize(3, 3);
  tri.vertices << 0, 0, 0, 0.02, 0, 0, 0.005, 0.015, 0;
  tri.triangles.resize(1, 3);
  tri.triangles << 0, 1, 2;
  const MembraneElements m(tri, kStiffness, kPoisson, MembraneModel::kStVK);
  Eigen::Matrix2d dm;
  dm << 0.02, 0.005, 0, 0.015;
  Eigen::Matrix3d x;
  x << 0, 0, 0, 0.021, 0.001, 0.002, 0.004, 0.016, 0;
  const MembraneLame lame = MembraneLame::FromStretch(kStiffness, kPoisson);
  EXPECT_NEAR(MembraneEnergy(MembraneModel::kStVK, lame, dm.inverse(), 1.5e-4, x),
              m.Energy(Vertices(x)), 1e-18);
  EXPECT_NEAR(lame.mu, 1000 / 2.6, 1e-12);
  EXPECT_NEAR(lame.lambda, 300 / 0.91, 1e-12);
}

TEST(Membrane, BadInputIsRefusedByName) {
  const TriangleMesh rest = RegularGridMesh(0.1, 0.1, 2, 2);
  auto error = [&](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no InputError)";
  };
  EXPECT_EQ(error([&] { MembraneElements(rest, -5.0, 0.3, MembraneModel::kStVK); }),
            "membrane: stretch_stiffness must be a positive number of N/m, got -5");
  EXPECT_EQ(error([&] { MembraneElements(rest, 1000.0, 1.0, MembraneModel::kStVK); }),
            "membrane: poisson must lie in (-1, 1) for a stable sheet, got 1");
  EXPECT_EQ(error([&] { MembraneElements(rest, std::nan(""), 0.3, MembraneModel::kStVK); }),
            "membrane: stretch_stiffness must be a positive number of N/m, got nan");
  TriangleMesh flat = rest;
  flat.vertices.row(flat.triangles(3, 2)) = flat.vertices.row(flat.triangles(3, 0));
  EXPECT_EQ(error([&] { MembraneElements(flat, 1000.0, 0.3, MembraneModel::kStVK); }).substr(0, 39),
            "membrane: rest triangle 0 is degenerate");
  TriangleMesh bad = rest;
  bad.triangles(1, 1) = 99;
  EXPECT_EQ(error([&] { MembraneElements(bad, 1000.0, 0.3, MembraneModel::kStVK); }),
            "membrane: triangle 1 refers to vertex 99, outside 0..8");
  const MembraneElements m(rest, 1000.0, 0.3, MembraneModel::kStVK);
  EXPECT_EQ(error([&] { m.Energy(Vertices::Zero(4, 3)); }),
            "membrane: positions have 4 rows, the mesh has 9 vertices");
}

// ---- The orthotropic membrane (MembraneModel::kOrthotropic).

// A material with an orthotropic block (nothing parses one yet: built in code).
Material Orthotropic(const TensileCurve& warp, const TensileCurve& weft, double shear,
                     double ratio = 1.0, double buckling_strain = 0.0) {
  Material m;
  m.orthotropic = OrthotropicMembrane{warp, weft, shear};
  m.compression_ratio = ratio;
  m.buckling_strain = buckling_strain;
  return m;
}

// The rest mesh under the uniform gradient a, each vertex displaced by up to `noise` [m], then
// rotated and moved rigidly.
Vertices Deformed(const TriangleMesh& rest, const Eigen::Matrix<double, 3, 2>& a, double noise,
                  unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  const Eigen::Matrix3d r = RandomRotation(rng);
  Vertices x = Affine(rest, a);
  for (int v = 0; v < x.rows(); ++v) x.row(v) += Eigen::RowVector3d(u(rng), u(rng), u(rng));
  x = x * r.transpose();
  x.rowwise() += Eigen::RowVector3d(0.3, -0.2, 0.1);
  return x;
}

Eigen::Matrix<double, 3, 2> Gradient3x2(double f11, double f12, double f21, double f22) {
  return (Eigen::Matrix<double, 3, 2>() << f11, f12, f21, f22, 0.0, 0.0).finished();
}

// The states the orthotropic tests visit: both yarns stretched; both compressed past a
// buckling strain of 1 %; sheared by about 0.2 rad; a random mix. Vertex noise 0.3 mm against
// ~33 mm edges moves strains by ~1 %, so no yarn sits within a finite-difference step of a kink
// (ε = 0, ε = -ε_b) except by chance.
std::vector<std::pair<std::string, Vertices>> OrthotropicStates(const TriangleMesh& rest) {
  return {{"tension", Deformed(rest, Gradient3x2(1.04, 0.0, 0.0, 1.03), 3e-4, 1)},
          {"compression", Deformed(rest, Gradient3x2(0.95, 0.0, 0.0, 0.94), 3e-4, 2)},
          {"shear", Deformed(rest, Gradient3x2(1.0, 0.1, 0.1, 1.0), 3e-4, 3)},
          {"mixed", RandomConfiguration(rest, 0.006, 4)}};
}

TEST(OrthotropicMembrane, GradientAndHessianMatchCentralDifferences) {
  const TriangleMesh rest = IrregularPatch(11);
  const Material linear = Orthotropic(TensileCurve::Linear(1500.0), TensileCurve::Linear(600.0),
                                      80.0, 0.1, 0.01);
  // KES curves (EMT 5 % and 8 %; LT 0.65 and 0.45, the second with the power-law form), stiff in
  // compression: the curves' nonlinearity on its own.
  const Material kes = Orthotropic(TensileCurveFromKes(5.0, 0.65), TensileCurveFromKes(8.0, 0.45),
                                   45.0);
  for (const auto& [label, material] : {std::pair{"linear", linear}, std::pair{"kes", kes}}) {
    const MembraneElements m(rest, material, MembraneModel::kStVK);
    ASSERT_EQ(m.model(), MembraneModel::kOrthotropic);
    for (const auto& [state, x] : OrthotropicStates(rest)) {
      EXPECT_LT(RelativeGradientError(m, x), 1e-6) << label << ", " << state;
      EXPECT_LT(RelativeHessianError(m, x), 1e-6) << label << ", " << state;
    }
  }
}

TEST(OrthotropicMembrane, ProjectedHessianIsPsdAndExactWhereNothingIsCompressed) {
  const TriangleMesh rest = IrregularPatch(12);
  const MembraneElements m(
      rest, Orthotropic(TensileCurveFromKes(5.0, 0.65), TensileCurve::Linear(600.0), 80.0, 0.05, 0.005),
      MembraneModel::kStVK);
  int indefinite = 0;
  for (const auto& [state, x] : OrthotropicStates(rest)) {
    const Eigen::MatrixXd raw = DenseHessian(m, x, false), projected = DenseHessian(m, x, true);
    const double scale = raw.cwiseAbs().maxCoeff();
    // Eigen-solver round-off on a matrix of norm ~scale.
    EXPECT_GT(MinEigenvalue(projected), -1e-10 * scale) << state;
    if (MinEigenvalue(raw) < -1e-6 * scale) ++indefinite;
  }
  EXPECT_GE(indefinite, 2);  // compression and the mix: the projection was exercised
  // Stretched along both yarns without shear, and stretched with a little shear where the
  // tension's stiffness dominates: the projection leaves the exact Hessian alone.
  for (const Vertices& x : {Affine(rest, Gradient3x2(1.04, 0.0, 0.0, 1.03)),
                            Deformed(rest, Gradient3x2(1.04, 0.0, 0.0, 1.03), 3e-4, 5)}) {
    const Eigen::MatrixXd raw = DenseHessian(m, x, false);
    EXPECT_LT((DenseHessian(m, x, true) - raw).cwiseAbs().maxCoeff(),
              1e-12 * raw.cwiseAbs().maxCoeff());
  }
}

// The shear term's closed-form projection against the eigen-solve: yarns a billion times softer
// than the shear (stretched, so not projected themselves), F random. Clamping moves a matrix by
// at most the perturbation, so the yarns' terms bound the difference (~1e-9 of the shear's).
TEST(OrthotropicMembrane, ShearProjectionIsTheEigenSolvesClampedMatrix) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const OrthotropicMembrane law{TensileCurve::Linear(1e-6), TensileCurve::Linear(1e-6), 1000.0};
  Eigen::Matrix2d dm;
  dm << 0.01, 0.004, 0.0, 0.009;
  const Eigen::Matrix2d b = dm.inverse();
  Eigen::Matrix<double, 6, 9> g = Eigen::Matrix<double, 6, 9>::Zero();
  for (int j = 0; j < 2; ++j) {
    const double c[3] = {-(b(0, j) + b(1, j)), b(0, j), b(1, j)};
    for (int a = 0; a < 3; ++a) g.block<3, 3>(3 * j, 3 * a) = c[a] * Eigen::Matrix3d::Identity();
  }
  const Eigen::Matrix<double, 6, 6> left = (g * g.transpose()).inverse();
  for (int trial = 0; trial < 50; ++trial) {
    // Yarn stretches 1.02..1.3, shear angles up to ±0.6 rad (both signs of γ).
    const double l1 = 1.16 + 0.14 * unit(rng), l2 = 1.16 + 0.14 * unit(rng), t = 0.6 * unit(rng);
    const Eigen::Matrix3d r = RandomRotation(rng);
    const Eigen::Matrix<double, 3, 2> f =
        r.leftCols<2>() *
        (Eigen::Matrix2d() << l1, l2 * std::sin(t), 0.0, l2 * std::cos(t)).finished();
    Eigen::Matrix3d x;
    x.row(0).setZero();
    x.row(1) = (f * dm.col(0)).transpose();
    x.row(2) = (f * dm.col(1)).transpose();
    const Eigen::Matrix<double, 9, 9> raw = OrthotropicMembraneHessian(law, {}, b, 1.0, x, false);
    const Eigen::Matrix<double, 9, 9> projected =
        OrthotropicMembraneHessian(law, {}, b, 1.0, x, true);
    const Eigen::Matrix<double, 6, 6> h = left * g * raw * g.transpose() * left;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(0.5 * (h + h.transpose()));
    const Eigen::Matrix<double, 6, 6> clamped =
        eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
        eig.eigenvectors().transpose();
    const Eigen::Matrix<double, 9, 9> expected = g.transpose() * clamped * g;
    EXPECT_LT((projected - expected).cwiseAbs().maxCoeff(), 1e-8 * raw.cwiseAbs().maxCoeff())
        << "trial " << trial << ", shear angle " << t;
  }
}

// Sum of the gradient over the vertices with the given pattern coordinate at `value` [N].
Eigen::Vector3d EdgeForce(const TriangleMesh& rest, const Vertices& g, int axis, double value,
                          bool skip_corners = false) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v = 0; v < rest.num_vertices(); ++v) {
    if (std::abs(rest.vertices(v, axis) - value) > 1e-12) continue;
    const double other = rest.vertices(v, 1 - axis);
    const double other_max = rest.vertices.col(1 - axis).maxCoeff();
    if (skip_corners && (other < 1e-12 || other > other_max - 1e-12)) continue;
    sum += g.row(v).transpose();
  }
  return sum;
}

// Stretched along one yarn with the other's length held, which is where a free lateral edge
// settles (the yarns are uncoupled): the end carries the curve's force per width, no lateral
// force anywhere, and the energy is the curve's energy times the area.
TEST(OrthotropicMembrane, StripsReproduceTheWarpAndWeftCurves) {
  const double width = 0.2, height = 0.05;
  const TriangleMesh strip = CrissCrossGridMesh(width, height, 8, 2);
  const TensileCurve warp = TensileCurveFromKes(5.0, 0.65), weft = TensileCurveFromKes(8.0, 0.45);
  const MembraneElements m(strip, Orthotropic(warp, weft, 45.0), MembraneModel::kStVK);
  for (const double eps : {0.01, 0.03, 0.07}) {  // 0.07: past the warp's EMT
    // Along x (warp): the right end at x = width carries warp.Force(ε) · height along x.
    const Vertices along_x = Affine(strip, Gradient3x2(1 + eps, 0.0, 0.0, 1.0));
    const Vertices gx = Gradient(m, along_x);
    const Eigen::Vector3d end_x = EdgeForce(strip, gx, 0, width);
    const double tol = 1e-9 * warp.Force(eps) * height;  // round-off on sums of ~10 forces
    EXPECT_NEAR(end_x.x(), warp.Force(eps) * height, tol) << "warp, ε " << eps;
    EXPECT_LT(gx.col(1).cwiseAbs().maxCoeff(), tol) << "warp: no lateral force, ε " << eps;
    EXPECT_NEAR(m.Energy(along_x), warp.Energy(eps) * width * height,
                1e-12 * warp.Energy(eps) * width * height);
    // Along y (weft): the top at y = height carries weft.Force(ε) · width along y.
    const Vertices along_y = Affine(strip, Gradient3x2(1.0, 0.0, 0.0, 1 + eps));
    const Vertices gy = Gradient(m, along_y);
    const Eigen::Vector3d end_y = EdgeForce(strip, gy, 1, height);
    EXPECT_NEAR(end_y.y(), weft.Force(eps) * width, 1e-9 * weft.Force(eps) * width)
        << "weft, ε " << eps;
    EXPECT_LT(gy.col(0).cwiseAbs().maxCoeff(), 1e-9 * weft.Force(eps) * width);
    EXPECT_GT(warp.Force(eps), 0.0);
  }
}

// f1 = (cos θ, sin θ), f2 = (sin θ, cos θ): both yarns keep their length, γ = f1·f2 = sin 2θ.
// The energy is ½ G γ² per area and the right end (normal x) carries the shear traction G γ f2
// per width; its corners also take half an edge of the top and bottom tractions G γ f1, so they
// are left out of the sum (an interior end of height - dy).
TEST(OrthotropicMembrane, ShearedSheetGivesGGammaPerWidth) {
  const double width = 0.1, height = 0.1, shear = 60.0;
  const int ny = 4;
  const TriangleMesh sheet = CrissCrossGridMesh(width, height, 4, ny);
  const MembraneElements m(
      sheet, Orthotropic(TensileCurve::Linear(1000.0), TensileCurve::Linear(800.0), shear),
      MembraneModel::kStVK);
  for (const double theta : {0.01, 0.1}) {
    const double gamma = std::sin(2 * theta);
    const Eigen::Matrix<double, 3, 2> a =
        Gradient3x2(std::cos(theta), std::sin(theta), std::sin(theta), std::cos(theta));
    const Vertices x = Affine(sheet, a);
    EXPECT_NEAR(m.Energy(x), 0.5 * shear * gamma * gamma * width * height,
                1e-12 * 0.5 * shear * gamma * gamma * width * height);
    const Eigen::Vector3d end = EdgeForce(sheet, Gradient(m, x), 0, width, /*skip_corners=*/true);
    const Eigen::Vector3d expected = shear * gamma * (height - height / ny) * a.col(1);
    EXPECT_LT((end - expected).norm(), 1e-9 * expected.norm()) << "θ " << theta;
  }
}

TEST(OrthotropicMembrane, InvariantUnderRigidMotion) {
  const TriangleMesh rest = IrregularPatch(14);
  const MembraneElements m(rest,
                           Orthotropic(TensileCurveFromKes(5.0, 0.65),
                                       TensileCurve::Linear(600.0), 80.0, 0.1, 0.01),
                           MembraneModel::kStVK);
  std::mt19937 rng(15);
  for (const auto& [state, x] : OrthotropicStates(rest)) {
    const Eigen::Matrix3d r = RandomRotation(rng);
    Vertices y = x * r.transpose();
    y.rowwise() += Eigen::RowVector3d(1.0, -2.0, 0.5);
    EXPECT_NEAR(m.Energy(y), m.Energy(x), 1e-12 * m.Energy(x)) << state;
    const Vertices gx = Gradient(m, x), gy = Gradient(m, y);
    EXPECT_LT((gy - gx * r.transpose()).cwiseAbs().maxCoeff(), 1e-9 * gx.cwiseAbs().maxCoeff())
        << state;
  }
  EXPECT_LT(std::abs(m.Energy(RandomConfiguration(rest, 0.0, 16))), 1e-20);  // rigid: nothing
}

// Warp = weft = k, G = k/2 is the corotational linear sheet with ν = 0 to first order in the
// strain: ½ k (ε11² + ε22²) + ½ G (2 ε12)² = μ |ε|², μ = k/2. At strains ~1e-4 the models'
// nonlinear terms differ by ~1e-4 of the energy.
TEST(OrthotropicMembrane, EqualYarnsAndHalfShearAreTheLinearSheetAtSmallStrain) {
  const TriangleMesh rest = IrregularPatch(17);
  const double k = 1000.0;
  const MembraneElements ortho(
      rest, Orthotropic(TensileCurve::Linear(k), TensileCurve::Linear(k), k / 2),
      MembraneModel::kStVK);
  const MembraneElements linear(rest, k, 0.0, MembraneModel::kCorotationalLinear);
  for (unsigned seed = 0; seed < 3; ++seed) {
    const Vertices x = RandomConfiguration(rest, 3e-6, 40 + seed);  // 3 µm on ~33 mm edges
    EXPECT_NEAR(ortho.Energy(x), linear.Energy(x), 1e-3 * linear.Energy(x)) << seed;
    const Vertices go = Gradient(ortho, x), gl = Gradient(linear, x);
    EXPECT_LT((go - gl).cwiseAbs().maxCoeff(), 1e-3 * gl.cwiseAbs().maxCoeff()) << seed;
  }
}

TEST(OrthotropicMembrane, StifferWarpGivesAStifferResponseAlongX) {
  const TriangleMesh rest = IrregularPatch(18);
  const MembraneElements m(
      rest, Orthotropic(TensileCurve::Linear(2000.0), TensileCurve::Linear(500.0), 45.0),
      MembraneModel::kStVK);
  const double along_x = m.Energy(Affine(rest, Gradient3x2(1.01, 0.0, 0.0, 1.0)));
  const double along_y = m.Energy(Affine(rest, Gradient3x2(1.0, 0.0, 0.0, 1.01)));
  EXPECT_NEAR(along_x / along_y, 4.0, 1e-9);  // the moduli's ratio
  // A 45° stretch loads both yarns alike: between the two.
  const double c = 1 + 0.01 / std::sqrt(2.0), s = 0.01 / std::sqrt(2.0);
  const double diagonal = m.Energy(Affine(rest, Gradient3x2(c, s, s, c)));
  EXPECT_LT(diagonal, along_x);
  EXPECT_GT(diagonal, along_y);
}

// The rest frame's first axis is pattern x in the triangle's plane: a sheet tilted about x (its
// triangles' planes still hold x) stretched along x is loaded in the warp only, whichever edge
// comes first; a sheet standing in the y-z plane (x normal to every triangle) falls back to the
// first edge and still has a finite, rigid-motion-free energy.
TEST(OrthotropicMembrane, RestFrameFollowsPatternX) {
  TriangleMesh rest = IrregularPatch(19);
  const double tilt = 0.6;
  const Eigen::Matrix3d about_x = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
  TriangleMesh tilted = rest;
  tilted.vertices = rest.vertices * about_x.transpose();
  const TensileCurve warp = TensileCurve::Linear(2000.0), weft = TensileCurve::Linear(500.0);
  const MembraneElements m(tilted, Orthotropic(warp, weft, 45.0), MembraneModel::kStVK);
  Vertices x = tilted.vertices;
  x.col(0) *= 1.02;
  EXPECT_NEAR(m.Energy(x), warp.Energy(0.02) * 0.01, 1e-12 * warp.Energy(0.02) * 0.01);
  TriangleMesh standing = rest;
  standing.vertices.col(2) = rest.vertices.col(0);
  standing.vertices.col(0).setZero();
  const MembraneElements fallback(standing, Orthotropic(warp, weft, 45.0), MembraneModel::kStVK);
  EXPECT_LT(std::abs(fallback.Energy(standing.vertices)), 1e-20);
  const double stretched = fallback.Energy(standing.vertices * 1.01);
  EXPECT_TRUE(std::isfinite(stretched));
  EXPECT_GT(stretched, 0.0);
}

// The isotropic models do not care about the rest frame: their energies in the pattern-x frame
// match those in the first-edge frame (the frame before this one) to round-off, on a flat and a
// tilted rest mesh.
TEST(Membrane, IsotropicEnergiesDoNotDependOnTheRestFrame) {
  TriangleMesh rest = IrregularPatch(20);
  TriangleMesh tilted = rest;
  tilted.vertices =
      rest.vertices *
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix().transpose();
  for (const TriangleMesh* mesh : {&rest, &tilted}) {
    for (const MembraneModel model : kModels) {
      for (const double c : {1.0, 0.2}) {
        if (model != MembraneModel::kStVK && c != 1.0) continue;
        const MembraneElements m(*mesh, kStiffness, kPoisson, model, c);
        const MembraneLame lame = MembraneLame::FromStretch(kStiffness, kPoisson, c);
        const Vertices x = RandomConfiguration(*mesh, 0.006, 50);
        double first_edge = 0;
        for (int f = 0; f < mesh->num_triangles(); ++f) {
          Eigen::Matrix3d rest_corners, corners;
          for (int k = 0; k < 3; ++k) {
            rest_corners.row(k) = mesh->vertices.row(mesh->triangles(f, k));
            corners.row(k) = x.row(mesh->triangles(f, k));
          }
          const Eigen::Vector3d e1 = (rest_corners.row(1) - rest_corners.row(0)).transpose(),
                                e2 = (rest_corners.row(2) - rest_corners.row(0)).transpose();
          const Eigen::Vector3d t1 = e1.normalized(), t2 = e1.cross(e2).normalized().cross(t1);
          Eigen::Matrix2d dm;
          dm << e1.dot(t1), e2.dot(t1), 0.0, e2.dot(t2);
          first_edge += MembraneEnergy(model, lame, dm.inverse(), 0.5 * e1.cross(e2).norm(), corners);
        }
        EXPECT_NEAR(m.Energy(x), first_edge, 1e-12 * first_edge) << Name(model) << ", c " << c;
      }
    }
  }
}

TEST(OrthotropicMembrane, MaterialChoosesTheModelAndBadInputIsRefused) {
  const TriangleMesh rest = RegularGridMesh(0.1, 0.1, 2, 2);
  auto error = [&](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no InputError)";
  };
  Material isotropic;
  EXPECT_EQ(MembraneElements(rest, isotropic, MembraneModel::kCorotationalLinear).model(),
            MembraneModel::kCorotationalLinear);
  const Material ortho =
      Orthotropic(TensileCurve::Linear(1000.0), TensileCurve::Linear(800.0), 45.0, 0.1, 0.01);
  EXPECT_EQ(MembraneElements(rest, ortho, MembraneModel::kCorotationalLinear).model(),
            MembraneModel::kOrthotropic);
  isotropic.buckling_strain = 1.5;
  EXPECT_EQ(error([&] { MembraneElements(rest, isotropic, MembraneModel::kStVK); }),
            "membrane: buckling strain must lie in [0, 1), got 1.5");
  EXPECT_EQ(error([&] { MembraneElements(rest, 1000.0, 0.3, MembraneModel::kOrthotropic); }),
            "membrane: the orthotropic model needs a material's warp, weft and shear");
  Material bad = ortho;
  bad.orthotropic->shear_modulus = -1.0;
  EXPECT_EQ(error([&] { MembraneElements(rest, bad, MembraneModel::kStVK); }),
            "membrane: shear modulus must be a finite number ≥ 0 of N/m, got -1");
  bad = ortho;
  bad.compression_ratio = 0.0;
  EXPECT_EQ(error([&] { MembraneElements(rest, bad, MembraneModel::kStVK); }).substr(0, 50),
            "membrane: compression ratio must lie in [0.001, 1]");
  bad = ortho;
  bad.buckling_strain = -0.01;
  EXPECT_EQ(error([&] { MembraneElements(rest, bad, MembraneModel::kStVK); }),
            "membrane: buckling strain must be a finite number ≥ 0, got -0.01");
}

}  // namespace
}  // namespace textile
