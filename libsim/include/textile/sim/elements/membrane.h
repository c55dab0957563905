#ifndef TEXTILE_SIM_ELEMENTS_MEMBRANE_H_
#define TEXTILE_SIM_ELEMENTS_MEMBRANE_H_

// In-plane (membrane) elasticity of cloth: constant-strain triangles (CST) with energy, gradient
// and Hessian side by side. Three models (docs/spec/physics.md, "Membrane";
// docs/methods/meshing-and-membrane.md):
//
//   kCorotationalLinear  Pabst's linear-elastic CST: Hooke's law on the rotation-free strain
//                        ε = U - I of the polar decomposition F = R U, so large rotations of a
//                        small-strain triangle cost nothing and a stretch costs exactly ½ k ε².
//   kStVK                St. Venant-Kirchhoff on the Green strain E = ½(FᵀF - I). With
//                        project_psd it is the stabilised StVK CST of Sensitive Couture (section
//                        5): the Hessian's negative eigenvalues, which appear only in compression,
//                        are clamped to zero. Energy and forces are untouched, so the equilibria
//                        are the same; only a Newton step's direction changes.
//   kOrthotropic         a woven sheet's yarn laws (membrane_law.h's OrthotropicMembrane):
//                        ψ = W_warp(|F x| - 1) + W_weft(|F y| - 1) + ½ G ((F x)·(F y))², each W
//                        a tensile curve with the material's compression model; with project_psd
//                        the compressed yarns' and the shear's negative curvature is dropped in
//                        closed form (membrane.cc). Chosen by MembraneElements when the material
//                        has an orthotropic block.
//
// Every model's rest frame has its first axis along the pattern's x axis projected into the
// rest triangle's plane (the warp), the second at +90° about the triangle's normal; isotropic
// energies do not depend on it.
//
// The isotropic models use the plane-stress law of a 2D isotropic sheet with stretch stiffness k [N/m] (the
// Young's modulus times the thickness) and Poisson ratio ν: energy per rest area
//   ψ = k / (2 (1 - ν²)) · (e11² + e22² + 2 ν e11 e22 + 2 (1 - ν) e12²) = μ tr(e²) + λ/2 tr(e)²,
//   μ = k / (2 (1 + ν)),  λ = k ν / (1 - ν²),
// with e = ε (corotational) or e = E (StVK).
//
// Soft in compression (StVK with compression c < 1, the material's stretch.compression_ratio,
// and buckling strain ε_b ≥ 0): over the principal Green strains E1, E2,
// ψ = μ (q(E1) + q(E2)) + λ/2 q(E1 + E2) with q(t) = t² for t ≥ -b and
// b² - 2 b (t + b) + c (t + b)² past it (C¹; b = ε_b - ε_b²/2, the Green strain of -ε_b), which is
// StVK's ψ when c = 1; with ε_b = 0, q = c t² for t < 0. Woven fabric buckles at a small
// fraction of the load it takes in tension (what cloth tools call a buckling ratio); c is that
// fraction. The energy is C¹ (its stiffness jumps where a principal strain changes sign); the
// Hessian comes from the isotropic eigensystem in closed form (membrane.cc), exact or with its
// negative eigenvalues clamped (project_psd). docs/methods/drapemeter.md, "Compression ratio".
//
//   textile::MembraneElements membrane(rest_mesh, material, textile::MembraneModel::kStVK);
//   double energy = membrane.Energy(x);                      // x: #V×3 positions [m]
//   textile::Vertices grad = textile::Vertices::Zero(x.rows(), 3);
//   membrane.AddGradient(x, grad);                           // [N]; forces are -grad
//   std::vector<Eigen::Triplet<double>> triplets;
//   membrane.AddHessianTriplets(x, &triplets, /*project_psd=*/true);  // dof 3 v + c, [N/m]

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "textile/sim/law/material.h"
#include "textile/sim/mesh/mesh.h"

