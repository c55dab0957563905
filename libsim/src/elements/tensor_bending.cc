#include "textile/sim/elements/tensor_bending.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "hinge_angle.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using hinge_angle::Mat12;

// Below this ratio of the smallest to the largest singular value of the (scaled) quadratic fit,
// a rest patch counts as degenerate (six points nearly on one conic).
constexpr double kConicTolerance = 1e-6;

std::string TriangleName(int t, const TriangleMesh& mesh) {
  std::ostringstream s;
  s << "tensor bending: triangle " << t << " (vertices " << mesh.triangles(t, 0) << ", "
    << mesh.triangles(t, 1) << ", " << mesh.triangles(t, 2) << ")";
  return s.str();
}

// The quadratic-fit row of a point (X, Y) (coordinates over the patch length): the height
// ½ K_xx X² + ½ K_yy Y² + K_xy X Y + g_x X + g_y Y + z_0.
Eigen::Matrix<double, 1, 6> FitRow(const Vec2& p) {
  Eigen::Matrix<double, 1, 6> row;
  row << 0.5 * p.x() * p.x(), 0.5 * p.y() * p.y(), p.x() * p.y(), p.x(), p.y(), 1.0;
  return row;
}

}  // namespace

TensorBending::TensorBending(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                             const BendingLaw& warp, const std::optional<BendingLaw>& weft,
                             const std::vector<double>& hinge_multiplier)
    : warp_(warp), weft_(weft ? *weft : warp), hinges_(hinges) {
  const int nt = rest.num_triangles();
  const int nh = static_cast<int>(hinges.size());
  if (!hinge_multiplier.empty() && static_cast<int>(hinge_multiplier.size()) != nh) {
    throw InputError("tensor bending: " + std::to_string(hinge_multiplier.size()) +
                     " seam multipliers for " + std::to_string(nh) + " hinges");
  }
  const Vertices& xr = rest.vertices;
  rest_angle_.resize(nh);
  // Per triangle and local edge i (opposite corner i): the hinge and the wing across it.
  std::vector<std::array<int, 3>> edge_hinge(nt, {-1, -1, -1}), edge_wing(nt, {-1, -1, -1});
  for (int h = 0; h < nh; ++h) {
    const Hinge& hg = hinges[h];
    for (int i = 0; i < 4; ++i) {
      if (hg.v[i] < 0 || hg.v[i] >= rest.num_vertices()) {
        throw InputError("tensor bending: hinge " + std::to_string(h) + " has vertex id " +
                         std::to_string(hg.v[i]) + " outside the mesh");
      }
    }
    if (!hinge_multiplier.empty() &&
        !(std::isfinite(hinge_multiplier[h]) && hinge_multiplier[h] > 0.0)) {
      throw InputError("tensor bending: hinge " + std::to_string(h) +
                       ": seam multiplier must be a finite number > 0");
    }
    rest_angle_[h] = hinge_angle::AngleAndGradient(xr, hg.v, nullptr);
    for (int side = 0; side < 2; ++side) {
      const int t = hg.faces[side];
      const int own = hg.v[side], across = hg.v[1 - side];
      for (int i = 0; i < 3; ++i) {
        if (rest.triangles(t, i) == own) {
          edge_hinge[t][i] = h;
          edge_wing[t][i] = across;
        }
      }
    }
  }

  tri_.resize(nt);
  patch_.resize(nt);
  for (int t = 0; t < nt; ++t) {
    std::array<Vec3, 3> p;
    for (int i = 0; i < 3; ++i) p[i] = xr.row(rest.triangles(t, i)).transpose();
    Vec3 normal = (p[1] - p[0]).cross(p[2] - p[0]);
    const double area = 0.5 * normal.norm();
    if (!(area > 0.0) || !std::isfinite(area)) {
      throw InputError(TriangleName(t, rest) + ": degenerate rest triangle");
    }
    normal.normalize();
    // Frame: e1 the warp (x axis) projected onto the triangle, e2 = normal × e1.
    Vec3 e1 = Vec3::UnitX() - normal.x() * normal;
    if (e1.norm() < 0.1) e1 = p[1] - p[0];
    e1.normalize();
    const Vec3 e2 = normal.cross(e1);
    const Vec3 centre = (p[0] + p[1] + p[2]) / 3.0;
    const double scale = std::sqrt(area);
    auto local = [&](const Vec3& q) {
      return Vec2((q - centre).dot(e1) / scale, (q - centre).dot(e2) / scale);
    };

    // Six conditions on the quadratic height field: zero at the three corners; per edge, the
    // height d_i θ_i at the wing across it unfolded into the triangle's plane, or, on a free
    // edge, no curvature across the edge (m_iᵀ K m_i = 0, m_i its in-plane normal: the
    // moment-free edge of a plate with no Poisson coupling).
    std::array<double, 3> dist{};
    std::array<Vec2, 3> normal2;
    Eigen::Matrix<double, 6, 6> fit;
    for (int i = 0; i < 3; ++i) {
      const Vec3& a = p[(i + 1) % 3];
      const Vec3 e = (p[(i + 2) % 3] - a).normalized();
      Vec3 out = e.cross(normal);  // in-plane normal of the edge, away from corner i
      if (out.dot(p[i] - a) > 0.0) out = -out;
      normal2[i] = Vec2(out.dot(e1), out.dot(e2));
      fit.row(i) = FitRow(local(p[i]));
      if (edge_wing[t][i] >= 0) {
        const Vec3 w = xr.row(edge_wing[t][i]).transpose();
        const Vec3 foot = a + (w - a).dot(e) * e;
        dist[i] = (w - foot).norm();
        if (!(dist[i] > 1e-8 * scale)) {
          throw InputError(TriangleName(t, rest) + ": the wing across edge " +
                           std::to_string(i) + " lies on the edge line");
        }
        fit.row(3 + i) = FitRow(local(foot + dist[i] * out));
      } else {
        const Vec2& m = normal2[i];
        fit.row(3 + i) << m.x() * m.x(), m.y() * m.y(), 2.0 * m.x() * m.y(), 0.0, 0.0, 0.0;
      }
    }

    // N_i: the curvature per unit θ_i, from the fit or, for a degenerate patch, from the
    // mid-edge formula K = Σ θ_i l_i/(2A) m_i m_iᵀ.
    Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>> svd(fit);
    const auto& sv = svd.singularValues();
    std::array<Vec3, 3> n;
    if (sv(5) > kConicTolerance * sv(0)) {
      const Eigen::Matrix<double, 6, 6> inverse = fit.inverse();
      for (int i = 0; i < 3; ++i)
        n[i] = inverse.block<3, 1>(0, 3 + i) * (dist[i] / (scale * scale));
    } else {
      ++num_fallback_;
      for (int i = 0; i < 3; ++i) {
        const Vec2& m = normal2[i];
        const double l = (p[(i + 2) % 3] - p[(i + 1) % 3]).norm();
        n[i] = Vec3(m.x() * m.x(), m.y() * m.y(), m.x() * m.y()) * (l / (2.0 * area));
      }
    }

    TriangleRest& r = tri_[t];
    double s_sum = 0.0;
    int s_count = 0;
    for (int i = 0; i < 3; ++i) {
      r.hinge[i] = edge_hinge[t][i];
      r.n[i] = r.hinge[i] >= 0 ? n[i] : Vec3::Zero();
      if (r.hinge[i] >= 0) {
        s_sum += hinge_multiplier.empty() ? 1.0 : hinge_multiplier[r.hinge[i]];
        ++s_count;
      }
    }
    r.weight = area * (s_count > 0 ? s_sum / s_count : 1.0);
    if (!r.n[0].allFinite() || !r.n[1].allFinite() || !r.n[2].allFinite()) {
      throw InputError(TriangleName(t, rest) + ": degenerate rest patch");
    }

    std::vector<int>& patch = patch_[t];
    for (int i = 0; i < 3; ++i) patch.push_back(rest.triangles(t, i));
    for (int i = 0; i < 3; ++i)
      if (edge_wing[t][i] >= 0) patch.push_back(edge_wing[t][i]);
  }
}

