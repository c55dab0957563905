#ifndef TEXTILE_SIM_SOLVE_STATIC_SOLVER_H_
#define TEXTILE_SIM_SOLVE_STATIC_SOLVER_H_

// Static equilibrium of a ClothProblem (docs/spec/physics.md, "Static equilibrium"; Sensitive
// Couture sections 5 and 7): minimise the total potential.
//
//   textile::SolveOptions options;                       // Newton + CHOLMOD, tolerance 1e-6
//   textile::SolveSummary s = textile::SolveStatic(&problem, &x, options);
//   if (!s.converged) throw textile::ComputeError(s.message);   // never report such an x
//   std::cout << s.BriefReport() << "\n";
//
// Methods:
// - Newton: H d = -∇E with H the Hessian made positive semi-definite (membrane: stabilised
//   StVK; bending: Gauss-Newton or eigen-projected blocks; contact: n nᵀ springs), solved by
//   sparse Cholesky (CHOLMOD; a diagonal shift is added when the matrix is singular, as on a flat
//   sheet with no out-of-plane stiffness) or by conjugate gradients with an incomplete Cholesky
//   preconditioner; a step cap and an Armijo backtracking line search on E.
// - Kinetic damping (Barnes 1988; Sensitive Couture section 7): the undamped equations of
//   motion integrated with the semi-implicit (linearised backward Euler) step of Baraff and
//   Witkin 1998, (M + h² H) Δv = h (f - h H v); when the kinetic energy passes a peak the
//   velocities are zeroed.
// Both declare convergence when the RMS force on free vertices falls below `tolerance` times
// the RMS vertex weight (ClothProblem::RelativeResidual) and no friction anchor slid in the
// last step. A run that stops for another reason (iteration or time cap, NaN, a failed line
// search, the cloth falling with nothing to hold it) returns converged = false and says why; its
// state must not be reported as a result.
// - Cascadic (progressive coarse → fine, section 7.1): SolveCascadic solves a coarse problem,
//   prolongs the solution to the fine mesh by barycentric interpolation in the pattern plane,
//   and finishes there.

#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "textile/sim/solve/cloth_problem.h"

namespace textile {

enum class SolverMethod { kNewton, kKineticDamping };
enum class LinearSolverKind { kCholmod, kConjugateGradient };

std::string SolverMethodName(SolverMethod method);
SolverMethod ParseSolverMethod(const std::string& name);  // "newton" | "kinetic"; InputError

struct SolveOptions {
  SolverMethod method = SolverMethod::kNewton;
  LinearSolverKind linear = LinearSolverKind::kCholmod;
  HessianProjection projection = HessianProjection::kGaussNewton;
  // Newton with CHOLMOD: below this relative residual a step first tries the exact
  // (unprojected) Hessian and takes it when its Cholesky factorisation succeeds (positive
  // definite, so the step heads for a minimum, never a saddle), else the projected one; after a
  // failed try the next waits 1, 2, 4 ... 16 steps. The projected Hessian alone converges only
  // linearly where folds compress the membrane and bend the hinges (a drape's last 100 steps
  // cut the residual by ×0.94 each); with the exact one near the end the drapes took 1.3-11×
  // fewer steps to the same equilibria (docs/methods/drapemeter.md, "Solver"). ≥ 0; 0: never, ∞:
  // from the start.
  double exact_below = 1.0;
  // Newton: when a full projected step lowers the energy, try it doubled, quadrupled ...
  // (within max_step and the contact step limit) while the energy keeps falling. Where folds
  // form, the projected Hessian is far stiffer than the energy along the folds' way: a drape's
  // steps moved no vertex more than 10-100 µm for a hundred iterations, and doubling them
  // halved the steps to the same equilibria (docs/methods/drapemeter.md, "Solver"). Off by default: such long steps can cross
  // into another basin, and did on the ACPM shell's strip (an overhang 0.39 of the true one).
  bool expand_steps = false;
  double tolerance = 1e-6;       // on the relative residual [-]
  int max_iterations = 1000;     // Newton steps or kinetic-damping time steps
  double max_seconds = 60.0;     // wall-time cap [s], finite, ≥ 0 (0: stop at the first check)
  // Largest vertex displacement of one Newton step [m]; 0: 10 % of the pattern's diagonal.
  double max_step = 0.0;
  // Kinetic damping's time step [s]. The implicit step is stable for any h; larger steps
  // approach Newton's.
  double time_step = 0.02;
  // Conjugate gradients: relative tolerance of each linear solve and its iteration cap.
  double cg_tolerance = 1e-4;
  int cg_max_iterations = 2000;
  // Anchors that slide less than this in a step count as sticking [m]. Not used under lagged
  // slip or the friction potential (ContactOptions), where any slip or lag gap left counts.
  double anchor_tolerance = 1e-7;
  // The run stops ("falls") when the centre of mass sinks more than this many pattern
  // diagonals below where it started: nothing holds the cloth.
  double fall_limit = 20.0;
  // Print one line per iteration on stderr.
  bool verbose = false;

