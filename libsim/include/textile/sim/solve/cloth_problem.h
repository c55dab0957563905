#ifndef TEXTILE_SIM_SOLVE_CLOTH_PROBLEM_H_
#define TEXTILE_SIM_SOLVE_CLOTH_PROBLEM_H_

// The total potential of a piece of cloth in a static scene (docs/spec/physics.md, "Static
// equilibrium"; Sensitive Couture eq. 1): membrane + bending + gravity + contact penalty + friction
// anchor springs, with fixed (or prescribed) vertices. Solvers (static_solver.h) minimise it.
//
//   textile::TriangleMesh sheet = textile::RegularGridMesh(0.5, 0.5, 30, 30);
//   textile::ClothProblem problem(sheet, material, {}, textile::ClothOptions{});
//   problem.FixVertices({0, 30}, sheet.vertices({0, 30}, Eigen::all));   // two corners
//   problem.AddSupport(textile::Support::Plane({0, 0, -0.3}, {0, 0, 1}));
//   textile::Vertices x = sheet.vertices;                      // start flat
//   textile::SolveSummary s = textile::SolveStatic(&problem, &x, {});
//
// Degrees of freedom are the 3V vertex coordinates (dof 3 i + c); fixed vertices keep the
// positions given to FixVertices (move them with SetFixedPositions for a prescribed motion)
// and their rows of the gradient and Hessian are those of the identity.
//
// Contact (contact.h): node i inside support s (signed distance φ < 0) feels the penalty
// ½ k_i φ² with k_i = m_i g / sink. With friction μ > 0 a node in contact is tied to an anchor
// point a on the support by the tangential spring ½ k_t |P (x_i - a)|² (k_t = tangential_ratio
// × the stretch stiffness), P = I - n nᵀ (n the normal at the anchor): the node sticks. When that
// spring pulls harder than μ f_n (Coulomb) the node slides: the spring is replaced by a constant
// force μ f_n against the slip direction (potential f t̂·x), and when a sliding node stops or is
// pulled back it sticks again where it is. UpdateAnchors makes these switches and creates and
// drops anchors where contact starts and ends. Between two updates the energy is a fixed,
// differentiable function, which is what Newton's line search needs; an active set of sliding
// nodes moves as far as the forces say in one Newton solve (a lagged spring would creep).
// Under ContactOptions::friction_potential (the drape's resting mount) nothing switches: the
// spring becomes a Huber function of |P (x_i - a)|, linear with slope μ f̄_n past the stick
// radius, f̄_n and n lagged (contact.h).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/elements/bending_element.h"
#include "textile/sim/elements/contact.h"
#include "textile/sim/law/material.h"
#include "textile/sim/elements/membrane.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/law/seam.h"
#include "textile/sim/elements/tensor_bending.h"

namespace textile {

struct ClothOptions {
  MembraneModel membrane = MembraneModel::kStVK;  // stabilised StVK (Sensitive Couture)
  BendingOptions bending;                         // Pabst's law by default
  // Hinge energies (bending.model) or Pabst's law on a curvature tensor per triangle
  // (tensor_bending.h: bend and twist separate, the stiffness of a free strip right). The
  // tensor takes warp and weft laws only: ClothProblem refuses it for a material with a
  // measured bias law (bending_bias), which the hinges blend in.
  BendingDiscretization discretization = BendingDiscretization::kHinge;
  Eigen::Vector3d gravity{0.0, 0.0, -9.80665};    // [m/s²]
  ContactOptions contact;                         // used when supports are added
  // Multiplies the material's bending law (the 100× plate of the stability benchmark); > 0.
  double bending_scale = 1.0;

  bool Check(std::string* why) const;
};

class ClothProblem {
 public:
  // @param rest      the pattern: #V×3 rest positions [m] (flat: z = 0), #F×3 triangles;
  //                  must pass CheckMesh (it is called)
  // @param material  areal density, bending law(s), β, stretch stiffness, Poisson ratio;
  //                  the friction coefficient of options.contact is used, not material.friction
  //                  (callers copy it over when they want the material's)
  // @param seams     seam lines on the pattern: bending multipliers S(d) per hinge and the
  //                  seam-band mass (seam.h)
  // Throws InputError for a bad mesh, material, seam or option.
  ClothProblem(const TriangleMesh& rest, const Material& material, const std::vector<Seam>& seams,
               const ClothOptions& options);

  // Holds vertices at positions (#K×3 [m]); replaces any previous set. Ids must be distinct and
  // in range; positions finite.
  void FixVertices(const std::vector<int>& vertices, const Vertices& positions);
  // New positions for the fixed vertices, in FixVertices' order (a prescribed motion).
  void SetFixedPositions(const Vertices& positions);
  void AddSupport(const Support& support);

