#include "textile/sim/elements/tensor_bending.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <random>
#include <set>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

BendingLaw Fig8() { return BendingLaw::FromKes(0.1, 0.0892, -0.0092); }
BendingLaw Interlining() { return BendingLaw::FromKes(0.5168, 1.8856, 2.2683); }
BendingLaw Linear(double b) { return BendingLaw::FromSi(b, b, 0.0); }

// A 4 cm × 4 cm grid with its interior vertices jittered by up to `jitter` of a cell.
TriangleMesh Jittered(TriangleMesh m, int n, double jitter, std::mt19937* rng) {
  const double cell = 0.04 / n;
  std::uniform_real_distribution<double> u(-jitter * cell, jitter * cell);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.vertices(v, 0), y = m.vertices(v, 1);
    if (x > 1e-9 && x < 0.04 - 1e-9 && y > 1e-9 && y < 0.04 - 1e-9) {
      m.vertices(v, 0) += u(*rng);
      m.vertices(v, 1) += u(*rng);
    }
  }
  return m;
}

// The grid with its cells' diagonals alternating like a chequerboard (ncx cells along x).
TriangleMesh Alternated(TriangleMesh m, int ncx) {
  for (int f = 0; f < m.num_triangles(); f += 2) {
    const int cell = f / 2, i = cell % ncx, j = cell / ncx;
    if ((i + j) % 2 == 0) continue;
    std::set<int> corners;
    for (int q = 0; q < 3; ++q) {
      corners.insert(m.triangles(f, q));
      corners.insert(m.triangles(f + 1, q));
    }
    const std::vector<int> v(corners.begin(), corners.end());  // (i,j) (i+1,j) (i,j+1) (i+1,j+1)
    m.triangles.row(f) << v[0], v[1], v[2];
    m.triangles.row(f + 1) << v[1], v[3], v[2];
  }
  return m;
}

// The flat pattern lifted onto the height field z = ½ pᵀ K p (p from the sheet's centre).
Vertices Lifted(const TriangleMesh& m, const Eigen::Matrix2d& k) {
  Vertices x = m.vertices;
  for (int v = 0; v < x.rows(); ++v) {
    const Eigen::Vector2d p(x(v, 0) - 0.02, x(v, 1) - 0.02);
    x(v, 2) = 0.5 * p.dot(k * p);
  }
  return x;
}

TEST(TensorBending, ReproducesAConstantCurvatureTensorOnEveryMesh) {
  std::mt19937 rng(7);
  const std::vector<std::pair<std::string, TriangleMesh>> meshes = {
      {"regular", RegularGridMesh(0.04, 0.04, 16, 16)},
      {"regular 2:1", RegularGridMesh(0.04, 0.04, 16, 8)},
      {"criss-cross", CrissCrossGridMesh(0.04, 0.04, 12, 12)},
      {"jittered", Jittered(RegularGridMesh(0.04, 0.04, 16, 16), 16, 0.25, &rng)},
      {"alternating 4:1", Alternated(RegularGridMesh(0.04, 0.04, 32, 8), 32)}};
  Eigen::Matrix2d k;
  k << 0.8, -0.5, -0.5, 0.3;  // [1/m]: bend, curl and twist together
  for (const auto& [name, mesh] : meshes) {
    const std::vector<Hinge> hinges = BuildHinges(mesh);
    const TensorBending b(mesh, hinges, Fig8(), std::nullopt, {});
    EXPECT_EQ(b.num_fallback_patches(), 0) << name;
    const Vertices x = Lifted(mesh, k);
    double worst = 0.0;
    int checked = 0;
    for (int t = 0; t < mesh.num_triangles(); ++t) {
      // Interior patches away from the sheet's border: all three wings are real.
      const Eigen::Vector3d c = (mesh.vertices.row(mesh.triangles(t, 0)) +
                                 mesh.vertices.row(mesh.triangles(t, 1)) +
                                 mesh.vertices.row(mesh.triangles(t, 2))).transpose() / 3.0;
      if (b.patch(t).size() != 6 || std::abs(c.x() - 0.02) > 0.012 || std::abs(c.y() - 0.02) > 0.012)
        continue;
      worst = std::max(worst, (b.Curvature(x, t) - k).norm() / k.norm());
      ++checked;
    }
    EXPECT_GT(checked, 20) << name;
    // The fit is exact for a quadratic; what is left is θ ≈ sin θ and the wings' unfolding,
    // second order in the ~0.005 rad angles, and the height field's own slope (~1 %).
    EXPECT_LT(worst, 0.02) << name;
  }
}

