#ifndef TEXTILE_SIM_ELEMENTS_CONTACT_H_
#define TEXTILE_SIM_ELEMENTS_CONTACT_H_

// Supports the cloth rests on: analytic signed-distance shapes (docs/spec/physics.md, "Contact"),
// with penalty springs on the nodes and Coulomb friction by moving anchor springs (Sensitive
// Couture section 7, after Hasegawa et al. 2003). No self-contact in this version.
//
//   textile::Support table = textile::Support::Disk({0, 0, 0}, 0.09, 0.005, 0.001);
//   Eigen::Vector3d n;
//   double d = table.SignedDistance({0.05, 0.0, 0.002}, &n);   // 0.002 m above, n = +z
//
// Distances are in metres, positive outside the solid; the gradient is the unit outward normal.

#include <Eigen/Core>
#include <string>

namespace textile {

struct Support {
  enum class Kind {
    kPlane,  // the half-space below a plane through `center` with outward normal `normal`
    kBox,    // axis-aligned box, centre `center`, half extents `half_extents`, edges rounded by
             // `rounding`
    kDisk,   // the drapemeter's support: a horizontal cylinder of `radius` and `thickness`
             // whose top face has its centre at `center`; rim rounded by `rounding`
  };
  Kind kind = Kind::kPlane;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        // [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();       // plane only, unit
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  // box only [m]
  double radius = 0.0;                                     // disk only [m]
  double thickness = 0.0;                                  // disk only [m]
  double rounding = 0.0;                                   // box edges, disk rim [m]

  // Throw InputError for non-finite or non-positive sizes, a zero normal, or a rounding larger
  // than the shape allows (half the smallest box extent, half the disk thickness or its radius).
  static Support Plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal);
  static Support Box(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents,
                     double rounding);
  static Support Disk(const Eigen::Vector3d& top_center, double radius, double thickness,
                      double rounding);

  // Signed distance from p [m] (negative inside); *normal (if not null) gets its gradient, the
  // outward unit normal of the nearest surface point.
  double SignedDistance(const Eigen::Vector3d& p, Eigen::Vector3d* normal) const;

  // How deep a node can go in before the nearest surface is the far side [m]: a step longer
  // than this could tunnel through (infinite for a plane).
  double TunnelDepth() const;

  std::string Describe() const;  // "plane", "box 0.2×0.1×0.05 m", ..., for reports
};

struct ContactOptions {
  // Penalty stiffness as the sinking of a node under its own weight [m]: the normal spring of
  // node i is k_i = m_i g / sink_under_own_weight. Scaling with the node's mass keeps the
  // stiffness ratio to gravity the same on every mesh.
  double sink_under_own_weight = 1e-5;
  // Coulomb coefficient μ between cloth and supports; 0 = frictionless.
  double friction = 0.3;
  // Tangential (anchor) spring stiffness relative to the membrane's stretch stiffness [-]:
  // k_t = ratio × k_stretch [N/m] per node. Much stiffer than the cloth around the node, so that
  // sticking nodes barely move and the lagged anchor updates of sliding nodes converge fast
  // (each update leaves a fraction ~ k_stretch / (k_t + k_stretch) of the slip to the next).
  double tangential_ratio = 10.0;
  // Nodes within this distance outside a support keep their anchors (hysteresis, so a node
  // resting on a support does not lose its anchor by round-off) [m].
  double anchor_keep_distance = 1e-6;
  // Friction by stick, then slip between converged stretches of a solve, instead of switching
  // nodes between sticking and sliding at every step. Within a stretch every node in contact
  // sticks to its anchor. Once the residual is below the tolerance, ClothProblem::SlipAnchors
  // moves the anchors of the nodes pulled past μ f_n (return mapping) and the solve goes on,
  // until every node holds (slip_excess). The energy is fixed within each stretch, so Newton
  // does not cycle on nodes at the limit (the drape's resting mount until friction_potential
  // replaced it). Newton only: the kinetic solver keeps every node in contact sticking under
  // this option.
  bool lagged_slip = false;
  // Lagged slip: a node sticks while its spring pulls at most this fraction of μ f_n past μ f_n
  // (plus 1e-4 of its weight, for nodes with next to no normal force) [-]; 1 % is well inside
  // what μ is known to.
  double slip_excess = 0.01;
  // Friction as a potential (the drape's resting mount): each touching node is tied to the
  // point where its contact began by a Huber function of its tangential offset s, ½ k_t s² up
  // to s = μ f̄_n / k_t and μ f̄_n (s − μ f̄_n / 2 k_t) beyond, so the force it feels is the
  // stiff anchor spring while it sticks and a constant μ f̄_n back towards its start once it
  // slides, never more. f̄_n and the tangent plane are lagged (as in Li et al. 2020,
  // "Incremental Potential Contact"): taken from the state when the contact begins and after a
  // Newton step only where they are more than 1 % off (relaxed; cloth_problem.cc), so within a
  // step the friction term is one fixed convex function and the solve needs no slip moves. At
  // convergence |f_t| ≤ 1.01 μ f_n, in a plane within 0.01 of the tangent one. The slip is
  // measured from where the contact began, which is the drape's monotone loading. Overrides
  // lagged_slip.
  bool friction_potential = false;

  bool Check(std::string* why) const;
};

}  // namespace textile

#endif  // TEXTILE_SIM_ELEMENTS_CONTACT_H_
