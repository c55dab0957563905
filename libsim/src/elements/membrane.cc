#include "textile/sim/elements/membrane.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
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
// λ/2 q(E1 + E2) over the principal Green strains, q(t) = w(t) t² with w = 1 for t ≥ 0 and c for
// t < 0.

// The principal strains Ei (E1 ≥ E2), their unit eigenvectors vi in the rest frame and the
// principal second Piola-Kirchhoff stresses Si = ∂ψ/∂Ei = 2μ wi Ei + λ wt tr E.
struct SoftStrains {
  double strain[2];
  Eigen::Vector2d v[2];
  double stress[2];
  double weight[2], weight_trace;
};

SoftStrains Soft(const MembraneLame& l, const Mat32& f) {
  SoftStrains t;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> green;
  green.computeDirect(0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity()));
  for (int i = 0; i < 2; ++i) {
    t.strain[i] = green.eigenvalues()(1 - i);
    t.v[i] = green.eigenvectors().col(1 - i);
    t.weight[i] = t.strain[i] < 0 ? l.compression : 1.0;
  }
  const double tr = t.strain[0] + t.strain[1];
  t.weight_trace = tr < 0 ? l.compression : 1.0;
  for (int i = 0; i < 2; ++i)
    t.stress[i] = 2 * l.mu * t.weight[i] * t.strain[i] + l.lambda * t.weight_trace * tr;
  return t;
}

double SoftDensity(const MembraneLame& l, const Mat32& f) {
  const SoftStrains t = Soft(l, f);
  const double tr = t.strain[0] + t.strain[1];
  return l.mu *
             (t.weight[0] * t.strain[0] * t.strain[0] + t.weight[1] * t.strain[1] * t.strain[1]) +
         0.5 * l.lambda * t.weight_trace * tr * tr;
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
  const double c = l.compression;
  const double e1 = 0.5 * (s1 * s1 - 1), e2 = 0.5 * (s2 * s2 - 1), tr = e1 + e2;
  const double w1 = e1 < 0 ? c : 1.0, w2 = e2 < 0 ? c : 1.0, wt = tr < 0 ? c : 1.0;
  const double stress1 = 2 * l.mu * w1 * e1 + l.lambda * wt * tr;
  const double stress2 = 2 * l.mu * w2 * e2 + l.lambda * wt * tr;
  e.stretch << stress1 + (2 * l.mu * w1 + l.lambda * wt) * s1 * s1, l.lambda * wt * s1 * s2,
      l.lambda * wt * s1 * s2, stress2 + (2 * l.mu * w2 + l.lambda * wt) * s2 * s2;
  const double shear_mu = w1 == w2 || !(s1 - s2 > 1e-12)
                              ? 0.5 * (w1 + w2) * (s1 * s1 + s1 * s2 + s2 * s2 - 1)
                              : (w1 * (s1 * s1 * s1 - s1) - w2 * (s2 * s2 * s2 - s2)) / (s1 - s2);
  e.shear = l.lambda * wt * tr + l.mu * shear_mu;
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

}  // namespace

MembraneLame MembraneLame::FromStretch(double stretch_stiffness, double poisson,
                                       double compression) {
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
  MembraneLame l;
  l.compression = compression;
  l.mu = stretch_stiffness / (2 * (1 + poisson));
  l.lambda = stretch_stiffness * poisson / (1 - poisson * poisson);
  return l;
}

double MembraneEnergy(MembraneModel model, const MembraneLame& lame,
                      const Eigen::Matrix2d& rest_inverse, double rest_area,
                      const Eigen::Matrix3d& x) {
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

MembraneElements::MembraneElements(const TriangleMesh& rest, double stretch_stiffness,
                                   double poisson, MembraneModel model, double compression)
    : model_(model), lame_(MembraneLame::FromStretch(stretch_stiffness, poisson, compression)) {
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
    const Eigen::Vector3d x0 = rest.vertices.row(triangles_(f, 0)),
                          x1 = rest.vertices.row(triangles_(f, 1)),
                          x2 = rest.vertices.row(triangles_(f, 2));
    // A frame of the triangle's plane: t1 along the first edge, t2 = n × t1.
    const Eigen::Vector3d e1 = x1 - x0, e2 = x2 - x0;
    const Eigen::Vector3d normal = e1.cross(e2);
    const double area = 0.5 * normal.norm();
    if (!(area > 1e-14 * std::max(e1.squaredNorm(), e2.squaredNorm())) || !std::isfinite(area)) {
      throw InputError("membrane: rest triangle " + std::to_string(f) + " is degenerate (area " +
                       NumberText(area) + " m²)");
    }
    const Eigen::Vector3d t1 = e1.normalized(), t2 = normal.normalized().cross(t1);
    Eigen::Matrix2d dm;
    dm << e1.dot(t1), e2.dot(t1), 0.0, e2.dot(t2);
    rest_inverse_[f] = dm.inverse();
    rest_area_(f) = area;
  }
}

MembraneElements::MembraneElements(const TriangleMesh& rest, const Material& material,
                                   MembraneModel model)
    : MembraneElements(rest, material.stretch_stiffness, material.poisson, model,
                       material.compression_ratio) {}

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
    e += MembraneEnergy(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f));
  }
  return e;
}

void MembraneElements::AddGradient(Eigen::Ref<const Vertices> x, Eigen::Ref<Vertices> grad) const {
  CheckSize(x);
  CheckSize(grad);
  for (int f = 0; f < num_triangles(); ++f) {
    const Eigen::Matrix<double, 9, 1> g =
        MembraneGradient(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f));
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
        MembraneHessian(model_, lame_, rest_inverse_[f], rest_area_(f), Corners(x, f), project_psd);
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