  // ∇E [N] at x of the parts a material gives (membrane, bending, gravity), for `other` in
  // place of the problem's material on the same pattern, seams and options; zero on fixed
  // vertices. Contact is left out. For design sensitivities (sensitivity.h): the difference of
  // two such gradients over a parameter step is ∂R/∂p, with the contact state frozen.
  // `parts` limits it to those (MaterialPart bits; a part the change does not touch adds nothing
  // to a difference). With `rest`, on that rest mesh in place of the problem's (the same
  // vertices and triangles), and with `seams`, those seams (as many: lines moved with the rest,
  // or profiles stepped) in place of the problem's: a rest-shape or seam sensitivity's
  // difference (the seams' masses come from them too). Throws
  // InputError as the constructor does for `other`, `rest` or `seams`.
  enum MaterialPart { kMembranePart = 1, kBendingPart = 2, kGravityPart = 4, kAllParts = 7 };
  Vertices MaterialGradient(const Vertices& x, const Material& other, int parts = kAllParts,
                            const TriangleMesh* rest = nullptr,
                            const std::vector<Seam>* seams = nullptr) const;

  // Total potential energy [J] at x (#V×3 [m]), with the current anchors.
  double Energy(const Vertices& x) const;
  // Fills grad (#V×3, resized) with ∇E [N], zero on fixed vertices; returns E [J].
  double EnergyGradient(const Vertices& x, Vertices* grad) const;
  // ∇²E [N/m] (3V×3V, fixed sparsity, full symmetric storage) with fixed vertices' rows and
  // columns replaced by identity rows scaled to the free dofs' mean diagonal; their off-diagonal
  // entries are not even stored (FixVertices drops them from the pattern). The reference stays
  // valid until the next call.
  const Eigen::SparseMatrix<double>& Hessian(const Vertices& x, HessianProjection projection);

  // Creates, releases and slides friction anchors for state x (see the file comment); a new
  // anchor goes where the node was in `previous` (the state before the step that brought it into
  // contact), projected onto the support, so a step cannot slide a landing node for free.
  // Returns the largest slip of a sliding node since `previous` [m] (0 when every node sticks).
  // With ContactOptions::lagged_slip no node slides here: touching nodes stick. With
  // ContactOptions::friction_potential anchors never move: a new contact's lagged μ f̄_n and
  // tangent plane are taken from x, older ones follow x where more than 1 % off (relaxed), and
  // the largest gap still over 1 % after that is returned [-] (0: all within), which keeps the
  // solver from declaring convergence (any gap does; SolveOptions::anchor_tolerance, a length,
  // does not apply to it).
  double UpdateAnchors(const Vertices& x, const Vertices& previous);
  // ContactOptions::lagged_slip, between converged stretches of a solve: moves the anchor of
  // every node whose spring pulls more than slip_excess of μ f_n past μ f_n (Coulomb) along the
  // pull, to where it pulls μ f_n, or further, by the sum of the geometric series its
  // successive slips form (Aitken, at most 50 slips ahead). Returns the largest move [m] (0:
  // every node holds). Does nothing under ContactOptions::friction_potential.
  double SlipAnchors(const Vertices& x);
  // Slip between converged stretches is on (ContactOptions::lagged_slip, not overridden by
  // friction_potential).
  bool lagged_slip() const {
    return options_.contact.lagged_slip && !options_.contact.friction_potential &&
           options_.contact.friction > 0.0 && !supports_.empty();
  }
  // Friction as a lagged potential is on (ContactOptions::friction_potential, with friction and
  // a support): UpdateAnchors' return is then how far the lagged normal forces and tangent
  // planes still are off.
  bool friction_potential() const {
    return options_.contact.friction_potential && options_.contact.friction > 0.0 &&
           !supports_.empty();
  }
  void ClearAnchors();
  // After a mesh refinement (RefineTriangles), before solving on it: takes over `coarse`'s
  // friction anchors for the old vertices (ids below coarse's #V); each split point gets the
  // middle of its parents' anchors, put back on the support, when both have one on the same
  // support (else its contact starts afresh). The old vertices' lagged μ f̄_n is rescaled to
  // this mesh's penalty (lumped masses change with the split) and their lag starts afresh; the
  // split points' is set at the next UpdateAnchors. So the finer mesh goes on with the friction
  // history instead of restarting it from where it lies. Throws InputError when the sizes do
  // not fit a refinement of coarse or the supports differ in number.
  void CarryAnchorsFrom(const ClothProblem& coarse, const std::vector<std::array<int, 2>>& parents);
  int num_anchors() const;
  // Incremented whenever an anchor is created, released or moved: the energy changed.
  long anchor_version() const { return anchor_version_; }
  int num_contacts(const Vertices& x) const;  // nodes with φ < 0 against some support

  // The largest α ≤ 1 for which the step x + α d (d: 3V) moves no node deeper than half a
  // support's TunnelDepth past its surface: a step may not jump through a thin support.
  double ContactStepLimit(const Vertices& x, const Eigen::VectorXd& d) const;
  // Sets the fixed vertices of x to their prescribed positions.
  void ApplyFixed(Vertices* x) const;
  // RMS of the force on free vertices over the RMS of their weights m_i |g| [-]: the
  // convergence measure of every solver (docs/spec/physics.md: "relative to the weight").
  double RelativeResidual(const Vertices& grad) const;