void TensorBending::Angles(const Vertices& x, std::vector<double>* dtheta) const {
  dtheta->resize(hinges_.size());
  for (size_t h = 0; h < hinges_.size(); ++h)
    (*dtheta)[h] = hinge_angle::AngleAndGradient(x, hinges_[h].v, nullptr) - rest_angle_[h];
}

Eigen::Vector3d TensorBending::TensorOf(int t, const std::vector<double>& dtheta) const {
  const TriangleRest& r = tri_[t];
  Vec3 k = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (r.hinge[i] >= 0) k += dtheta[r.hinge[i]] * r.n[i];
  return k;
}

double TensorBending::Density(const Eigen::Vector3d& k, Eigen::Vector3d* moment,
                              Eigen::Vector3d* stiffness) const {
  if (moment) {
    *moment = Vec3(warp_.Moment(k.x()), weft_.Moment(k.y()),
                   warp_.Moment(k.z()) + weft_.Moment(k.z()));
  }
  if (stiffness) {
    *stiffness = Vec3(warp_.Stiffness(k.x()), weft_.Stiffness(k.y()),
                      warp_.Stiffness(k.z()) + weft_.Stiffness(k.z()));
  }
  return warp_.Energy(k.x()) + weft_.Energy(k.y()) + warp_.Energy(k.z()) + weft_.Energy(k.z());
}

double TensorBending::Energy(const Vertices& x) const {
  std::vector<double> dtheta;
  Angles(x, &dtheta);
  double energy = 0.0;
  for (int t = 0; t < num_triangles(); ++t)
    energy += tri_[t].weight * Density(TensorOf(t, dtheta), nullptr, nullptr);
  return energy;
}

