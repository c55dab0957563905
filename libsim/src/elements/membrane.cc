#include "textile/sim/elements/membrane.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cassert>
#include <cmath>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat32 = Eigen::Matrix<double, 3, 2>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Deformation gradient F = Ds Dm⁻¹ (3×2), Ds = (x1 - x0, x2 - x0).
Mat32 DeformationGradient(const Eigen::Matrix2d& rest_inverse, const Eigen::Matrix3d& x) {
  Mat32 ds;
  ds.col(0) = (x.row(1) - x.row(0)).transpose();
  ds.col(1) = (x.row(2) - x.row(0)).transpose();
  return ds * rest_inverse;
}

// dvec(F)/d(x0, x1, x2): 6×9, vec(F) = (f1; f2) the columns of F. f_j = Σ_a c_aj x_a with
// c_1j = B_0j, c_2j = B_1j, c_0j = -(B_0j + B_1j), B = Dm⁻¹.
Eigen::Matrix<double, 6, 9> GradientMap(const Eigen::Matrix2d& b) {
  Eigen::Matrix<double, 6, 9> g = Eigen::Matrix<double, 6, 9>::Zero();
  for (int j = 0; j < 2; ++j) {
    const double c[3] = {-(b(0, j) + b(1, j)), b(0, j), b(1, j)};
    for (int a = 0; a < 3; ++a) g.block<3, 3>(3 * j, 3 * a) = c[a] * Eigen::Matrix3d::Identity();
  }
  return g;
}

Vec6 Vec(const Mat32& f) {
  Vec6 v;
  v << f.col(0), f.col(1);
  return v;
}

// ---- St. Venant-Kirchhoff: ψ = μ tr(E²) + λ/2 tr(E)², E = ½(FᵀF - I).

double StvkDensity(const MembraneLame& l, const Mat32& f) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  return l.mu * e.squaredNorm() + 0.5 * l.lambda * e.trace() * e.trace();
}

// P = F S with the second Piola-Kirchhoff stress S = 2μE + λ tr(E) I.
Vec6 StvkStress(const MembraneLame& l, const Mat32& f) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  const Eigen::Matrix2d s = 2 * l.mu * e + l.lambda * e.trace() * Eigen::Matrix2d::Identity();
  return Vec(f * s);
}

// ∂P_j/∂f_l = S_lj I + μ f_l f_jᵀ + μ δ_jl F Fᵀ + λ f_j f_lᵀ (3×3 blocks).
Mat6 StvkStressDerivative(const MembraneLame& l, const Mat32& f) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  const Eigen::Matrix2d s = 2 * l.mu * e + l.lambda * e.trace() * Eigen::Matrix2d::Identity();
  const Eigen::Matrix3d fft = f * f.transpose();
  Mat6 h;
  for (int j = 0; j < 2; ++j) {
    for (int k = 0; k < 2; ++k) {
      h.block<3, 3>(3 * j, 3 * k) = s(k, j) * Eigen::Matrix3d::Identity() +
                                    l.mu * f.col(k) * f.col(j).transpose() +
                                    l.lambda * f.col(j) * f.col(k).transpose();
      if (j == k) h.block<3, 3>(3 * j, 3 * k) += l.mu * fft;
    }
  }
  return h;
}

// ---- StVK soft in compression (MembraneLame::compression = c < 1): ψ = μ (q(E1) + q(E2)) +
// λ/2 q(E1 + E2) over the principal Green strains, q(t) = t² for t ≥ -b and, past it,
// b² - 2 b (t + b) + c (t + b)² (C¹), b = MembraneLame::buckling the Green strain of the
// buckling strain; b = 0: q = w(t) t², w = 1 for t ≥ 0 and c for t < 0.

// q(t) and its derivatives, with q'(t) = 2 w t + κ: w = 1, κ = 0 down to -b; w = c and
// κ = -2 b (1 - c) past it.
struct SoftPiece {
  double q, weight, kappa;
  double dq(double t) const { return 2 * weight * t + kappa; }
};

SoftPiece Piece(const MembraneLame& l, double t) {
  const double b = l.buckling;
  if (t >= -b) return {t * t, 1.0, 0.0};
  const double past = t + b;
  return {b * b - 2 * b * past + l.compression * past * past, l.compression,
          -2 * b * (1 - l.compression)};
}

// The principal strains Ei (E1 ≥ E2), their unit eigenvectors vi in the rest frame and the
// principal second Piola-Kirchhoff stresses Si = ∂ψ/∂Ei = 2μ wi Ei + λ wt tr E.
struct SoftStrains {
  double strain[2];
  Eigen::Vector2d v[2];
  double stress[2];
  SoftPiece piece[2], piece_trace;
};

SoftStrains Soft(const MembraneLame& l, const Mat32& f) {
  SoftStrains t;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> green;
  green.computeDirect(0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity()));
  for (int i = 0; i < 2; ++i) {
    t.strain[i] = green.eigenvalues()(1 - i);
    t.v[i] = green.eigenvectors().col(1 - i);
    t.piece[i] = Piece(l, t.strain[i]);
  }
  const double tr = t.strain[0] + t.strain[1];
  t.piece_trace = Piece(l, tr);
  for (int i = 0; i < 2; ++i)
    t.stress[i] = l.mu * t.piece[i].dq(t.strain[i]) + 0.5 * l.lambda * t.piece_trace.dq(tr);
  return t;
}