TEST(TensorBending, BendAndTwistAreSeparate) {
  // On a 2:1 grid a pure bend along x costs A Ψ(κ) and nothing else; a pure twist costs
  // A 2Ψ(κ). The hinge energies mix the two (docs/methods/statics.md); this one does not.
  const TriangleMesh mesh = RegularGridMesh(0.04, 0.04, 32, 16);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  const BendingLaw law = Linear(1e-5);
  const TensorBending b(mesh, hinges, law, std::nullopt, {});
  const double kappa = 0.5, area = 0.04 * 0.04;
  Eigen::Matrix2d bend, twist;
  bend << kappa, 0.0, 0.0, 0.0;
  twist << 0.0, kappa, kappa, 0.0;
  // The triangles with a free edge across the bend (one per cell at each end, 1/32 of all)
  // carry no moment: their angle across that edge is condensed. Nothing else is lost.
  const double bent = b.Energy(Lifted(mesh, bend)), twisted = b.Energy(Lifted(mesh, twist));
  EXPECT_NEAR(bent, (1.0 - 1.0 / 32.0) * area * law.Energy(kappa), 0.003 * area * law.Energy(kappa));
  EXPECT_NEAR(twisted, 2.0 * area * law.Energy(kappa), 0.003 * 2.0 * area * law.Energy(kappa));
}

TEST(TensorBending, ZeroAtRestAndUnderRigidMotions) {
  std::mt19937 rng(3);
  TriangleMesh mesh = Jittered(RegularGridMesh(0.04, 0.04, 6, 6), 6, 0.2, &rng);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  const TensorBending b(mesh, hinges, Fig8(), Interlining(), {});
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  Vertices moved = mesh.vertices * r.transpose();
  moved.rowwise() += Eigen::RowVector3d(0.3, -1.0, 2.0);
  // A bent state, for the scale of energy and forces; it keeps its energy when moved rigidly.
  Eigen::Matrix2d k;
  k << 3.0, 1.0, 1.0, -2.0;
  const Vertices bent = Lifted(mesh, k);
  Vertices bent_gradient = Vertices::Zero(bent.rows(), 3);
  const double bent_energy = b.EnergyGradient(bent, bent_gradient);
  for (const Vertices* x : {&mesh.vertices, &moved}) {
    Vertices g = Vertices::Zero(x->rows(), 3);
    EXPECT_LT(b.EnergyGradient(*x, g), 1e-20 * bent_energy);
    EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-9 * bent_gradient.cwiseAbs().maxCoeff());
  }
  Vertices bent_moved = bent * r.transpose();
  bent_moved.rowwise() += Eigen::RowVector3d(0.3, -1.0, 2.0);
  const double e = b.Energy(bent);
  EXPECT_GT(e, 0.0);
  EXPECT_NEAR(b.Energy(bent_moved), e, 1e-12 * e);
}

TEST(TensorBending, ForcesSumToZeroWithZeroTorque) {
  std::mt19937 rng(11);
  TriangleMesh mesh = Jittered(CrissCrossGridMesh(0.04, 0.04, 4, 4), 4, 0.2, &rng);
  const TensorBending b(mesh, BuildHinges(mesh), Fig8(), Interlining(), {});
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  Vertices x = mesh.vertices;
  for (int v = 0; v < x.rows(); ++v)
    for (int c = 0; c < 3; ++c) x(v, c) += u(rng);
  Vertices g = Vertices::Zero(x.rows(), 3);
  b.EnergyGradient(x, g);
  const double scale = g.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(g.colwise().sum().norm(), 1e-12 * scale);
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  for (int v = 0; v < x.rows(); ++v)
    torque += x.row(v).transpose().cross(g.row(v).transpose());
  EXPECT_LT(torque.norm(), 1e-12 * scale);
}

Eigen::MatrixXd DenseHessian(const TensorBending& b, const Vertices& x, HessianProjection p) {
  std::vector<Eigen::Triplet<double>> t;
  b.AddHessianTriplets(x, &t, p);
  Eigen::SparseMatrix<double> h(3 * x.rows(), 3 * x.rows());
  h.setFromTriplets(t.begin(), t.end());
  return Eigen::MatrixXd(h);
}