double TensorBending::EnergyGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const {
  std::vector<double> dtheta, mu;
  Angles(x, &dtheta);
  double energy = 0.0;
  mu.assign(hinges_.size(), 0.0);
  for (int t = 0; t < num_triangles(); ++t) {
    const TriangleRest& r = tri_[t];
    Vec3 moment;
    energy += r.weight * Density(TensorOf(t, dtheta), &moment, nullptr);
    for (int i = 0; i < 3; ++i)
      if (r.hinge[i] >= 0) mu[r.hinge[i]] += r.weight * moment.dot(r.n[i]);
  }
  std::array<Vec3, 4> g;
  for (size_t h = 0; h < hinges_.size(); ++h) {
    if (mu[h] == 0.0) continue;
    hinge_angle::AngleAndGradient(x, hinges_[h].v, &g);
    for (int k = 0; k < 4; ++k) grad.row(hinges_[h].v[k]) += mu[h] * g[k].transpose();
  }
  return energy;
}

Eigen::Matrix2d TensorBending::Curvature(const Vertices& x, int t) const {
  const TriangleRest& r = tri_[t];
  Vec3 k = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    const int h = r.hinge[i];
    if (h >= 0) k += (hinge_angle::AngleAndGradient(x, hinges_[h].v, nullptr) - rest_angle_[h]) * r.n[i];
  }
  Eigen::Matrix2d m;
  m << k.x(), k.z(), k.z(), k.y();
  return m;
}

void TensorBending::AddHessianTriplets(const Vertices& x,
                                       std::vector<Eigen::Triplet<double>>* triplets,
                                       HessianProjection projection, int first_element,
                                       int end_element) const {
  const int nt = num_triangles();
  // The curvature tensor and ∂Φ/∂k, ∂²Φ/∂k² of triangle t, computed locally.
  auto triangle_terms = [&](int t, Vec3* moment, Vec3* stiffness) {
    const TriangleRest& r = tri_[t];
    Vec3 k = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const int h = r.hinge[i];
      if (h >= 0)
        k += (hinge_angle::AngleAndGradient(x, hinges_[h].v, nullptr) - rest_angle_[h]) * r.n[i];
    }
    Density(k, moment, stiffness);
  };
  for (int element = first_element; element < end_element; ++element) {
    if (element < nt) {
      // Σ_ij S A (n_iᵀ Φ'' n_j) ∇θ_i ∇θ_jᵀ over the patch's vertices.
      const TriangleRest& r = tri_[element];
      const std::vector<int>& patch = patch_[element];
      const int np = static_cast<int>(patch.size());
      Eigen::Matrix<double, 18, 3> grads = Eigen::Matrix<double, 18, 3>::Zero();
      Vec3 stiffness;
      triangle_terms(element, nullptr, &stiffness);
      for (int i = 0; i < 3; ++i) {
        const int h = r.hinge[i];
        if (h < 0) continue;
        std::array<Vec3, 4> g;
        hinge_angle::AngleAndGradient(x, hinges_[h].v, &g);
        for (int k = 0; k < 4; ++k) {
          const int slot = static_cast<int>(std::find(patch.begin(), patch.end(), hinges_[h].v[k]) -
                                            patch.begin());
          grads.block<3, 1>(3 * slot, i) += g[k];
        }
      }
      Eigen::Matrix3d coupling;  // S A n_iᵀ Φ'' n_j
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          coupling(i, j) = r.weight * r.n[i].dot(stiffness.cwiseProduct(r.n[j]));
      const Eigen::Matrix<double, 18, 18> block = grads * coupling * grads.transpose();
      for (int a = 0; a < np; ++a)
        for (int b = 0; b < np; ++b)
          for (int c = 0; c < 3; ++c)
            for (int d = 0; d < 3; ++d)
              triplets->emplace_back(3 * patch[a] + c, 3 * patch[b] + d, block(3 * a + c, 3 * b + d));
      continue;
    }
    // (∂E/∂θ_h) ∇²θ_h.
    const int h = element - nt;
    const Hinge& hg = hinges_[h];
    Mat12 block = Mat12::Zero();
    if (projection != HessianProjection::kGaussNewton) {
      double mu = 0.0;
      for (int side = 0; side < 2; ++side) {
        const int t = hg.faces[side];
        Vec3 moment;
        triangle_terms(t, &moment, nullptr);
        for (int i = 0; i < 3; ++i)
          if (tri_[t].hinge[i] == h) mu += tri_[t].weight * moment.dot(tri_[t].n[i]);
      }
      hinge_angle::AddAngleHessian(x, hg.v, mu, &block);
      if (projection == HessianProjection::kEigen) {
        Eigen::SelfAdjointEigenSolver<Mat12> eigen(block);
        if (eigen.eigenvalues().minCoeff() < 0.0) {
          block = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
                  eigen.eigenvectors().transpose();
        }
      }
    }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int c = 0; c < 3; ++c)
          for (int d = 0; d < 3; ++d)
            triplets->emplace_back(3 * hg.v[a] + c, 3 * hg.v[b] + d, block(3 * a + c, 3 * b + d));
  }
}

}  // namespace textile
