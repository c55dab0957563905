#ifndef TEXTILE_SIM_SRC_HINGE_ANGLE_H_
#define TEXTILE_SIM_SRC_HINGE_ANGLE_H_

// The bend angle θ of a hinge with its gradient and Hessian, the one scalar implementation for
// the elements that are functions of hinge angles (bending_element.cc, tensor_bending.cc); the
// SIMD kernels of bending_element.cc write the same formulas out lane by lane. Hinge numbering
// as in mesh.h: wings x0, x1, edge x2 → x3; θ is the signed angle of bending_element.h
// (HingeBendAngle). The derivation is docs/methods/bending.md, "Gradient of the bend angle" and
// "Hessian of the bend angle".

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "textile/sim/mesh/mesh.h"

namespace textile::hinge_angle {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat12 = Eigen::Matrix<double, 12, 12>;

inline Eigen::Map<const Vec3> Position(const Vertices& x, int i) {
  return Eigen::Map<const Vec3>(x.data() + 3 * i);
}

// The bend angle as atan2(sin_term, cos_term): |n0||n1| sin θ and |n0||n1| cos θ, n0 = e × a0
// and n1 = a1 × e the unnormalised normals of (x0, x2, x3) and (x1, x3, x2), e = x3 - x2,
// a_k = x_k - x2. The dihedral elements (bending_element.cc) take them as they are: their laws
// need cos θ and sin θ, or θ from their own vectorisable atan2.
struct AngleTerms {
  double sin_term, cos_term;
};

// The terms of θ and, when grad is given, ∂θ/∂x_k (k = 0..3) of the hinge with vertex ids v at
// positions x. The wings' gradients are |e| n_k/|n_k|²; the edge vertices take the reactions
// at the wings' feet along the edge.
inline AngleTerms AngleTermsAndGradient(const Vertices& x, const std::array<int, 4>& v,
                                        std::array<Vec3, 4>* grad) {
  const Vec3 x2 = Position(x, v[2]);
  const Vec3 e = Position(x, v[3]) - x2;
  const Vec3 a0 = Position(x, v[0]) - x2, a1 = Position(x, v[1]) - x2;
  const Vec3 n0 = e.cross(a0), n1 = a1.cross(e);
  const double l2 = e.squaredNorm(), l = std::sqrt(l2);
  if (grad) {
    // As the SIMD kernels of bending_element.cc compute it, so that both give the same bits.
    const double n0sq = n0.squaredNorm(), n1sq = n1.squaredNorm();
    const double inv = 1.0 / (n0sq * n1sq), inv_l2 = 1.0 / l2;
    const Vec3 g0 = n0 * (l * n1sq * inv), g1 = n1 * (l * n0sq * inv);
    const double t0 = a0.dot(e) * inv_l2, t1 = a1.dot(e) * inv_l2;  // the wings' feet on the edge
    (*grad)[0] = g0;
    (*grad)[1] = g1;
    (*grad)[2] = (t0 - 1.0) * g0 + (t1 - 1.0) * g1;
    (*grad)[3] = -t0 * g0 - t1 * g1;
  }
  return {l * n1.dot(a0), n0.dot(n1)};  // (n1 × n0)·e/|e| = |e| (a1 × e)·a0
}

// θ and ∂θ/∂x_k (k = 0..3), as AngleTermsAndGradient.
inline double AngleAndGradient(const Vertices& x, const std::array<int, 4>& v,
                               std::array<Vec3, 4>* grad) {
  const AngleTerms t = AngleTermsAndGradient(x, v, grad);
  return std::atan2(t.sin_term, t.cos_term);
}

// One triangle (wing w, edge x2 → x3, unnormalised normal n) of ∇²θ, times scale, into the
// 12×12 block h; `wing` is the block index of w (0 or 1), `cyclic` the triangle's edge vectors
// opposite (w, x2, x3) in its counter-clockwise order, so that ∂n/∂x_p = [cyclic_p]×.
inline void AddTriangleAngleHessian(const Vec3& w, const Vec3& x2, const Vec3& x3, const Vec3& n,
                                    const std::array<Vec3, 3>& cyclic, int wing, double scale,
                                    Mat12* h) {
  const Vec3 e = x3 - x2, from2 = w - x2, to3 = x3 - w;
  const double l2 = e.squaredNorm(), l = std::sqrt(l2), nsq = n.squaredNorm();
  const double inv = 1.0 / (l * nsq);
  // ∂θ/∂x_p (this triangle's share) = c_p n with c_p = f_p/(|e| |n|²).
  const double c[3] = {l2 * inv, -to3.dot(e) * inv, -from2.dot(e) * inv};
  const Vec3 zero = Vec3::Zero();
  const Vec3 df[3][3] = {{zero, -2.0 * e, 2.0 * e}, {e, to3, -e - to3}, {-e, e + from2, -from2}};
  const Vec3 dlog_l[3] = {zero, -e / l2, e / l2};
  const int block[3] = {wing, 2, 3};
  for (int q = 0; q < 3; ++q) {
    const Vec3 dlog_n2 = n.cross(cyclic[q]) * (2.0 / nsq);  // ∂ log|n|² / ∂x_q
    Mat3 skew;
    skew << 0.0, -cyclic[q].z(), cyclic[q].y(), cyclic[q].z(), 0.0, -cyclic[q].x(),
        -cyclic[q].y(), cyclic[q].x(), 0.0;
    for (int p = 0; p < 3; ++p) {
      const Vec3 dc = df[p][q] * inv - c[p] * (dlog_l[q] + dlog_n2);
      h->block<3, 3>(3 * block[p], 3 * block[q]) += scale * (n * dc.transpose() + c[p] * skew);
    }
  }
}

// scale · ∇²θ of the hinge, added to the 12×12 block h (rows/columns 3k..3k+2: vertex v[k]).
inline void AddAngleHessian(const Vertices& x, const std::array<int, 4>& v, double scale,
                            Mat12* h) {
  const Vec3 x0 = Position(x, v[0]), x1 = Position(x, v[1]);
  const Vec3 x2 = Position(x, v[2]), x3 = Position(x, v[3]);
  const Vec3 e = x3 - x2;
  AddTriangleAngleHessian(x0, x2, x3, e.cross(x0 - x2), {e, x0 - x3, x2 - x0}, 0, scale, h);
  AddTriangleAngleHessian(x1, x2, x3, (x1 - x2).cross(e), {-e, x3 - x1, x1 - x2}, 1, scale, h);
}

}  // namespace textile::hinge_angle

#endif  // TEXTILE_SIM_SRC_HINGE_ANGLE_H_