double SoftDensity(const MembraneLame& l, const Mat32& f) {
  const SoftStrains t = Soft(l, f);
  return l.mu * (t.piece[0].q + t.piece[1].q) + 0.5 * l.lambda * t.piece_trace.q;
}

// P = F S, S = Σ Si vi viᵀ.
Vec6 SoftStress(const MembraneLame& l, const Mat32& f) {
  const SoftStrains t = Soft(l, f);
  const Eigen::Matrix2d s =
      t.stress[0] * t.v[0] * t.v[0].transpose() + t.stress[1] * t.v[1] * t.v[1].transpose();
  return Vec(f * s);
}

// ---- Corotational linear: ψ = μ |U - I|² + λ/2 tr(U - I)², U the stretch of F = R U.
// With the singular values σ1, σ2 of F: |U - I|² = I1 - 2 s + 2 and tr(U) = s, where
// I1 = |F|² = σ1² + σ2², J = |f1 × f2| = σ1 σ2 and s = σ1 + σ2 = sqrt(I1 + 2 J): the energy is a
// smooth function of F wherever the triangle has area (J > 0), no SVD needed.

struct CorotationalTerms {
  double s = 0;       // σ1 + σ2
  double j = 0;       // σ1 σ2
  Eigen::Vector3d n;  // unit normal of the deformed triangle
  Vec6 grad_j;        // ∂J/∂vec(F)
  Vec6 grad_s;        // ∂s/∂vec(F)
};

CorotationalTerms Corotational(const Mat32& f) {
  CorotationalTerms t;
  const Eigen::Vector3d f1 = f.col(0), f2 = f.col(1);
  const Eigen::Vector3d cross = f1.cross(f2);
  t.j = cross.norm();
  const double i1 = f.squaredNorm();
  // A collapsed triangle has no normal; any unit vector normal to its edges keeps J's gradient
  // finite (J is not differentiable there).
  if (t.j > 1e-14 * i1) {
    t.n = cross / t.j;
  } else {
    const Eigen::Vector3d e = f1.squaredNorm() >= f2.squaredNorm() ? f1 : f2;
    t.n = e.squaredNorm() > 0 ? e.unitOrthogonal() : Eigen::Vector3d::UnitZ();
  }
  t.grad_j << f2.cross(t.n), t.n.cross(f1);
  t.s = std::sqrt(i1 + 2 * t.j);
  t.grad_s = (Vec(f) + t.grad_j) / std::max(t.s, 1e-300);
  return t;
}

// The same energy evaluated without cancellation: the principal strains σi - 1 come from the
// eigenvalues ei of the Green strain as σi - 1 = 2 ei / (1 + sqrt(1 + 2 ei)), so a nearly
// unstrained triangle stores ~k ε² A, not round-off of size k · 1e-16 · A.
double CorotationalDensity(const MembraneLame& l, const Mat32& f) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  const double mean = 0.5 * (e(0, 0) + e(1, 1));
  const double radius = std::hypot(0.5 * (e(0, 0) - e(1, 1)), e(0, 1));
  double strain_sq = 0, strain_sum = 0;
  for (const double ei : {mean + radius, mean - radius}) {
    const double c = std::max(1 + 2 * ei, 0.0);  // an eigenvalue of FᵀF, ≥ 0 up to round-off
    const double principal = (c - 1) / (1 + std::sqrt(c));
    strain_sq += principal * principal;
    strain_sum += principal;
  }
  return l.mu * strain_sq + 0.5 * l.lambda * strain_sum * strain_sum;
}

// P = 2μ vec(F) + ψ_s ∇s, ψ_s = -2μ + λ (s - 2).
Vec6 CorotationalStress(const MembraneLame& l, const Mat32& f) {
  const CorotationalTerms t = Corotational(f);
  return 2 * l.mu * Vec(f) + (-2 * l.mu + l.lambda * (t.s - 2)) * t.grad_s;
}

// ∂P/∂F = 2μ I + ψ_s ∇²s + λ ∇s ∇sᵀ, with ∇²s = (I + ∇²J - ∇s ∇sᵀ) / s (from s² = I1 + 2J) and
// ∇²J = Aᵀ (I - n nᵀ) A / J + [[0, -[n]×], [[n]×, 0]], A = ∂(f1 × f2)/∂(f1, f2) = (-[f2]×, [f1]×).
Mat6 CorotationalStressDerivative(const MembraneLame& l, const Mat32& f) {
  const CorotationalTerms t = Corotational(f);
  const Eigen::Vector3d f1 = f.col(0), f2 = f.col(1);
  Eigen::Matrix<double, 3, 6> a;
  a << -Skew(f2), Skew(f1);
  Mat6 hess_j = Mat6::Zero();
  if (t.j > 0)
    hess_j = a.transpose() * (Eigen::Matrix3d::Identity() - t.n * t.n.transpose()) * a / t.j;
  hess_j.block<3, 3>(0, 3) -= Skew(t.n);
  hess_j.block<3, 3>(3, 0) += Skew(t.n);
  const double s = std::max(t.s, 1e-300);
  const Mat6 hess_s = (Mat6::Identity() + hess_j - t.grad_s * t.grad_s.transpose()) / s;
  const double psi_s = -2 * l.mu + l.lambda * (t.s - 2);
  return 2 * l.mu * Mat6::Identity() + psi_s * hess_s + l.lambda * t.grad_s * t.grad_s.transpose();
}