  bool Check(std::string* why) const;
};

struct SolveSummary {
  bool converged = false;
  std::string method;          // "newton", "kinetic", "cascadic"
  std::string message;         // why it stopped, one line
  int iterations = 0;          // steps taken (fine level for cascadic)
  int linear_iterations = 0;   // CG iterations in total (0 with CHOLMOD)
  int factorizations = 0;      // Cholesky factorisations (incl. shifted retries)
  int exact_steps = 0;         // Newton steps taken with the exact Hessian (exact_below)
  int slips = 0;               // friction updates that moved anchors (ContactOptions::lagged_slip)
  double residual = 0.0;       // final relative residual [-]
  double energy = 0.0;         // final total potential [J]
  double seconds = 0.0;        // wall time [s]
  int contacts = 0;            // nodes touching a support at the end
  int anchors = 0;             // friction anchors at the end
  // Cascadic only: the coarse level's figures.
  int coarse_iterations = 0;
  double coarse_seconds = 0.0;

  std::string BriefReport() const;
};

// Solves from *x (#V×3 [m], the start; fixed vertices are set first) and leaves the last state
// in *x. Throws InputError for bad options or a wrongly sized x; everything else is reported in
// the summary.
SolveSummary SolveStatic(ClothProblem* problem, Vertices* x, const SolveOptions& options);

// #V_fine × #V_coarse matrix P with x_fine = P x_coarse: each fine rest vertex written in
// barycentric coordinates of the coarse rest triangle that contains it (in the x-y plane of flat
// patterns) or, off the coarse mesh (a polygonal disk's rim), of the nearest one with its
// coordinates clamped to the triangle. Throws InputError if either mesh is empty.
Eigen::SparseMatrix<double> BarycentricProlongation(const TriangleMesh& coarse_rest,
                                                    const TriangleMesh& fine_rest);

// Solves *coarse from *x_coarse, then *fine from the prolonged state; *x_fine receives it.
// Options apply to both levels (the coarse one with 10× the tolerance: it only has to be a good
// start). The summary is the fine level's, with the coarse figures added.
SolveSummary SolveCascadic(ClothProblem* coarse, ClothProblem* fine, Vertices* x_coarse,
                           Vertices* x_fine, const SolveOptions& options);

// The same over any number of levels, coarsest first (at least 2): each level starts from the
// prolonged solution of the one before; all but the finest are solved to 10× the tolerance.
// *x: the coarsest level's start on entry, the finest level's solution on exit. The summary is
// the finest level's; coarse_iterations and coarse_seconds add up the coarser levels.
SolveSummary SolveCascadic(const std::vector<ClothProblem*>& levels, Vertices* x,
                           const SolveOptions& options);

}  // namespace textile

#endif  // TEXTILE_SIM_SOLVE_STATIC_SOLVER_H_
