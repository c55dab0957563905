#ifndef TEXTILE_SIM_ELEMENTS_BENDING_ELEMENT_H_
#define TEXTILE_SIM_ELEMENTS_BENDING_ELEMENT_H_

// Discrete bending on triangle hinges: four models behind one interface, each with energy,
// gradient and a consistent Hessian (docs/methods/bending.md derives them).
//
//   textile::TriangleMesh rest = textile::CrissCrossGridMesh(0.5, 0.5, 30, 30);
//   std::vector<textile::Hinge> hinges = textile::BuildHinges(rest);
//   textile::Material fabric = textile::ReadMaterial("samples/materials/pabst-fig8.json");
//   textile::BendingElements bending(rest, hinges, fabric, {.model =
//   textile::BendingModel::kPabst}); textile::Vertices grad =
//   textile::Vertices::Zero(rest.num_vertices(), 3); double energy = bending.EnergyGradient(x,
//   grad);   // J and J/m; forces are -grad std::vector<Eigen::Triplet<double>> triplets;
//   bending.AddHessianTriplets(x, &triplets, /*project_psd=*/true);  // 3V×3V, for Newton
//
//   // Newton steps on a fixed sparsity pattern: no triplets, no sorting, no allocation a call.
//   Eigen::SparseMatrix<double> hessian = bending.HessianPattern(/*upper=*/true);
//   const textile::BendingHessianSlots slots = bending.HessianSlots(hessian, /*upper=*/true);
//   bending.SetHessian(x, textile::HessianProjection::kNone, slots, &hessian);
//   // hessian.selfadjointView<Eigen::Upper>() is ∇²E
//
// Hinge h has wings v[0], v[1] and edge (v[2], v[3]) (mesh.h). Its bend angle θ is the signed
// angle between the two triangle normals, 0 when flat, positive when the hinge bends towards
// the side its normals point to (e.g. a flat pattern laid on a cylinder below it).
//
//   kPabst      Pabst et al. 2008: κ = (θ - θ̄)/h̄e (eq. 2), E = S A_h Ψ(κ) with the law's
//               strain energy Ψ (Ψ' = M), A_h = |ē| h̄e = the two rest triangles' area.
//               -∇E has the direction of eqs. 3-5 and twice the magnitude of eq. 3
//               (eq. 3's ½ corresponds to A_h/2; docs/methods/bending.md, "Area weight").
//   kBridson    Bridson et al. 2003: force ∝ sin(θ/2) - sin(θ̄/2) along the same modes,
//               weights |ē|²/(|N̄0| + |N̄1|) frozen at rest so that a potential exists;
//               stiffness k_e = 4 b1 (S and warp/weft blending as for Pabst).
//   kVolino     Volino & Magnenat-Thalmann 2006: linear bending vector R = Σ α_i x_i (the
//               wing line's crossing with the edge), E = ½ S k_h |R - R̄|², constant Hessian.
//   kIsometric  Bergou et al. 2006 (Sensitive Couture's IBM): E = ½ Σ S k 3/(Ā0+Ā1) |Σ w_i
//               (x_i - x̄_i)|² with cotangent weights w, constant Hessian; k = b1/3.
//
// The Bridson, Volino and isometric stiffnesses come from the law's initial stiffness b1 so
// that, for a flat rest state and small bends, every model gives the Pabst energy
// A_h b1 κ²/2 on every hinge. The two linear models are not rotation invariant when the rest
// state is curved (R̄ ≠ 0); the Pabst and Bridson models are.
//
// Units: positions [m], energy [J], gradient [J/m = N], Hessian [N/m].

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/law/material.h"
#include "textile/sim/mesh/mesh.h"

namespace textile {

enum class BendingModel { kPabst, kBridson, kVolino, kIsometric };

// How a hinge's Hessian block is made positive semi-definite for Newton-type solvers.
enum class HessianProjection {
  kNone,         // the exact Hessian E''(θ) ∇θ ∇θᵀ + E'(θ) ∇²θ (indefinite in general)
  kEigen,        // the exact block with its negative eigenvalues set to 0 (12×12 eigen-solve)
  kGaussNewton,  // max(E'', 0) ∇θ ∇θᵀ: drops the E' ∇²θ term; PSD, ~20× cheaper than kEigen,
                 // exact at rest and wherever E' = 0 (Newton then converges linearly, not
                 // quadratically, in strongly bent states)
};

// "pabst", "bridson", "volino", "isometric".
std::string BendingModelName(BendingModel model);
// Inverse of BendingModelName; throws InputError listing the known names.
BendingModel ParseBendingModel(const std::string& name);

struct BendingOptions {
  BendingModel model = BendingModel::kPabst;  // which energy (see above)
  // Worker threads for the hinge loops: 1 = serial (the default, and what solvers that
  // thread elsewhere want), 0 = all hardware threads; at most 64 are used. Results do not depend on
  // it beyond round-off in the energy sum.
  int threads = 1;