// Clamps negative eigenvalues to zero (Teran et al. 2005; Sensitive Couture section 5).
Mat6 ProjectPsd(const Mat6& h) {
  Mat6 sym = 0.5 * (h + h.transpose());
  if (Eigen::LLT<Mat6>(sym).info() == Eigen::Success) return sym;  // positive definite: cheap exit
  Eigen::SelfAdjointEigenSolver<Mat6> eig(sym);
  if (eig.eigenvalues().minCoeff() >= 0) return sym;
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eig.eigenvectors().transpose();
}

// The eigenvalues of ∂²ψ/∂F² for an isotropic ψ(σ1, σ2) of a 3×2 F = Σ σi ui viᵀ
// (u3 = u1 × u2), ψi = ∂ψ/∂σi (Smith, de Goes and Kim 2019, "Analytic eigensystems for
// isotropic distortion energies", here with the two out-of-plane directions of a 3×2 F): the
// stretches a u1 v1ᵀ + b u2 v2ᵀ, (a, b) the eigenvectors of the 2×2 Hessian ∂²ψ/∂σ²; the
// in-plane shear (u1 v2ᵀ + u2 v1ᵀ)/√2, (ψ1 − ψ2)/(σ1 − σ2); the in-plane twist
// (u1 v2ᵀ − u2 v1ᵀ)/√2, (ψ1 + ψ2)/(σ1 + σ2); the out-of-plane u3 viᵀ, ψi/σi.
struct IsotropicEigenvalues {
  Eigen::Matrix2d stretch;  // ∂²ψ/∂σi∂σj
  double shear = 0, twist = 0;
  double out[2] = {0, 0};
};

// F = Σ σi ui viᵀ (σ1 ≥ σ2, vi in the rest frame, u3 = u1 × u2) for the eigensystem above.
// σ2 is J/σ1 (J = |f1 × f2| = σ1 σ2), not the root of FᵀF's smaller eigenvalue, which loses
// eps (σ1/σ2)² of it to cancellation: at σ2 = 1e-5 σ1 the corotational ψ2/σ2 came out so far off
// that the "projected" matrix had an eigenvalue of −0.18 × 2μ. A triangle collapsed to under
// 1e-6 σ1 (`collapsed`) gets any unit u2 normal to u1; F = 0 has no frame (false).
struct IsotropicFrame {
  double sigma[2];
  Eigen::Vector2d v[2];
  Eigen::Vector3d u[2], u3;
  bool collapsed = false;
};

bool SingularFrame(const Mat32& f, IsotropicFrame* frame) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> cauchy_green;
  cauchy_green.computeDirect(f.transpose() * f);  // eigenvalues σi² in increasing order
  const double large = std::sqrt(std::max(cauchy_green.eigenvalues()(1), 0.0));
  if (!(large > 0)) return false;
  const double small = f.col(0).cross(f.col(1)).norm() / large;
  frame->sigma[0] = large;
  frame->sigma[1] = small;
  frame->v[0] = cauchy_green.eigenvectors().col(1);
  frame->v[1] = cauchy_green.eigenvectors().col(0);
  frame->collapsed = !(small > 1e-6 * large);
  frame->u[0] = f * frame->v[0] / large;
  frame->u[1] = frame->collapsed ? Eigen::Vector3d(frame->u[0].unitOrthogonal())
                                 : Eigen::Vector3d(f * frame->v[1] / small);
  frame->u3 = frame->u[0].cross(frame->u[1]).normalized();
  return true;
}

// Calls visit(eigenvalue, q) for the six eigenpairs of ∂²ψ/∂F² (q of unit length, as vec(F)).
template <typename Visit>
void ForEachIsotropicEigenpair(const IsotropicFrame& fr, const IsotropicEigenvalues& e,
                               Visit visit) {
  auto outer = [](const Eigen::Vector3d& a, const Eigen::Vector2d& b) {
    return Vec(a * b.transpose());
  };
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> stretch;
  stretch.computeDirect(e.stretch);
  const Vec6 d1 = outer(fr.u[0], fr.v[0]), d2 = outer(fr.u[1], fr.v[1]);
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d ab = stretch.eigenvectors().col(k);
    visit(stretch.eigenvalues()(k), ab(0) * d1 + ab(1) * d2);
  }
  const Vec6 uv = outer(fr.u[0], fr.v[1]), vu = outer(fr.u[1], fr.v[0]);
  visit(e.shear, (uv + vu) / std::sqrt(2.0));
  visit(e.twist, (uv - vu) / std::sqrt(2.0));
  for (int i = 0; i < 2; ++i) visit(e.out[i], outer(fr.u3, fr.v[i]));
}

// h (= ∂²ψ/∂F²) with its negative eigenvalues clamped to zero, from the eigensystem above instead
// of a 6×6 eigen-solve (8 % of a drape's samples): each negative eigenpair is taken out of h.
// F = 0 and collapsed triangles take the eigen-solve.
template <typename Eigenvalues>
Mat6 ProjectIsotropicPsd(const Mat32& f, const Mat6& h, Eigenvalues eigenvalues) {
  IsotropicFrame frame;
  if (!SingularFrame(f, &frame) || frame.collapsed) return ProjectPsd(h);
  Mat6 projected = 0.5 * (h + h.transpose());
  ForEachIsotropicEigenpair(frame, eigenvalues(frame.sigma[0], frame.sigma[1]),
                            [&](double eigenvalue, const Vec6& q) {
                              if (eigenvalue < 0) projected -= eigenvalue * q * q.transpose();
                            });
  return projected;
}