namespace textile {

enum class MembraneModel {
  kCorotationalLinear,  // linear-elastic CST made rotation-invariant by polar decomposition
  kStVK,                // St. Venant-Kirchhoff (Green strain); stabilised with project_psd
  kOrthotropic,         // yarn tensile curves along pattern x and y plus a shear modulus
};

// Lamé constants of the plane-stress sheet [N/m].
struct MembraneLame {
  double mu = 0.0;      // shear: k / (2 (1 + ν))
  double lambda = 0.0;  // k ν / (1 - ν²)
  // StVK only: the factor c on the energy of a compressed principal Green strain and of a
  // compressed area (tr E < 0), c = 1: plain StVK. See MembraneModel.
  double compression = 1.0;
  // StVK only: b, the Green strain down to which a compressed principal strain keeps the full
  // stiffness (the buckling strain ε_b as b = ε_b - ε_b²/2) [-].
  double buckling = 0.0;
  // Throws InputError unless k > 0 is finite, -1 < ν < 1 (a positive-definite sheet),
  // kMinCompressionRatio ≤ compression ≤ 1 and 0 ≤ buckling_strain < 1.
  static MembraneLame FromStretch(double stretch_stiffness, double poisson,
                                  double compression = 1.0, double buckling_strain = 0.0);
};

// One triangle, the building block of MembraneElements.
// @param rest_inverse  Dm⁻¹: inverse of the 2×2 matrix of rest edges (x1 - x0, x2 - x0) in a
//                      frame of the rest triangle's plane [1/m]
// @param rest_area     rest area [m²]
// @param x             3×3 current positions, one vertex per row [m]
// Energy [J]; gradient with respect to (x0, x1, x2) stacked, 9 [N]; Hessian 9×9 [N/m].
double MembraneEnergy(MembraneModel model, const MembraneLame& lame,
                      const Eigen::Matrix2d& rest_inverse, double rest_area,
                      const Eigen::Matrix3d& x);
Eigen::Matrix<double, 9, 1> MembraneGradient(MembraneModel model, const MembraneLame& lame,
                                             const Eigen::Matrix2d& rest_inverse, double rest_area,
                                             const Eigen::Matrix3d& x);
// project_psd: clamp the negative eigenvalues of the Hessian with respect to the deformation
// gradient (6×6) to zero, which makes the 9×9 Hessian positive semi-definite.
Eigen::Matrix<double, 9, 9> MembraneHessian(MembraneModel model, const MembraneLame& lame,
                                            const Eigen::Matrix2d& rest_inverse, double rest_area,
                                            const Eigen::Matrix3d& x, bool project_psd);

// The orthotropic model's triangle (MembraneModel::kOrthotropic), with the same parameters as
// above; rest_inverse must be in the frame whose first axis is the warp (pattern x).
// project_psd: the exact Hessian when it is positive definite, otherwise the compressed yarns'
// geometric stiffness W'(ε)/|F a| (I - n nᵀ) dropped (W' < 0) and the shear term's negative
// eigenpairs removed, each in closed form.
double OrthotropicMembraneEnergy(const OrthotropicMembrane& law,
                                 const MembraneCompression& compression,
                                 const Eigen::Matrix2d& rest_inverse, double rest_area,
                                 const Eigen::Matrix3d& x);
Eigen::Matrix<double, 9, 1> OrthotropicMembraneGradient(const OrthotropicMembrane& law,
                                                        const MembraneCompression& compression,
                                                        const Eigen::Matrix2d& rest_inverse,
                                                        double rest_area, const Eigen::Matrix3d& x);
Eigen::Matrix<double, 9, 9> OrthotropicMembraneHessian(const OrthotropicMembrane& law,
                                                       const MembraneCompression& compression,
                                                       const Eigen::Matrix2d& rest_inverse,
                                                       double rest_area, const Eigen::Matrix3d& x,
                                                       bool project_psd);

// Dm⁻¹ of a rest triangle (3 corners, one per row [m]) in the frame whose first axis is the
// pattern x axis projected into the triangle's plane (the first edge when x is within 1e-6 rad
// of the normal), the second n × the first. Throws InputError for a degenerate triangle,
// naming it by `index`.
Eigen::Matrix2d RestInverse(const Eigen::Matrix3d& corners, int index, double* rest_area);

// All membrane triangles of a mesh, with their rest shapes precomputed once.
class MembraneElements {
 public:
  // @param rest  rest mesh (flat patterns: z = 0, but any non-degenerate triangles work) [m]
  // An isotropic sheet (model kCorotationalLinear or kStVK).
  // Throws InputError for a bad stiffness or Poisson ratio, a triangle referring to a missing
  // vertex, or a degenerate rest triangle (naming it), or model kOrthotropic (no yarn laws).
  MembraneElements(const TriangleMesh& rest, double stretch_stiffness, double poisson,
                   MembraneModel model, double compression = 1.0, double buckling_strain = 0.0);
  // The orthotropic model when material.orthotropic is set (`model` is then ignored), otherwise
  // `model` with material.stretch_stiffness and material.poisson; material.Compression() in both
  // cases. Throws InputError as above, for a compression ratio outside
  // [kMinCompressionRatio, 1], a negative or non-finite shear modulus or buckling strain.
  MembraneElements(const TriangleMesh& rest, const Material& material, MembraneModel model);

  // @param x  #V×3 current positions [m]. Total membrane energy [J].
  double Energy(Eigen::Ref<const Vertices> x) const;
  // Adds ∂E/∂x [N] to grad (#V×3).
  void AddGradient(Eigen::Ref<const Vertices> x, Eigen::Ref<Vertices> grad) const;
  // Appends the Hessian [N/m] as (3 i + c, 3 j + d, value) triplets, 81 per triangle.
  void AddHessianTriplets(Eigen::Ref<const Vertices> x,
                          std::vector<Eigen::Triplet<double>>* triplets, bool project_psd) const;
  // Only triangles first ≤ f < end, in order.
  void AddHessianTriplets(Eigen::Ref<const Vertices> x,
                          std::vector<Eigen::Triplet<double>>* triplets, bool project_psd,
                          int first, int end) const;

  MembraneModel model() const { return model_; }
  const MembraneLame& lame() const { return lame_; }  // isotropic models only
  int num_vertices() const { return num_vertices_; }
  int num_triangles() const { return static_cast<int>(rest_area_.size()); }
  const Eigen::VectorXd& rest_areas() const { return rest_area_; }

 private:
  Eigen::Matrix3d Corners(Eigen::Ref<const Vertices> x, int f) const;
  void CheckSize(Eigen::Ref<const Vertices> x) const;
  void BuildRestShapes(const TriangleMesh& rest);

  MembraneModel model_;
  MembraneLame lame_;
  OrthotropicMembrane orthotropic_;  // kOrthotropic only
  MembraneCompression compression_;  // kOrthotropic only (the isotropic one is lame_.compression)
  int num_vertices_ = 0;
  Triangles triangles_;                        // #F×3
  std::vector<Eigen::Matrix2d> rest_inverse_;  // #F Dm⁻¹ [1/m]
  Eigen::VectorXd rest_area_;                  // #F [m²]
};

}  // namespace textile

#endif  // TEXTILE_SIM_ELEMENTS_MEMBRANE_H_
