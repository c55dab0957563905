#ifndef TEXTILE_SIM_ELEMENTS_TENSOR_BENDING_H_
#define TEXTILE_SIM_ELEMENTS_TENSOR_BENDING_H_

// Bending with a curvature tensor per triangle: Pabst's law applied to bend and twist
// separately (docs/methods/statics.md, "Bending-twist coupling").
//
//   textile::TriangleMesh rest = textile::RegularGridMesh(0.2, 0.05, 80, 20);
//   std::vector<textile::Hinge> hinges = textile::BuildHinges(rest);
//   textile::TensorBending bending(rest, hinges, fabric.EffectiveLaw(), std::nullopt, {});
//   textile::Vertices grad = textile::Vertices::Zero(rest.num_vertices(), 3);
//   double energy = bending.EnergyGradient(x, grad);           // J and N
//   Eigen::Matrix2d k = bending.Curvature(x, /*triangle=*/0);  // 1/m, warp/weft frame
//
// Why: every hinge energy (the four models of bending_element.h) is a sum over edges of a
// function of one normal curvature. On a triangle grid the diagonal edges see a mix of bend
// and twist, so a strip bent along x lowers its energy by twisting and curling: a free strip
// is 0.6-0.8 times as stiff as the law says (docs/methods/statics.md). Here each triangle t gets the
// tensor K_t that a quadratic height field through its three vertices and the three wing
// vertices across its edges has (a rotation-free plate triangle): with the wings' heights
// above the triangle's plane d_i sin θ_i ≈ d_i θ_i,
//
//   K_t = Σ_i (θ_i - θ̄_i) N_{t,i}          (i over the triangle's three edges)
//
// with 2×2 tensors N_{t,i} fixed by the rest geometry. K_t is exact for any quadratic surface
// on any mesh, and invariant under rigid motions because the θ_i are. The energy is
//
//   E = Σ_t S_t A_t [Ψ_warp(K_xx) + Ψ_weft(K_yy) + Ψ_warp(K_xy) + Ψ_weft(K_xy)]
//
// in the warp/weft frame (pattern x, y), Ψ the law's strain energy (Ψ' = M). A strip bent
// along the warp has K_yy = K_xy = 0 at the minimum and the energy A Ψ_warp(κ) of the elastica;
// for a linear isotropic law it is the plate energy ½ b (K_xx² + K_yy² + 2 K_xy²) (Poisson
// ratio 0); an orthotropic one twists with (b_warp + b_weft)/2. S_t is the mean seam
// multiplier of the triangle's interior edges.
//
// Free edges: an edge on the boundary has no wing; its condition is no curvature across the
// edge, m_iᵀ K_t m_i = 0 (m_i its in-plane normal), which for this energy (no Poisson coupling)
// is the moment-free edge whenever the edge runs along the warp or the weft, and holds
// exactly for a strip bent along its length. (Minimising the energy over the missing wing's
// height instead lets a skinny border triangle trade bend for the conic through its five
// points: a 2-cell-wide strip came out far too soft.)
//
// Units: positions [m], energy [J], gradient [N], Hessian [N/m].

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <vector>

#include "textile/sim/elements/bending_element.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/mesh/mesh.h"

namespace textile {

// How ClothProblem discretises bending.
enum class BendingDiscretization {
  kHinge,   // one energy per hinge, BendingOptions::model (the paper's eq. 2-6)
  kTensor,  // TensorBending: Pabst's law on a curvature tensor per triangle
};

class TensorBending {
 public:
  // @param rest    rest mesh (must pass CheckMesh); a curved rest state is allowed
  // @param hinges  BuildHinges(rest)
  // @param warp, weft  the laws along the pattern's x (warp) and y (weft), β applied;
  //                weft = nullopt for an isotropic fabric
  // @param hinge_multiplier  per-hinge seam factor S (#H values > 0) or empty for 1
  // Throws InputError naming the triangle when its rest patch is degenerate.
  TensorBending(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                const BendingLaw& warp, const std::optional<BendingLaw>& weft,
                const std::vector<double>& hinge_multiplier);

  double Energy(const Vertices& x) const;  // [J]
  // grad += ∇E [N]; returns E [J].
  double EnergyGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const;

  // Elements of the Hessian, for assembly in chunks: 0 ≤ k < num_triangles() is triangle k's
  // term Σ_ij S A N_i:Φ'':N_j ∇θ_i ∇θ_jᵀ (PSD), num_triangles() ≤ k < num_elements() is
  // hinge h = k - num_triangles()'s term (∂E/∂θ_h) ∇²θ_h. kGaussNewton writes zeros for the
  // latter, kEigen projects each of its 12×12 blocks to PSD. The triplet count and order depend
  // on the mesh only.
  int num_elements() const { return num_triangles() + static_cast<int>(hinges_.size()); }
  void AddHessianTriplets(const Vertices& x, std::vector<Eigen::Triplet<double>>* triplets,
                          HessianProjection projection, int first_element, int end_element) const;
  void AddHessianTriplets(const Vertices& x, std::vector<Eigen::Triplet<double>>* triplets,
                          HessianProjection projection) const {
    AddHessianTriplets(x, triplets, projection, 0, num_elements());
  }
  // The vertices whose coordinates triangle t's element couples (3 to 6 ids).
  const std::vector<int>& patch(int t) const { return patch_[t]; }

  int num_triangles() const { return static_cast<int>(tri_.size()); }
  // K_t [1/m] in the warp/weft frame (symmetric 2×2).
  Eigen::Matrix2d Curvature(const Vertices& x, int t) const;
  // Rest patches whose six points were (nearly) on one conic, so that the quadratic fit was
  // replaced by the mid-edge formula (docs/methods/statics.md); 0 on the structured meshes.
  int num_fallback_patches() const { return num_fallback_; }

 private:
  struct TriangleRest {
    std::array<int, 3> hinge;                   // -1: boundary edge
    std::array<Eigen::Vector3d, 3> n;           // N_i as (K_xx, K_yy, K_xy) per unit θ_i
    double weight;                              // S_t A_t [m²]
  };
  // θ - θ̄ of every hinge.
  void Angles(const Vertices& x, std::vector<double>* dtheta) const;
  // (K_xx, K_yy, K_xy) of triangle t from the hinge angle changes.
  Eigen::Vector3d TensorOf(int t, const std::vector<double>& dtheta) const;
  // Φ(k), ∂Φ/∂k and the diagonal of ∂²Φ/∂k² (energy density per area, [J/m²] etc.).
  double Density(const Eigen::Vector3d& k, Eigen::Vector3d* moment,
                 Eigen::Vector3d* stiffness) const;

  BendingLaw warp_, weft_;
  std::vector<Hinge> hinges_;
  std::vector<double> rest_angle_;
  std::vector<TriangleRest> tri_;
  std::vector<std::vector<int>> patch_;
  int num_fallback_ = 0;
};

}  // namespace textile

#endif  // TEXTILE_SIM_ELEMENTS_TENSOR_BENDING_H_