// Corotational: ψi = 2μ (σi − 1) + λ (s − 2), s = σ1 + σ2; shear 2μ, twist 2(μ + λ)(s − 2)/s.
IsotropicEigenvalues CorotationalEigenvalues(const MembraneLame& l, double s1, double s2) {
  IsotropicEigenvalues e;
  const double s = s1 + s2;
  e.stretch << 2 * l.mu + l.lambda, l.lambda, l.lambda, 2 * l.mu + l.lambda;
  e.shear = 2 * l.mu;
  e.twist = 2 * (l.mu + l.lambda) * (s - 2) / s;
  e.out[0] = (2 * l.mu * (s1 - 1) + l.lambda * (s - 2)) / s1;
  e.out[1] = (2 * l.mu * (s2 - 1) + l.lambda * (s - 2)) / s2;
  return e;
}

// StVK: Ei = (σi² − 1)/2, principal stresses Si = 2μ Ei + λ (E1 + E2), ψi = σi Si;
// ∂²ψ/∂σi² = Si + (2μ + λ) σi², ∂²ψ/∂σ1∂σ2 = λ σ1 σ2; shear λ tr E + μ (σ1² + σ1 σ2 + σ2² − 1),
// twist λ tr E + μ (σ1² − σ1 σ2 + σ2² − 1); out of plane Si.
IsotropicEigenvalues StvkEigenvalues(const MembraneLame& l, double s1, double s2) {
  IsotropicEigenvalues e;
  const double e1 = 0.5 * (s1 * s1 - 1), e2 = 0.5 * (s2 * s2 - 1), tr = e1 + e2;
  const double stress1 = 2 * l.mu * e1 + l.lambda * tr, stress2 = 2 * l.mu * e2 + l.lambda * tr;
  e.stretch << stress1 + (2 * l.mu + l.lambda) * s1 * s1, l.lambda * s1 * s2, l.lambda * s1 * s2,
      stress2 + (2 * l.mu + l.lambda) * s2 * s2;
  e.shear = l.lambda * tr + l.mu * (s1 * s1 + s1 * s2 + s2 * s2 - 1);
  e.twist = l.lambda * tr + l.mu * (s1 * s1 - s1 * s2 + s2 * s2 - 1);
  e.out[0] = stress1;
  e.out[1] = stress2;
  return e;
}

// Soft StVK: ψi = σi Si; ∂²ψ/∂σi² = Si + (2μ wi + λ wt) σi², ∂²ψ/∂σ1∂σ2 = λ wt σ1 σ2; shear
// (ψ1 − ψ2)/(σ1 − σ2) = λ wt tr E + μ (w1 (σ1³ − σ1) − w2 (σ2³ − σ2))/(σ1 − σ2), in closed form
// μ w (σ1² + σ1 σ2 + σ2² − 1) when w1 = w2; twist (ψ1 + ψ2)/(σ1 + σ2); out of plane Si.
IsotropicEigenvalues SoftEigenvalues(const MembraneLame& l, double s1, double s2) {
  IsotropicEigenvalues e;
  const double e1 = 0.5 * (s1 * s1 - 1), e2 = 0.5 * (s2 * s2 - 1), tr = e1 + e2;
  const SoftPiece p1 = Piece(l, e1), p2 = Piece(l, e2), pt = Piece(l, tr);
  const double w1 = p1.weight, w2 = p2.weight, wt = pt.weight;
  const double trace_stress = 0.5 * l.lambda * pt.dq(tr);  // λ/2 q'(tr E)
  const double stress1 = l.mu * p1.dq(e1) + trace_stress;
  const double stress2 = l.mu * p2.dq(e2) + trace_stress;
  e.stretch << stress1 + (2 * l.mu * w1 + l.lambda * wt) * s1 * s1, l.lambda * wt * s1 * s2,
      l.lambda * wt * s1 * s2, stress2 + (2 * l.mu * w2 + l.lambda * wt) * s2 * s2;
  // (σ1 q'(E1) - σ2 q'(E2)) / (σ1 - σ2), in closed form when both are on one piece.
  const bool one_piece = w1 == w2 && p1.kappa == p2.kappa;
  const double shear_mu =
      one_piece || !(s1 - s2 > 1e-12)
          ? 0.5 * (w1 + w2) * (s1 * s1 + s1 * s2 + s2 * s2 - 1) + 0.5 * (p1.kappa + p2.kappa)
          : (s1 * p1.dq(e1) - s2 * p2.dq(e2)) / (s1 - s2);
  e.shear = trace_stress + l.mu * shear_mu;
  e.twist = (s1 * stress1 + s2 * stress2) / (s1 + s2);
  e.out[0] = stress1;
  e.out[1] = stress2;
  return e;
}