  // False with a reason when a field is out of range.
  bool Check(std::string* why) const;
};

// Signed bend angle θ ∈ (-π, π] of the hinge (x0, x1 wings; x2→x3 the edge) [rad]; 0 when the
// two triangles (x0, x2, x3) and (x1, x3, x2) are coplanar, positive when they fold towards
// their normals.
double HingeBendAngle(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                      const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);

// Where every hinge's Hessian entries live in the value array of one compressed column-major
// sparse matrix (BendingElements::HessianSlots), so that a call adds them by position.
struct BendingHessianSlots {
  bool upper = false;    // only entries with row ≤ col are stored (a symmetric matrix's upper half)
  int per_hinge = 0;     // entries per hinge: 78 (upper) or 144
  long nonzeros = 0;     // nonZeros() of the matrix the slots were made for
  std::vector<int> slot;  // #H × per_hinge positions in valuePtr(), hinge-major
  // For threaded filling, per value position p: sources[source_offsets[p] .. source_offsets[p+1])
  // are the contributions (78 h + packed entry) in hinge order, the serial order of additions.
  std::vector<int> source_offsets, sources;
  // Serial filling goes through 3×3 blocks, one per vertex pair va ≤ vb of some hinge (entry
  // (3 va + a, 3 vb + b) is number 3 a + b: 0-7 at 8 k in one cache line, 8 in a second array),
  // so that a hinge adds 10 short contiguous vectors and 10 scalars.
  // block_slot: #H × 10, hinge-major, for the vertex pairs (i, j), i ≤ j, of the hinge in the
  // order (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3): 2 × block + 1 if
  // v[i] > v[j] (the block is then the transpose of the hinge's (i, j) block).
  std::vector<int> block_slot;
  // The block entries then go to the matrix: values[value_position[k]] += block entry
  // value_source[k] (8 × block + 3 a + b, or 8 × #blocks + block for entry 8), value_position
  // ascending.
  std::vector<int> value_position, value_source;
  bool covers_all = false;  // value_position is 0, 1, ..., nonzeros - 1
  // Scratch (9 a block and 8 to align them): one fill at a time per slots.
  mutable std::vector<double> block_values;
};

class BendingElements {
 public:
  // @param rest        rest mesh: #V×3 rest positions [m] (flat patterns: z = 0; a curved
  //                    rest state is allowed), #F×3 triangles. CheckMesh is the caller's job.
  // @param hinges      the bending elements, usually BuildHinges(rest) (#H)
  // @param warp, weft  moment-curvature laws [SI], β already applied: the warp law bends a
  //                    strip cut along the warp (the pattern's x axis), curvature along x. A
  //                    hinge bends across its rest edge: one whose edge makes angle ψ with the
  //                    weft (y) uses BlendedLaw(warp, weft, ψ), an edge along y the warp law.
  //                    Pass weft = nullopt for an isotropic fabric.
  // @param stiffness_multiplier  per-hinge factor S (seam factor of eq. 6), #H values > 0,
  //                    or empty for S = 1 everywhere
  // Throws InputError naming the hinge: bad options, multiplier count or value, vertex ids
  // out of range, non-finite or degenerate rest triangles.
  BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                  const BendingLaw& warp, const std::optional<BendingLaw>& weft,
                  const BendingOptions& options = {},
                  const std::vector<double>& stiffness_multiplier = {});
  // The same with a measured bias law (a strip cut at 45°; nullopt: none): a hinge then blends
  // the laws with DirectionWeights (bending_law.h), linear in cos 2ψ between the two measured
  // directions its bending lies between.
  BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                  const DirectionLaws& laws, const BendingOptions& options = {},
                  const std::vector<double>& stiffness_multiplier = {});
  // The material's effective (β-scaled) warp, weft and bias laws.
  BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                  const Material& material, const BendingOptions& options = {},
                  const std::vector<double>& stiffness_multiplier = {});

  // Total bending energy [J] at positions x (#V×3 [m]).
  double Energy(const Vertices& x) const;
  // grad += ∇E [N] (#V×3); forces are -∇E.
  void AddGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const;
  // Both in one pass: grad += ∇E, returns E.
  double EnergyGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const;
  // Appends the Hessian ∇²E [N/m] as triplets (row, col) of the 3V×3V matrix, dof 3·i + c for
  // coordinate c of vertex i: 144 per hinge (a 12×12 block) for Pabst and Bridson, 48 for the
  // linear models (their blocks are multiples of the 3×3 identity). Duplicates add up
  // (Eigen's setFromTriplets). With project_psd each hinge block has its negative
  // eigenvalues set to 0 (Newton needs a positive semi-definite matrix; the linear models are
  // PSD already).
  void AddHessianTriplets(const Vertices& x, std::vector<Eigen::Triplet<double>>* triplets,
                          bool project_psd) const {
    AddHessianTriplets(x, triplets,
                       project_psd ? HessianProjection::kEigen : HessianProjection::kNone);
  }
  // The same with a choice of projection; the triplet count and order never depend on it or on x
  // (so a fixed sparsity pattern can be filled by position).
  void AddHessianTriplets(const Vertices& x, std::vector<Eigen::Triplet<double>>* triplets,
                          HessianProjection projection) const;
  // Only hinges first_hinge ≤ h < end_hinge, in order (assembly in chunks keeps the triplet
  // buffer small on large meshes).
  void AddHessianTriplets(const Vertices& x, std::vector<Eigen::Triplet<double>>* triplets,
                          HessianProjection projection, int first_hinge, int end_hinge) const;

  // Fixed-pattern Hessian (for Newton solvers that refill one matrix every step).
  // The 3V×3V pattern of the bending Hessian (dof 3·i + c): every pair of vertices of a hinge a
  // dense 3×3 block, all values 0, compressed. upper: only entries with row ≤ col.
  Eigen::SparseMatrix<double> HessianPattern(bool upper) const;
  // Positions of every hinge's entries in `pattern` (3V×3V, compressed; any pattern that holds
  // all of HessianPattern(upper)'s entries, e.g. one shared with other elements). Throws
  // InputError if the size is wrong, the matrix is not compressed or an entry is missing.
  BendingHessianSlots HessianSlots(const Eigen::SparseMatrix<double>& pattern, bool upper) const;
  // values[p] += ∇²E [N/m] at the positions of `slots` (values = valuePtr() of the matrix the
  // slots were made for): the same numbers as AddHessianTriplets to round-off, upper-half
  // entries when slots.upper. Each hinge block is symmetrised (its exact value is symmetric; the
  // triplet path's is to ~1e-12). No allocation unless threaded (a scratch buffer, reused).
  // Each value gets the sum of its hinges' entries in hinge order, threaded or not (the same
  // bits); calls with the same slots must not run concurrently (they share a scratch buffer).
  void AddHessianValues(const Vertices& x, HessianProjection projection,
                        const BendingHessianSlots& slots, double* values) const;
  // hessian = ∇²E: zeroes the values of `hessian` (the matrix `slots` was made for), then adds.
  void SetHessian(const Vertices& x, HessianProjection projection,
                  const BendingHessianSlots& slots, Eigen::SparseMatrix<double>* hessian) const;

  // Per-hinge views, for tests, plots and seams.
  int num_hinges() const { return static_cast<int>(rest_.size()); }
  const Hinge& hinge(int h) const { return hinges_[h]; }
  BendingModel model() const { return options_.model; }
  double rest_dihedral(int h) const { return rest_[h].rest_angle; }                  // θ̄ [rad]
  double rest_height(int h) const { return 1.0 / rest_[h].inv_height; }              // h̄e [m]
  double rest_edge_length(int h) const { return edge_length_[h]; }                   // |ē| [m]
  double area_weight(int h) const { return edge_length_[h] / rest_[h].inv_height; }  // A_h [m²]
  double stiffness_multiplier(int h) const { return multiplier_[h]; }                // S
  double warp_weight(int h) const { return rest_[h].warp_weight; }  // w_warp (cos²ψ without bias)
  double bias_weight(int h) const { return rest_[h].bias_weight; }  // w_bias (0 without bias)
  // Bend angle θ [rad], hinge curvature κ = (θ - θ̄)/h̄e [1/m] and energy [J] of hinge h.
  double BendAngle(const Vertices& x, int h) const;
  double HingeCurvature(const Vertices& x, int h) const;
  double HingeEnergy(const Vertices& x, int h) const;

 private:
  // Hot per-hinge rest data, one contiguous array (56 bytes a hinge).
  struct HingeRest {
    std::array<int, 4> v;
    double rest_angle;   // θ̄ [rad]
    double inv_height;   // 1/h̄e [1/m]
    double weight;       // Pabst: S A_h [m²]; Bridson: S k_h [J]; linear: S k_h [N/m]
    double warp_weight;  // DirectionWeights(cos²ψ).warp; the weft's is 1 - warp - bias
    double bias_weight;  // DirectionWeights(cos²ψ).bias
  };
  // Linear models: R = Σ alpha[i] x_v[i], rest value R̄.
  struct LinearRest {
    std::array<double, 4> alpha;
    Eigen::Vector3d rest_vector;
  };

  // Dihedral models, structure of arrays padded to a multiple of the SIMD block (hot loop).
  struct DihedralRest {
    std::vector<double> rest_angle, inv_height, weight, warp_weight, bias_weight, sin_half,
        cos_half;
    std::array<std::vector<int>, 4> corner;  // 3 v[i]: offset of corner i's position in x
  };

  static constexpr int kMaxThreads = 64;
  template <bool kWithEnergy, bool kWithGradient>
  double Evaluate(const Vertices& x, double* grad) const;
  // Dihedral hinge h's 12×12 Hessian block (rows/columns 3k..3k+2: vertex v[k]), projected.
  void DihedralHessianBlock(const Vertices& x, int h, HessianProjection projection,
                            Eigen::Matrix<double, 12, 12>* block) const;
  // Hinge h's Hessian block, packed upper triangle of the 12×12 block (78 values) into u.
  void HingeHessianUpper(const Vertices& x, int h, HessianProjection projection, double* u) const;
  // The same for hinges first ≤ h < first + count (count ≤ kSimdLanes), lane-minor:
  // u[kSimdLanes k + l] is entry k of hinge first + l (the SIMD kernel for the dihedral models).
  static constexpr int kSimdLanes = 8;
  void HessianBlocks(const Vertices& x, HessianProjection projection, long first, int count,
                     double* u) const;
  // AddHessianValues; overwrite: values = ∇²E instead (SetHessian).
  void FillHessianValues(const Vertices& x, HessianProjection projection,
                         const BendingHessianSlots& slots, bool overwrite, double* values) const;
  double HingeTerms(const Vertices& x, int h, double* d_energy, double* d2_energy) const;
  double DihedralTerms(double cos_term, double sin_term, int h, double* d_energy, double* d2_energy,
                       bool want_energy) const;
  template <class F>
  double HingeLaw(const HingeRest& r, F&& f) const;
  double LawEnergy(const HingeRest& r, double kappa) const;
  double LawMoment(const HingeRest& r, double kappa) const;
  double LawStiffness(const HingeRest& r, double kappa) const;
  int NumThreads() const;

  BendingOptions options_;
  BendingLaw warp_, weft_, bias_;  // bias_ is warp_ when the fabric has no bias law
  bool anisotropic_ = false;        // a weft or a bias law: the hinges blend by direction
  bool has_bias_ = false;
  // The Pabst model with a spline law: hinge by hinge through BendingLaw (the SIMD kernels
  // inline the three-constant law).
  bool hinge_by_hinge_ = false;
  int num_vertices_ = 0;
  std::vector<Hinge> hinges_;
  std::vector<HingeRest> rest_;
  std::vector<double> edge_length_, multiplier_;
  std::vector<double> half_angle_;  // Bridson: {sin θ̄/2, cos θ̄/2} per hinge
  std::vector<LinearRest> linear_;  // Volino and isometric only
  DihedralRest dihedral_;           // Pabst and Bridson only
  // Threaded gradient: per-hinge 12-vectors gathered per vertex (CSR of (hinge, slot)).
  std::vector<int> vertex_offsets_, vertex_slots_;
  mutable std::vector<double> hinge_gradient_;  // scratch: not for concurrent threaded calls
  mutable std::vector<double> hinge_hessian_;   // scratch of threaded AddHessianValues (78 a hinge)
};

}  // namespace textile

#endif  // TEXTILE_SIM_ELEMENTS_BENDING_ELEMENT_H_