// Gradient = finite difference of the energy, Hessian = finite difference of the gradient, on
// a jittered mesh with seam multipliers and random bends.
void ExpectDerivativesMatchFiniteDifferences(const BendingLaw& warp, const BendingLaw& weft) {
  std::mt19937 rng(5);
  TriangleMesh mesh = Jittered(RegularGridMesh(0.04, 0.04, 4, 4), 4, 0.2, &rng);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  std::vector<double> seam(hinges.size());
  std::uniform_real_distribution<double> s(1.0, 4.0), u(-0.005, 0.005);
  for (double& v : seam) v = s(rng);
  const TensorBending b(mesh, hinges, warp, weft, seam);
  for (int trial = 0; trial < 3; ++trial) {
    Vertices x = mesh.vertices;
    for (int v = 0; v < x.rows(); ++v)
      for (int c = 0; c < 3; ++c) x(v, c) += u(rng);
    Vertices g = Vertices::Zero(x.rows(), 3);
    b.EnergyGradient(x, g);
    const Eigen::MatrixXd h = DenseHessian(b, x, HessianProjection::kNone);
    const double step = 1e-7;
    const double gscale = g.cwiseAbs().maxCoeff(), hscale = h.cwiseAbs().maxCoeff();
    for (int dof = 0; dof < 3 * x.rows(); ++dof) {
      Vertices plus = x, minus = x;
      plus(dof / 3, dof % 3) += step;
      minus(dof / 3, dof % 3) -= step;
      const double fd = (b.Energy(plus) - b.Energy(minus)) / (2.0 * step);
      EXPECT_NEAR(g(dof / 3, dof % 3), fd, 1e-6 * gscale) << "dof " << dof;
      Vertices gp = Vertices::Zero(x.rows(), 3), gm = Vertices::Zero(x.rows(), 3);
      b.EnergyGradient(plus, gp);
      b.EnergyGradient(minus, gm);
      const Eigen::VectorXd column =
          (Eigen::Map<const Eigen::VectorXd>(gp.data(), gp.size()) -
           Eigen::Map<const Eigen::VectorXd>(gm.data(), gm.size())) / (2.0 * step);
      EXPECT_LT((h.col(dof) - column).cwiseAbs().maxCoeff(), 1e-5 * hscale) << "dof " << dof;
    }
    EXPECT_LT((h - h.transpose()).cwiseAbs().maxCoeff(), 1e-12 * hscale);
  }
}

TEST(TensorBending, GradientAndHessianMatchFiniteDifferences) {
  // A nonlinear law on both branches (κ0 of the interlining is small) and a different weft.
  ExpectDerivativesMatchFiniteDifferences(Interlining(), Fig8());
}

TEST(TensorBending, GradientAndHessianMatchFiniteDifferencesForSplineLaws) {
  // A knee (stiff to 3 /m, nearly flat past 20 /m) and the Fig. 8 law sampled at 0.5 /cm.
  std::vector<double> kappa, moment;
  for (int i = 0; i <= 8; ++i) {
    kappa.push_back(50.0 * i);
    moment.push_back(Fig8().Moment(50.0 * i));
  }
  ExpectDerivativesMatchFiniteDifferences(
      BendingLaw::FromSpline({0.0, 3.0, 20.0, 100.0, 200.0}, {0.0, 2.3e-4, 2.5e-4, 3.0e-4, 3.9e-4}),
      BendingLaw::FromSpline(kappa, moment));
}

TEST(TensorBending, ProjectedHessiansArePositiveSemiDefinite) {
  std::mt19937 rng(9);
  TriangleMesh mesh = Jittered(RegularGridMesh(0.04, 0.04, 4, 4), 4, 0.2, &rng);
  const TensorBending b(mesh, BuildHinges(mesh), Fig8(), std::nullopt, {});
  std::uniform_real_distribution<double> u(-0.008, 0.008);
  Vertices x = mesh.vertices;
  for (int v = 0; v < x.rows(); ++v)
    for (int c = 0; c < 3; ++c) x(v, c) += u(rng);
  for (HessianProjection p : {HessianProjection::kGaussNewton, HessianProjection::kEigen}) {
    const Eigen::MatrixXd h = DenseHessian(b, x, p);
    const double low = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(h).eigenvalues().minCoeff();
    EXPECT_GT(low, -1e-10 * h.cwiseAbs().maxCoeff());
  }
  // The exact Hessian of a bent state is not (so the projection did something).
  const Eigen::MatrixXd exact = DenseHessian(b, x, HessianProjection::kNone);
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(exact).eigenvalues().minCoeff(), 0.0);
  // The triplet count is the same for every projection (fixed sparsity pattern).
  std::vector<Eigen::Triplet<double>> a, c;
  b.AddHessianTriplets(x, &a, HessianProjection::kGaussNewton);
  b.AddHessianTriplets(mesh.vertices, &c, HessianProjection::kNone);
  EXPECT_EQ(a.size(), c.size());
}

TEST(TensorBending, RefusesBadInput) {
  const TriangleMesh mesh = RegularGridMesh(0.04, 0.04, 2, 2);
  const std::vector<Hinge> hinges = BuildHinges(mesh);
  EXPECT_THROW(TensorBending(mesh, hinges, Fig8(), std::nullopt, {1.0}), InputError);
  std::vector<double> bad(hinges.size(), 1.0);
  bad[2] = std::nan("");
  EXPECT_THROW(TensorBending(mesh, hinges, Fig8(), std::nullopt, bad), InputError);
  bad[2] = 0.0;
  EXPECT_THROW(TensorBending(mesh, hinges, Fig8(), std::nullopt, bad), InputError);
}

}  // namespace
}  // namespace textile