// ∂²ψ/∂F² of an isotropic ψ(σ1, σ2) assembled from its eigensystem (above), its negative
// eigenvalues dropped when project.
template <typename Eigenvalues>
Mat6 IsotropicHessian(const Mat32& f, Eigenvalues eigenvalues, bool project) {
  IsotropicFrame frame;
  if (!SingularFrame(f, &frame)) {  // F = 0: ∂P/∂F = S I, S the (equal) principal stress
    const double s = eigenvalues(0.0, 0.0).out[0];
    return (project ? std::max(s, 0.0) : s) * Mat6::Identity();
  }
  Mat6 h = Mat6::Zero();
  ForEachIsotropicEigenpair(frame, eigenvalues(frame.sigma[0], frame.sigma[1]),
                            [&](double eigenvalue, const Vec6& q) {
                              if (!project || eigenvalue > 0) h += eigenvalue * q * q.transpose();
                            });
  return h;
}

// Whether the soft membrane differs from StVK at F: some principal Green strain (and so
// possibly the trace) is negative, which a positive semi-definite E rules out. Stretched
// triangles take StVK's closed forms, without the eigen-solves.
bool SoftApplies(const MembraneLame& l, const Mat32& f) {
  if (!(l.compression < 1.0)) return false;
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  return e.trace() < 0 || e.determinant() < 0;
}

// StVK's Hessian is positive semi-definite when the Green strain is (no direction compressed)
// and λ ≥ 0: then its projection is itself and the eigen-solve can be skipped.
bool StvkNeedsProjection(const MembraneLame& l, const Mat32& f) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  return l.lambda < 0 || e.trace() < 0 || e.determinant() < 0;
}

// ---- Orthotropic (MembraneModel::kOrthotropic): ψ = W_w(|f1| - 1) + W_f(|f2| - 1) + ½ G γ²,
// γ = f1·f2, with f1 = F x, f2 = F y the columns of F in the warp-first rest frame.

// One yarn line a: its stretched direction n = f/|f|, strain ε = |f| - 1, and W'(ε), W''(ε).
struct YarnTerms {
  Eigen::Vector3d n;
  double length = 0, force = 0, stiffness = 0;
};

YarnTerms Yarn(const TensileCurve& curve, const MembraneCompression& c, const Eigen::Vector3d& f) {
  YarnTerms t;
  t.length = f.norm();
  // A yarn collapsed to a point has no direction; any unit n keeps the terms finite.
  t.n = t.length > 1e-12 ? Eigen::Vector3d(f / t.length) : Eigen::Vector3d::UnitX();
  t.force = YarnForce(curve, c, t.length - 1.0);
  t.stiffness = YarnStiffness(curve, c, t.length - 1.0);
  return t;
}

double OrthotropicDensity(const OrthotropicMembrane& law, const MembraneCompression& c,
                          const Mat32& f) {
  const double gamma = f.col(0).dot(f.col(1));
  return YarnEnergy(law.warp, c, f.col(0).norm() - 1.0) +
         YarnEnergy(law.weft, c, f.col(1).norm() - 1.0) + 0.5 * law.shear_modulus * gamma * gamma;
}

// P = ∂ψ/∂(f1, f2) = (W_w' n1 + G γ f2, W_f' n2 + G γ f1).
Vec6 OrthotropicStress(const OrthotropicMembrane& law, const MembraneCompression& c,
                       const Mat32& f) {
  const YarnTerms warp = Yarn(law.warp, c, f.col(0)), weft = Yarn(law.weft, c, f.col(1));
  const double g_gamma = law.shear_modulus * f.col(0).dot(f.col(1));
  Vec6 p;
  p << warp.force * warp.n + g_gamma * f.col(1), weft.force * weft.n + g_gamma * f.col(0);
  return p;
}

// A yarn's block of ∂²ψ/∂F²: W'' n nᵀ + W'/|f| (I - n nᵀ), the geometric part dropped when
// W' < 0 (a compressed yarn, whose sideways curvature is negative) if `project`.
Eigen::Matrix3d YarnBlock(const YarnTerms& t, bool project) {
  const Eigen::Matrix3d nn = t.n * t.n.transpose();
  const double geometric = project ? std::max(t.force, 0.0) : t.force;
  return t.stiffness * nn +
         geometric / std::max(t.length, 1e-12) * (Eigen::Matrix3d::Identity() - nn);
}