  const TriangleMesh& rest() const { return rest_; }
  const Eigen::VectorXd& masses() const { return masses_; }  // #V [kg]
  const std::vector<Support>& supports() const { return supports_; }
  const std::vector<int>& fixed_vertices() const { return fixed_; }
  const std::vector<char>& is_fixed() const { return is_fixed_; }
  const MembraneElements& membrane() const { return membrane_; }
  // The hinge bending when options().discretization is kHinge, else null (not built).
  const BendingElements* hinge_bending() const { return bending_ ? &*bending_ : nullptr; }
  // The curvature-tensor bending when options().discretization is kTensor, else null.
  const TensorBending* tensor_bending() const { return tensor_ ? &*tensor_ : nullptr; }
  const ClothOptions& options() const { return options_; }
  int num_vertices() const { return rest_.num_vertices(); }
  double total_mass() const { return masses_.sum(); }
  // Σ m_i |g| over free vertices [N].
  double FreeWeight() const;

 private:
  struct Anchor {
    int support = -1;  // -1: no anchor
    Eigen::Vector3d point = Eigen::Vector3d::Zero();   // sticking: the anchor; sliding: x then
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    bool sliding = false;
    Eigen::Vector3d slip = Eigen::Vector3d::Zero();  // sliding: unit slip direction
    double friction_force = 0.0;  // sliding, and friction_potential's μ f̄_n: μ f_n [N]
    bool stopped = false;  // it slid and stopped since contact began (hysteresis)
    Eigen::Vector3d last_slip = Eigen::Vector3d::Zero();  // lagged slip: the last unpaired slip [m]
    int lag_updates = 0;  // friction potential: updates of the lagged force and plane so far
  };
  // The deepest support node i touches (φ < limit), or -1; *phi and *normal filled.
  int Touching(const Eigen::Vector3d& p, double limit, double* phi, Eigen::Vector3d* normal) const;
  double ContactEnergyGradient(const Vertices& x, Vertices* grad) const;
  // Friction potential: node i's lagged μ f̄_n and tangent plane towards its depth [m] and
  // normal, where they are more than kLagTolerance off; returns what is still off [-] (0 when
  // within it, or when the node no longer presses).
  double UpdateLaggedFriction(int i, double depth, const Eigen::Vector3d& normal);
  void BuildPattern();
  void DropFixedFromPattern();
  // A material's bending laws (β and bending_scale applied) and elements on this pattern.
  DirectionLaws BendingLaws(const Material& material) const;
  // On `rest` with the hinges' seam multipliers `multipliers` (the problem's by default).
  BendingElements HingeElements(const Material& material, const TriangleMesh& rest,
                                const std::vector<double>& multipliers) const;
  TensorBending TensorElements(const Material& material, const TriangleMesh& rest,
                               const std::vector<double>& multipliers) const;
  // Bending Hessian elements [first, end) of the active discretisation into triplets_.
  int num_bending_elements() const;
  void BendingTriplets(const Vertices& x, HessianProjection projection, int first, int end);

  TriangleMesh rest_;
  ClothOptions options_;
  std::vector<Seam> seams_;
  Eigen::VectorXd masses_;
  MembraneElements membrane_;
  std::vector<Hinge> hinges_;
  std::vector<double> multipliers_;         // per hinge S(d) of the seams; empty: none
  std::optional<BendingElements> bending_;  // kHinge only
  std::optional<TensorBending> tensor_;     // kTensor only
  std::vector<Support> supports_;
  std::vector<int> fixed_;
  std::vector<char> is_fixed_;
  Vertices fixed_positions_;
  std::vector<Anchor> anchors_;  // #V
  long anchor_version_ = 0;
  Eigen::VectorXd penalty_;      // #V normal spring k_i [N/m]
  double tangential_stiffness_ = 0.0;  // anchor spring k_t [N/m]

  // Hessian with a fixed pattern: element triplets land in value slots found once.
  Eigen::SparseMatrix<double> hessian_;
  std::vector<Eigen::Triplet<double>> triplets_;
  std::vector<int> triplet_slot_;
  // Hinge bending: the elements' own fixed-pattern fill (BendingElements::SetHessian, 3×3
  // vertex-pair blocks, 8 hinges a SIMD block) into their upper-half pattern, whose values then
  // go to their slots here: one pass over its nonzeros instead of 144 scattered additions a
  // hinge.
  Eigen::SparseMatrix<double> bending_hessian_;
  BendingHessianSlots bending_slots_;
  // Per nonzero k of bending_hessian_ (upper half): slots 2k (its place in hessian_) and 2k + 1
  // (its mirror's; -1 on the diagonal).
  std::vector<int> bending_value_slot_;
  std::vector<int> diagonal_block_slot_;  // #V×9: slot of (3i+a, 3i+b)
  std::vector<int> fixed_diagonal_slots_;  // the fixed dofs' diagonals
  bool pattern_reduced_ = false;           // fixed dofs' off-diagonal entries dropped
};

}  // namespace textile

#endif  // TEXTILE_SIM_SOLVE_CLOTH_PROBLEM_H_