// The shear term's ∂²(½ G γ²)/∂F² = G (q qᵀ + γ S), q = (f2, f1), S = [[0, I], [I, 0]]. In the
// orthonormal coordinates s = (a + b)/√2, d = (a - b)/√2 of vec(F) = (a, b), S = diag(I, -I)
// and q = (ŝ |q_s|, d̂ |q_d|), q_s = (f1 + f2)/√2, q_d = (f2 - f1)/√2: the eigenvalues are G γ
// on s ⊥ ŝ, -G γ on d ⊥ d̂ (twice each) and those of G [[|q_s|² + γ, |q_s||q_d|],
// [|q_s||q_d|, |q_d|² - γ]] on (ŝ, d̂). With project, the negative ones are left out.
Mat6 ShearBlock(double shear_modulus, const Mat32& f, bool project) {
  const Eigen::Vector3d f1 = f.col(0), f2 = f.col(1);
  const double gamma = f1.dot(f2);
  Vec6 q;
  q << f2, f1;
  Mat6 h = q * q.transpose();
  h.block<3, 3>(0, 3).diagonal().array() += gamma;
  h.block<3, 3>(3, 0).diagonal().array() += gamma;
  if (!project || gamma == 0.0) return shear_modulus * h;
  const double r = 1.0 / std::sqrt(2.0);
  const Eigen::Vector3d qs = r * (f1 + f2), qd = r * (f2 - f1);
  const double ns = qs.norm(), nd = qd.norm();
  const Eigen::Vector3d us = ns > 0 ? Eigen::Vector3d(qs / ns) : Eigen::Vector3d(qd.unitOrthogonal());
  const Eigen::Vector3d ud = nd > 0 ? Eigen::Vector3d(qd / nd) : Eigen::Vector3d(qs.unitOrthogonal());
  // vec(F) of a unit vector u in s or d coordinates: (u, u)/√2 or (u, -u)/√2.
  auto in_s = [&](const Eigen::Vector3d& u) { Vec6 v; v << r * u, r * u; return v; };
  auto in_d = [&](const Eigen::Vector3d& u) { Vec6 v; v << r * u, -r * u; return v; };
  // The two-fold -|γ| eigenspace: d ⊥ d̂ when γ > 0, s ⊥ ŝ when γ < 0.
  const Eigen::Vector3d axis = gamma > 0 ? ud : us;
  const Eigen::Matrix3d complement = Eigen::Matrix3d::Identity() - axis * axis.transpose();
  Mat6 lift = Mat6::Zero();  // the 6×6 projector onto that eigenspace
  lift.block<3, 3>(0, 0) = lift.block<3, 3>(3, 3) = 0.5 * complement;
  lift.block<3, 3>(0, 3) = lift.block<3, 3>(3, 0) = (gamma > 0 ? -0.5 : 0.5) * complement;
  h += std::abs(gamma) * lift;
  // The 2×2 block on (ŝ, d̂): at most one negative eigenvalue (its determinant may be < 0).
  Eigen::Matrix2d m;
  m << ns * ns + gamma, ns * nd, ns * nd, nd * nd - gamma;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(m);
  if (eig.eigenvalues()(0) < 0) {
    const Eigen::Vector2d ab = eig.eigenvectors().col(0);
    const Vec6 v = ab(0) * in_s(us) + ab(1) * in_d(ud);
    h -= eig.eigenvalues()(0) * v * v.transpose();
  }
  return shear_modulus * h;
}

// ∂²ψ/∂F²: yarn blocks on the diagonal plus the shear term. project_psd keeps the exact matrix
// when it is positive definite (a 6×6 Cholesky) and otherwise sums the terms' own projections.
Mat6 OrthotropicStressDerivative(const OrthotropicMembrane& law, const MembraneCompression& c,
                                 const Mat32& f, bool project) {
  const YarnTerms warp = Yarn(law.warp, c, f.col(0)), weft = Yarn(law.weft, c, f.col(1));
  Mat6 h = ShearBlock(law.shear_modulus, f, false);
  h.block<3, 3>(0, 0) += YarnBlock(warp, false);
  h.block<3, 3>(3, 3) += YarnBlock(weft, false);
  if (!project) return h;
  // Nothing compressed and no shear: every term is positive semi-definite already.
  if (warp.force >= 0 && weft.force >= 0 && f.col(0).dot(f.col(1)) == 0.0) return h;
  if (Eigen::LLT<Mat6>(h).info() == Eigen::Success) return h;
  Mat6 p = ShearBlock(law.shear_modulus, f, true);
  p.block<3, 3>(0, 0) += YarnBlock(warp, true);
  p.block<3, 3>(3, 3) += YarnBlock(weft, true);
  return p;
}

}  // namespace

MembraneLame MembraneLame::FromStretch(double stretch_stiffness, double poisson,
                                       double compression, double buckling_strain) {
  if (!(stretch_stiffness > 0) || !std::isfinite(stretch_stiffness)) {
    throw InputError("membrane: stretch_stiffness must be a positive number of N/m, got " +
                     NumberText(stretch_stiffness));
  }
  if (!(poisson > -1 && poisson < 1)) {
    throw InputError("membrane: poisson must lie in (-1, 1) for a stable sheet, got " +
                     NumberText(poisson));
  }
  if (!(compression >= kMinCompressionRatio && compression <= 1)) {
    throw InputError("membrane: compression ratio must lie in [" + NumberText(kMinCompressionRatio) +
                     ", 1], got " + NumberText(compression));
  }
  if (!(buckling_strain >= 0 && buckling_strain < 1)) {
    throw InputError("membrane: buckling strain must lie in [0, 1), got " +
                     NumberText(buckling_strain));
  }
  MembraneLame l;
  l.compression = compression;
  // The Green strain of the engineering strain -ε_b: ½ ((1 - ε_b)² - 1) = -(ε_b - ε_b²/2).
  l.buckling = buckling_strain - 0.5 * buckling_strain * buckling_strain;
  l.mu = stretch_stiffness / (2 * (1 + poisson));
  l.lambda = stretch_stiffness * poisson / (1 - poisson * poisson);
  return l;
}

double MembraneEnergy(MembraneModel model, const MembraneLame& lame,
                      const Eigen::Matrix2d& rest_inverse, double rest_area,
                      const Eigen::Matrix3d& x) {
  assert(model != MembraneModel::kOrthotropic);  // OrthotropicMembraneEnergy
  const Mat32 f = DeformationGradient(rest_inverse, x);
  const double psi = model != MembraneModel::kStVK ? CorotationalDensity(lame, f)
                     : SoftApplies(lame, f)        ? SoftDensity(lame, f)
                                                   : StvkDensity(lame, f);
  return rest_area * psi;
}

Eigen::Matrix<double, 9, 1> MembraneGradient(MembraneModel model, const MembraneLame& lame,
                                             const Eigen::Matrix2d& rest_inverse, double rest_area,
                                             const Eigen::Matrix3d& x) {
  const Mat32 f = DeformationGradient(rest_inverse, x);
  const Vec6 p = model != MembraneModel::kStVK ? CorotationalStress(lame, f)
                 : SoftApplies(lame, f)        ? SoftStress(lame, f)
                                               : StvkStress(lame, f);
  return rest_area * GradientMap(rest_inverse).transpose() * p;
}

Eigen::Matrix<double, 9, 9> MembraneHessian(MembraneModel model, const MembraneLame& lame,
                                            const Eigen::Matrix2d& rest_inverse, double rest_area,
                                            const Eigen::Matrix3d& x, bool project_psd) {
  const Mat32 f = DeformationGradient(rest_inverse, x);
  Mat6 h;
  if (model == MembraneModel::kStVK && SoftApplies(lame, f)) {
    h = IsotropicHessian(
        f, [&](double s1, double s2) { return SoftEigenvalues(lame, s1, s2); }, project_psd);
  } else if (model == MembraneModel::kStVK) {
    h = StvkStressDerivative(lame, f);
    if (project_psd && StvkNeedsProjection(lame, f))
      h = ProjectIsotropicPsd(f, h, [&](double s1, double s2) { return StvkEigenvalues(lame, s1, s2); });
  } else {
    h = CorotationalStressDerivative(lame, f);
    if (project_psd)
      h = ProjectIsotropicPsd(f, h, [&](double s1, double s2) { return CorotationalEigenvalues(lame, s1, s2); });
  }
  const Eigen::Matrix<double, 6, 9> g = GradientMap(rest_inverse);
  return rest_area * g.transpose() * h * g;
}

double OrthotropicMembraneEnergy(const OrthotropicMembrane& law,
                                 const MembraneCompression& compression,
                                 const Eigen::Matrix2d& rest_inverse, double rest_area,
                                 const Eigen::Matrix3d& x) {
  return rest_area * OrthotropicDensity(law, compression, DeformationGradient(rest_inverse, x));
}

Eigen::Matrix<double, 9, 1> OrthotropicMembraneGradient(const OrthotropicMembrane& law,
                                                        const MembraneCompression& compression,
                                                        const Eigen::Matrix2d& rest_inverse,
                                                        double rest_area,
                                                        const Eigen::Matrix3d& x) {
  const Vec6 p = OrthotropicStress(law, compression, DeformationGradient(rest_inverse, x));
  return rest_area * GradientMap(rest_inverse).transpose() * p;
}

Eigen::Matrix<double, 9, 9> OrthotropicMembraneHessian(const OrthotropicMembrane& law,
                                                       const MembraneCompression& compression,
                                                       const Eigen::Matrix2d& rest_inverse,
                                                       double rest_area, const Eigen::Matrix3d& x,
                                                       bool project_psd) {
  const Mat6 h = OrthotropicStressDerivative(law, compression,
                                             DeformationGradient(rest_inverse, x), project_psd);
  const Eigen::Matrix<double, 6, 9> g = GradientMap(rest_inverse);
  return rest_area * g.transpose() * h * g;
}

Eigen::Matrix2d RestInverse(const Eigen::Matrix3d& corners, int index, double* rest_area) {
  const Eigen::Vector3d e1 = (corners.row(1) - corners.row(0)).transpose(),
                        e2 = (corners.row(2) - corners.row(0)).transpose();
  const Eigen::Vector3d normal = e1.cross(e2);
  const double area = 0.5 * normal.norm();
  if (!(area > 1e-14 * std::max(e1.squaredNorm(), e2.squaredNorm())) || !std::isfinite(area)) {
    throw InputError("membrane: rest triangle " + std::to_string(index) + " is degenerate (area " +
                     NumberText(area) + " m²)");
  }
  // t1: pattern x in the triangle's plane, the warp; the first edge if x is (nearly) normal.
  const Eigen::Vector3d n = normal.normalized();
  Eigen::Vector3d t1 = Eigen::Vector3d::UnitX() - n.x() * n;
  t1 = t1.norm() > 1e-6 ? Eigen::Vector3d(t1.normalized()) : Eigen::Vector3d(e1.normalized());
  const Eigen::Vector3d t2 = n.cross(t1);
  Eigen::Matrix2d dm;
  dm << e1.dot(t1), e2.dot(t1), e1.dot(t2), e2.dot(t2);
  *rest_area = area;
  return dm.inverse();
}

MembraneElements::MembraneElements(const TriangleMesh& rest, double stretch_stiffness,
                                   double poisson, MembraneModel model, double compression,
                                   double buckling_strain)
    : model_(model),
      lame_(MembraneLame::FromStretch(stretch_stiffness, poisson, compression, buckling_strain)) {
  if (model == MembraneModel::kOrthotropic) {
    throw InputError("membrane: the orthotropic model needs a material's warp, weft and shear");
  }
  BuildRestShapes(rest);
}

namespace {

// The checks of the compression model and shear modulus the isotropic FromStretch does not make.
void CheckOrthotropic(const OrthotropicMembrane& law, const MembraneCompression& c) {
  if (!(law.shear_modulus >= 0) || !std::isfinite(law.shear_modulus)) {
    throw InputError("membrane: shear modulus must be a finite number ≥ 0 of N/m, got " +
                     NumberText(law.shear_modulus));
  }
  if (!(c.ratio >= kMinCompressionRatio && c.ratio <= 1)) {
    throw InputError("membrane: compression ratio must lie in [" + NumberText(kMinCompressionRatio) +
                     ", 1], got " + NumberText(c.ratio));
  }
  if (!(c.buckling_strain >= 0) || !std::isfinite(c.buckling_strain)) {
    throw InputError("membrane: buckling strain must be a finite number ≥ 0, got " +
                     NumberText(c.buckling_strain));
  }
}

}  // namespace

MembraneElements::MembraneElements(const TriangleMesh& rest, const Material& material,
                                   MembraneModel model)
    : model_(material.orthotropic ? MembraneModel::kOrthotropic : model),
      compression_(material.Compression()) {
  if (material.orthotropic) {
    orthotropic_ = *material.orthotropic;
    CheckOrthotropic(orthotropic_, compression_);
  } else {
    if (model == MembraneModel::kOrthotropic) {
      throw InputError("membrane: the orthotropic model needs a material's warp, weft and shear");
    }
    lame_ = MembraneLame::FromStretch(material.stretch_stiffness, material.poisson,
                                      material.compression_ratio, material.buckling_strain);
  }
  BuildRestShapes(rest);
}

void MembraneElements::BuildRestShapes(const TriangleMesh& rest) {
  num_vertices_ = rest.num_vertices();
  triangles_ = rest.triangles;
  const int nf = rest.num_triangles();
  rest_inverse_.resize(nf);
  rest_area_.resize(nf);
  for (int f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) {
      if (triangles_(f, c) < 0 || triangles_(f, c) >= num_vertices_) {
        throw InputError("membrane: triangle " + std::to_string(f) + " refers to vertex " +
                         std::to_string(triangles_(f, c)) + ", outside 0.." +
                         std::to_string(num_vertices_ - 1));
      }
    }
    Eigen::Matrix3d corners;
    for (int k = 0; k < 3; ++k) corners.row(k) = rest.vertices.row(triangles_(f, k));
    rest_inverse_[f] = RestInverse(corners, f, &rest_area_(f));
  }
}

void MembraneElements::CheckSize(Eigen::Ref<const Vertices> x) const {
  if (x.rows() != num_vertices_) {
    throw InputError("membrane: positions have " + std::to_string(x.rows()) +
                     " rows, the mesh has " + std::to_string(num_vertices_) + " vertices");
  }
}

Eigen::Matrix3d MembraneElements::Corners(Eigen::Ref<const Vertices> x, int f) const {
  Eigen::Matrix3d c;
  for (int k = 0; k < 3; ++k) c.row(k) = x.row(triangles_(f, k));
  return c;
}

double MembraneElements::Energy(Eigen::Ref<const Vertices> x) const {
  CheckSize(x);
  double e = 0;
  for (int f = 0; f < num_triangles(); ++f) {
    e += model_ == MembraneModel::kOrthotropic
             ? OrthotropicMembraneEnergy(orthotropic_, compression_, rest_inverse_[f],
                                         rest_area_(f), Corners(x, f))
             : MembraneEnergy(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f));
  }
  return e;
}

void MembraneElements::AddGradient(Eigen::Ref<const Vertices> x, Eigen::Ref<Vertices> grad) const {
  CheckSize(x);
  CheckSize(grad);
  for (int f = 0; f < num_triangles(); ++f) {
    const Eigen::Matrix<double, 9, 1> g =
        model_ == MembraneModel::kOrthotropic
            ? OrthotropicMembraneGradient(orthotropic_, compression_, rest_inverse_[f],
                                          rest_area_(f), Corners(x, f))
            : MembraneGradient(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f));
    for (int k = 0; k < 3; ++k) grad.row(triangles_(f, k)) += g.segment<3>(3 * k).transpose();
  }
}

void MembraneElements::AddHessianTriplets(Eigen::Ref<const Vertices> x,
                                          std::vector<Eigen::Triplet<double>>* triplets,
                                          bool project_psd) const {
  AddHessianTriplets(x, triplets, project_psd, 0, num_triangles());
}

void MembraneElements::AddHessianTriplets(Eigen::Ref<const Vertices> x,
                                          std::vector<Eigen::Triplet<double>>* triplets,
                                          bool project_psd, int first, int end) const {
  CheckSize(x);
  triplets->reserve(triplets->size() + 81 * static_cast<std::size_t>(end - first));
  for (int f = first; f < end; ++f) {
    const Eigen::Matrix<double, 9, 9> h =
        model_ == MembraneModel::kOrthotropic
            ? OrthotropicMembraneHessian(orthotropic_, compression_, rest_inverse_[f],
                                         rest_area_(f), Corners(x, f), project_psd)
            : MembraneHessian(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f),
                              project_psd);
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        for (int c = 0; c < 3; ++c) {
          for (int d = 0; d < 3; ++d) {
            triplets->emplace_back(3 * triangles_(f, a) + c, 3 * triangles_(f, b) + d,
                                   h(3 * a + c, 3 * b + d));
          }
        }
      }
    }
  }
}

}  // namespace textile
