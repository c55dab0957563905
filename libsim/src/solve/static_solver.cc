#include "textile/sim/solve/static_solver.h"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include "serial_openmp.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

using Clock = std::chrono::steady_clock;
using SparseMatrix = Eigen::SparseMatrix<double>;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The state as one vector; Vertices is row-major, so entry 3 i + c is coordinate c of vertex i.
Eigen::Map<Eigen::VectorXd> Flat(Vertices& x) { return {x.data(), x.size()}; }

double PatternDiagonal(const TriangleMesh& rest) {
  const Eigen::Vector3d lo = rest.vertices.colwise().minCoeff();
  const Eigen::Vector3d hi = rest.vertices.colwise().maxCoeff();
  return (hi - lo).norm();
}

double CentreHeight(const ClothProblem& p, const Vertices& x, const Eigen::Vector3d& down) {
  return -(p.masses().transpose() * (x * down)).value() / p.total_mass();
}

// Solves A d = b with CHOLMOD (shifting the diagonal when A is singular) or with conjugate
// gradients. The sparsity of A is the same on every call, so CHOLMOD analyses it once.
// CHOLMOD reads A's upper triangle: its supernodal factorisation permutes an upper-stored
// matrix with one transpose and a lower-stored one with two (cholmod_factorize.c): the
// transposes took 5.5 % of a default drape's samples with two, 3.8 % with one.
class LinearSolver {
 public:
  explicit LinearSolver(const SolveOptions& options) {
    if (options.linear == LinearSolverKind::kCholmod) {
      cholmod_ = std::make_unique<Eigen::CholmodDecomposition<SparseMatrix, Eigen::Upper>>();
      cholmod_->cholmod().print = 0;  // failures are handled here, not printed by CHOLMOD
    } else {
      cg_ = std::make_unique<
          Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                                   Eigen::IncompleteCholesky<double>>>();
      cg_->setTolerance(options.cg_tolerance);
      cg_->setMaxIterations(options.cg_max_iterations);
    }
  }

  // One factorisation of `a` as it is (no shift): false when it is not positive definite.
  bool SolveUnshifted(const SparseMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd* d,
                      SolveSummary* summary) {
    return Factorize(a, b, d, summary);
  }

  // False when no usable direction came out (the caller falls back to steepest descent).
  bool Solve(const SparseMatrix& a, const Eigen::VectorXd& b, Eigen::VectorXd* d,
             SolveSummary* summary) {
    // Singular or indefinite matrices (a flat sheet has no out-of-plane stiffness) get λ I
    // added, λ growing ×100 from 1e-10 to 1e-2 of the mean diagonal. The last shift that
    // worked is where the next solve starts (÷100), so a run of singular steps does not pay
    // for the failed factorisations every time.
    const double mean_diag = std::max(a.diagonal().cwiseAbs().mean(), 1e-300);
    double lambda = shift_ > 1e-10 ? shift_ / 100.0 : 0.0;
    for (; lambda <= 1e-2; lambda = lambda > 0.0 ? lambda * 100.0 : 1e-10) {
      const SparseMatrix* m = &a;
      if (lambda > 0.0) {
        shifted_ = a;
        for (int i = 0; i < shifted_.cols(); ++i) shifted_.coeffRef(i, i) += lambda * mean_diag;
        m = &shifted_;
      }
      if (Factorize(*m, b, d, summary)) {
        shift_ = lambda;
        return true;
      }
    }
    shift_ = 0.0;
    return false;
  }

 private:
  bool Factorize(const SparseMatrix& m, const Eigen::VectorXd& b, Eigen::VectorXd* d,
                 SolveSummary* summary) {
    if (cg_) {
      cg_->compute(m);
      if (cg_->info() != Eigen::Success) return false;
      *d = cg_->solve(b);
      summary->linear_iterations += static_cast<int>(cg_->iterations());
    } else {
      const SerialOpenMp serial;
      if (!analysed_) {  // every matrix here has the same pattern (shifts stay on the diagonal)
        cholmod_->analyzePattern(m);
        analysed_ = true;
      }
      cholmod_->factorize(m);
      ++summary->factorizations;
      if (cholmod_->info() != Eigen::Success) return false;
      *d = cholmod_->solve(b);
    }
    return d->allFinite();
  }

  std::unique_ptr<Eigen::CholmodDecomposition<SparseMatrix, Eigen::Upper>> cholmod_;
  std::unique_ptr<Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                                           Eigen::IncompleteCholesky<double>>>
      cg_;
  bool analysed_ = false;
  double shift_ = 0.0;      // the last diagonal shift that worked (relative)
  SparseMatrix shifted_;    // scratch for a shifted copy
};

std::string Sci(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

// The smallest relative residual (ClothProblem::RelativeResidual) that double precision can
// show at x: each coordinate is known to ε |x|max, so each force component only to about
// ε |x|max H_ii, its own stiffness times that (a bound: the errors partly cancel, and the
// stalls seen lay 200× below it). Stiff, light strips put this above the usual
// tolerances: a technical fabric (b1 ~ 8000 gf·cm at 1387 g/m², 1 mm elements, 250 mm out)
// stalled at residuals of 1.0-1.6e-6 for 400 steps against a tolerance of 1e-7; apparel
// fabrics and drapes stay two decades or more below their tolerance.
double RoundOffFloor(const ClothProblem& p, const Vertices& x, const SparseMatrix& h) {
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  const double extent = x.cwiseAbs().maxCoeff();
  const Eigen::VectorXd diag = h.diagonal();
  Vertices force(x.rows(), 3);
  for (int i = 0; i < x.rows(); ++i)
    for (int k = 0; k < 3; ++k) force(i, k) = kEpsilon * extent * std::abs(diag(3 * i + k));
  return p.RelativeResidual(force);
}

// Checks without the residual halving after which a residual under the round-off floor counts
// as converged: Newton near its solution halves it every step.
constexpr int kStalledSteps = 5;

// What every method shares: start checks, the stop tests, the summary.
struct Run {
  ClothProblem* problem;
  Vertices* x;
  const SolveOptions& options;
  SolveSummary summary;
  Clock::time_point start = Clock::now();
  Eigen::Vector3d down = Eigen::Vector3d::UnitZ() * -1.0;
  double start_height = 0.0;
  double diagonal = 1.0;
  // Newton: an upper bound on the smallest residual the state can show in double precision
  // (RoundOffFloor), from the last Hessian. A residual below it that has stopped falling
  // (kStalledSteps checks without halving) is converged as far as arithmetic allows.
  double round_off_floor = 0.0;
  double best_residual = std::numeric_limits<double>::infinity();
  int stalled = 0;

  Run(ClothProblem* p, Vertices* state, const SolveOptions& o) : problem(p), x(state), options(o) {}

  // False (with the message set) when the problem cannot have a static equilibrium.
  bool Start() {
    std::string why;
    if (!options.Check(&why)) throw InputError("solver options: " + why);
    if (options.method == SolverMethod::kKineticDamping && problem->lagged_slip())
      throw InputError("solver: lagged friction slip needs Newton (the kinetic solver never slips)");
    if (x->rows() != problem->num_vertices())
      throw InputError("solver: the start state has " + std::to_string(x->rows()) +
                       " vertices, the mesh " + std::to_string(problem->num_vertices()));
    if (!x->allFinite()) throw InputError("solver: the start state is not finite");
    problem->ApplyFixed(x);
    const Eigen::Vector3d g = problem->options().gravity;
    if (g.norm() > 0.0) down = g.normalized();
    start_height = CentreHeight(*problem, *x, down);
    diagonal = PatternDiagonal(problem->rest());
    if (problem->fixed_vertices().empty() && problem->supports().empty() && g.norm() > 0.0) {
      summary.message =
          "nothing holds the cloth (no fixed vertex, no support): under gravity it has no static "
          "equilibrium";
      return false;
    }
    return true;
  }

  // Non-empty message when the run must stop unconverged.
  std::string Stop(double energy, double residual) const {
    if (!std::isfinite(energy) || !std::isfinite(residual) || !x->allFinite())
      return "the state became non-finite (NaN or inf)";
    // ≥, so that a cap of 0 stops every run at its first check (the tests' deterministic cap).
    if (Since(start) >= options.max_seconds)
      return "time cap of " + std::to_string(options.max_seconds) + " s reached";
    if (start_height - CentreHeight(*problem, *x, down) > options.fall_limit * diagonal)
      return "the cloth falls: nothing holds it (it sank " + std::to_string(options.fall_limit) +
             " pattern diagonals)";
    return {};
  }

  SolveSummary Finish(double energy, double residual) {
    summary.energy = energy;
    summary.residual = residual;
    summary.seconds = Since(start);
    summary.contacts = problem->num_contacts(*x);
    summary.anchors = problem->num_anchors();
    return summary;
  }

  // The checks at the top of every iteration: true (summary filled) when the run ends here,
  // converged or not.
  bool Done(int it, double energy, double residual, double slid) {
    summary.iterations = it;
    Trace(it, energy, residual, slid);
    if (const std::string stop = Stop(energy, residual); !stop.empty()) {
      summary.message = stop;
      return true;
    }
    if (residual < 0.5 * best_residual) {
      best_residual = residual;
      stalled = 0;
    } else {
      ++stalled;
    }
    const bool at_floor = residual < round_off_floor && stalled >= kStalledSteps;
    if ((residual < options.tolerance || at_floor) && !Sliding(slid)) {
      summary.converged = true;
      summary.message = residual < options.tolerance
                            ? "converged: residual below tolerance"
                            : "converged: residual " + Sci(residual) +
                                  " at the round-off floor " + Sci(round_off_floor) +
                                  " of this stiffness (tolerance " + Sci(options.tolerance) + ")";
      return true;
    }
    if (it >= options.max_iterations) {
      summary.message = CapMessage(slid);
      return true;
    }
    return false;
  }

  // Whether the friction anchors still move: under lagged slip any move of the last
  // SlipAnchors (it only moves nodes pulled past the cone); under the friction potential any
  // lag still over its 1 % (a relative gap, not a length); else a slip over anchor_tolerance.
  bool Sliding(double slid) const {
    return problem->lagged_slip() || problem->friction_potential() ? slid > 0.0
                                                                   : slid > options.anchor_tolerance;
  }

  std::string CapMessage(double slid) const {
    std::string m = "iteration cap of " + std::to_string(options.max_iterations) + " reached";
    if (Sliding(slid))
      m += problem->friction_potential()
               ? " with the friction's lagged normal forces or tangent planes still settling (over 1 % "
                 "off): no static equilibrium yet"
               : " with friction anchors still sliding: the cloth slides, no static equilibrium";
    return m;
  }

  void Trace(int it, double energy, double residual, double step) const {
    if (options.verbose)
      std::fprintf(stderr, "%s %4d  E %.9e J  residual %.3e  step %.3e\n", summary.method.c_str(),
                   it, energy, residual, step);
  }
};

// When Newton tries the exact Hessian (SolveOptions::exact_below): at once after a success,
// else after 1, 2, 4, ... 16 steps, since a try that fails (the Hessian is indefinite: the
// state is not yet in a minimum's basin) costs an assembly and a factorisation for nothing.
class ExactHessianTries {
 public:
  // Whether to try this step (counts the wait down).
  bool Due() {
    if (wait_ == 0) return true;
    --wait_;
    return false;
  }
  // Records a try's outcome and returns it.
  bool Took(bool success) {
    if (success) {
      backoff_ = 1;
    } else {
      wait_ = backoff_;
      backoff_ = std::min(2 * backoff_, 16);
    }
    return success;
  }

 private:
  int wait_ = 0;
  int backoff_ = 1;
};

SolveSummary Newton(Run& run) {
  ClothProblem& p = *run.problem;
  Vertices& x = *run.x;
  const SolveOptions& o = run.options;
  const double max_step = o.max_step > 0.0 ? o.max_step : 0.1 * run.diagonal;
  LinearSolver linear(o);
  // What the anchors report at the start counts at the first check too: a slip of the plain
  // anchors, or a friction_potential's lag carried over more than 1 % off, must not pass for
  // converged at iteration 0 (lagged slip reports its moves in the loop instead).
  const double start_slid = p.UpdateAnchors(x, x);
  Vertices grad, trial, trial_grad, longer, longer_grad;
  double energy = p.EnergyGradient(x, &grad);
  double residual = p.RelativeResidual(grad);
  double slid = p.lagged_slip() ? 0.0 : start_slid;
  ExactHessianTries exact;
  Eigen::VectorXd d;
  for (int it = 0;; ++it) {
    if (p.lagged_slip() && residual < o.tolerance) {
      // Stuck to tolerance: slip the anchors pulled past the friction cone (contact.h).
      slid = p.SlipAnchors(x);
      if (slid > 0.0) {
        energy = p.EnergyGradient(x, &grad);
        residual = p.RelativeResidual(grad);
        ++run.summary.slips;
      }
    }
    if (run.Done(it, energy, residual, slid)) return run.Finish(energy, residual);
    const Eigen::VectorXd g = Flat(grad);
    bool exact_step = false;
    if (residual < o.exact_below && o.projection != HessianProjection::kNone &&
        o.linear == LinearSolverKind::kCholmod && exact.Due()) {
      const SparseMatrix& h = p.Hessian(x, HessianProjection::kNone);
      run.round_off_floor = RoundOffFloor(p, x, h);
      exact_step = exact.Took(linear.SolveUnshifted(h, -g, &d, &run.summary) && d.dot(g) < 0.0);
    }
    if (exact_step) {
      ++run.summary.exact_steps;
    } else {
      const SparseMatrix& h = p.Hessian(x, o.projection);
      run.round_off_floor = RoundOffFloor(p, x, h);
      if (!linear.Solve(h, -g, &d, &run.summary) || d.dot(g) >= 0.0) d = -g;
    }
    // Step cap: no vertex moves further than max_step in one iteration.
    double largest = 0.0;
    for (int i = 0; i < p.num_vertices(); ++i) largest = std::max(largest, d.segment<3>(3 * i).norm());
    if (largest > max_step) d *= max_step / largest;
    d *= p.ContactStepLimit(x, d);
    // Armijo backtracking; near convergence, where E is flat to round-off, a full step that
    // lowers the residual is taken as well.
    const double slope = d.dot(g);
    double alpha = 1.0;
    bool accepted = false;
    bool armijo = false;  // accepted by the energy's decrease, not by the residual's
    double trial_energy = 0.0;
    for (int k = 0; k < 40; ++k, alpha *= 0.5) {
      trial = x;
      Flat(trial) += alpha * d;
      trial_energy = p.EnergyGradient(trial, &trial_grad);
      if (!std::isfinite(trial_energy)) continue;
      armijo = trial_energy <= energy + 1e-4 * alpha * slope;
      if (armijo || (k == 0 && p.RelativeResidual(trial_grad) < residual &&
                     trial_energy <= energy + 1e-12 * std::abs(energy))) {
        accepted = true;
        break;
      }
    }
    // SolveOptions::expand_steps: a full projected step that lowered the energy (not one taken
    // for its residual where E is flat to round-off) is doubled while the energy keeps falling,
    // within the step cap and the contact step limit of the longer step; not the exact
    // Hessian's steps, which are scaled right.
    if (o.expand_steps && armijo && alpha == 1.0 && !exact_step) {
      const double length = std::min(largest, max_step);
      for (double a = 2.0; a * length <= max_step; a *= 2.0) {
        if (p.ContactStepLimit(x, a * d) < 1.0) break;
        longer = x;
        Flat(longer) += a * d;
        const double longer_energy = p.EnergyGradient(longer, &longer_grad);
        if (!(longer_energy < trial_energy)) break;
        trial_energy = longer_energy;
        trial.swap(longer);
        trial_grad.swap(longer_grad);
      }
    }
    if (!accepted) {
      run.summary.message = "line search failed: no step lowers the energy";
      return run.Finish(energy, residual);
    }
    const long anchors_before = p.anchor_version();
    const double step_slid = p.UpdateAnchors(trial, x);
    if (!p.lagged_slip()) slid = step_slid;  // lagged: the last SlipAnchors' move stands
    x = trial;
    if (p.anchor_version() != anchors_before) {
      energy = p.EnergyGradient(x, &grad);  // the anchor springs changed
    } else {
      energy = trial_energy;
      grad = trial_grad;
    }
    residual = p.RelativeResidual(grad);
  }
}

SolveSummary KineticDamping(Run& run) {
  ClothProblem& p = *run.problem;
  Vertices& x = *run.x;
  const SolveOptions& o = run.options;
  const double h = o.time_step;
  const int n = 3 * p.num_vertices();
  Eigen::VectorXd mass(n);
  for (int i = 0; i < p.num_vertices(); ++i) mass.segment<3>(3 * i).setConstant(p.masses()(i));
  LinearSolver linear(o);
  double slid = p.UpdateAnchors(x, x);
  Vertices grad, previous;
  double energy = p.EnergyGradient(x, &grad);
  double residual = p.RelativeResidual(grad);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n), dv;
  double kinetic_prev = 0.0;
  SparseMatrix a;
  for (int it = 0;; ++it) {
    if (run.Done(it, energy, residual, slid)) return run.Finish(energy, residual);
    const SparseMatrix& hess = p.Hessian(x, o.projection);
    // (M + h² H) Δv = h (f - h H v), f = -∇E (Baraff and Witkin 1998, eq. 16, no damping).
    a = hess * (h * h);
    for (int i = 0; i < n; ++i) a.coeffRef(i, i) += p.is_fixed()[i / 3] ? 0.0 : mass(i);
    const Eigen::VectorXd rhs = h * (-Flat(grad) - h * (hess * v));
    if (!linear.Solve(a, rhs, &dv, &run.summary)) {
      run.summary.message = "the implicit step's linear system could not be solved";
      return run.Finish(energy, residual);
    }
    v += dv;
    for (int vtx : p.fixed_vertices()) v.segment<3>(3 * vtx).setZero();
    previous = x;
    Flat(x) += h * v;
    const double kinetic = 0.5 * v.dot(mass.asDiagonal() * v);
    // Kinetic damping: at a peak of the kinetic energy the potential is near a minimum along
    // the path; zero the velocities (Barnes 1988).
    if (kinetic < kinetic_prev) {
      v.setZero();
      kinetic_prev = 0.0;
    } else {
      kinetic_prev = kinetic;
    }
    slid = p.UpdateAnchors(x, previous);
    energy = p.EnergyGradient(x, &grad);
    residual = p.RelativeResidual(grad);
  }
}

// Barycentric coordinates of p in triangle (a, b, c) in the x-y plane.
Eigen::Vector3d Barycentric2d(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d v0 = b - a, v1 = c - a, v2 = p - a;
  const double den = v0.x() * v1.y() - v1.x() * v0.y();
  const double l1 = (v2.x() * v1.y() - v1.x() * v2.y()) / den;
  const double l2 = (v0.x() * v2.y() - v2.x() * v0.y()) / den;
  return {1.0 - l1 - l2, l1, l2};
}

// The point of triangle (a, b, c) nearest to p, as clamped barycentric coordinates.
Eigen::Vector3d ClampedBarycentric(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                   const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                                   double* distance) {
  Eigen::Vector3d l = Barycentric2d(p, a, b, c);
  if (l.minCoeff() >= 0.0) {
    *distance = 0.0;
    return l;
  }
  // Nearest point on the three edges.
  const Eigen::Vector2d corners[3] = {a, b, c};
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_l = l;
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d& u = corners[e];
    const Eigen::Vector2d& w = corners[(e + 1) % 3];
    const double t = std::clamp((p - u).dot(w - u) / (w - u).squaredNorm(), 0.0, 1.0);
    const double dist = (p - (u + t * (w - u))).norm();
    if (dist < best) {
      best = dist;
      best_l.setZero();
      best_l(e) = 1.0 - t;
      best_l((e + 1) % 3) = t;
    }
  }
  *distance = best;
  return best_l;
}

}  // namespace

std::string SolverMethodName(SolverMethod method) {
  return method == SolverMethod::kNewton ? "newton" : "kinetic";
}

SolverMethod ParseSolverMethod(const std::string& name) {
  if (name == "newton") return SolverMethod::kNewton;
  if (name == "kinetic") return SolverMethod::kKineticDamping;
  throw InputError("unknown solver '" + name + "' (newton, kinetic)");
}

bool SolveOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& w) {
    *why = w;
    return false;
  };
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) return fail("tolerance must be > 0");
  if (max_iterations < 0) return fail("max_iterations must be >= 0");
  if (!(std::isfinite(max_seconds) && max_seconds >= 0.0))
    return fail("max_seconds must be a finite number >= 0");
  if (!(max_step >= 0.0) || !std::isfinite(max_step)) return fail("max_step must be >= 0");
  if (!(time_step > 0.0) || !std::isfinite(time_step)) return fail("time_step must be > 0");
  if (!(cg_tolerance > 0.0) || cg_tolerance >= 1.0) return fail("cg_tolerance must be in (0, 1)");
  if (cg_max_iterations < 1) return fail("cg_max_iterations must be >= 1");
  if (!(anchor_tolerance >= 0.0)) return fail("anchor_tolerance must be >= 0");
  if (!(fall_limit > 0.0)) return fail("fall_limit must be > 0");
  if (!(exact_below >= 0.0)) return fail("exact_below must be >= 0");
  return true;
}

std::string SolveSummary::BriefReport() const {
  std::ostringstream out;
  out << method << ": " << (converged ? "converged" : "NOT converged") << " after " << iterations
      << " iterations in " << seconds << " s, residual " << residual << " of the weight, energy "
      << energy << " J";
  if (contacts > 0) out << ", " << contacts << " nodes in contact";
  if (!converged) out << " (" << message << ")";
  return out.str();
}

SolveSummary SolveStatic(ClothProblem* problem, Vertices* x, const SolveOptions& options) {
  Run run(problem, x, options);
  run.summary.method = SolverMethodName(options.method);
  if (!run.Start()) {
    Vertices grad;
    const double e = problem->EnergyGradient(*x, &grad);
    return run.Finish(e, problem->RelativeResidual(grad));
  }
  return options.method == SolverMethod::kNewton ? Newton(run) : KineticDamping(run);
}

Eigen::SparseMatrix<double> BarycentricProlongation(const TriangleMesh& coarse_rest,
                                                    const TriangleMesh& fine_rest) {
  if (coarse_rest.num_triangles() == 0 || fine_rest.num_vertices() == 0)
    throw InputError("prolongation: empty mesh");
  const int nc = coarse_rest.num_triangles();
  // Bucket grid over the coarse triangles' bounding boxes.
  const Eigen::Vector2d lo = coarse_rest.vertices.leftCols<2>().colwise().minCoeff();
  const Eigen::Vector2d hi = coarse_rest.vertices.leftCols<2>().colwise().maxCoeff();
  const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(nc))));
  const Eigen::Vector2d size = ((hi - lo) / cells).cwiseMax(1e-12);
  auto cell_of = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d c = ((p - lo).array() / size.array()).floor();
    return Eigen::Vector2i(std::clamp(static_cast<int>(c.x()), 0, cells - 1),
                           std::clamp(static_cast<int>(c.y()), 0, cells - 1));
  };
  std::vector<std::vector<int>> bucket(static_cast<size_t>(cells) * cells);
  auto corner = [&](int f, int k) -> Eigen::Vector2d {
    return coarse_rest.vertices.row(coarse_rest.triangles(f, k)).head<2>().transpose();
  };
  for (int f = 0; f < nc; ++f) {
    Eigen::Vector2d a = corner(f, 0), b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(corner(f, k));
      b = b.cwiseMax(corner(f, k));
    }
    const Eigen::Vector2i c0 = cell_of(a), c1 = cell_of(b);
    for (int i = c0.x(); i <= c1.x(); ++i)
      for (int j = c0.y(); j <= c1.y(); ++j) bucket[static_cast<size_t>(i) * cells + j].push_back(f);
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (int v = 0; v < fine_rest.num_vertices(); ++v) {
    const Eigen::Vector2d p = fine_rest.vertices.row(v).head<2>().transpose();
    const Eigen::Vector2i c = cell_of(p);
    int best_f = -1;
    double best_d = std::numeric_limits<double>::infinity();
    Eigen::Vector3d best_l;
    // Search the point's cell, then rings around it until a containing triangle is found or
    // the ring is further away than the nearest candidate.
    for (int ring = 0; ring <= cells && best_d > 0.0; ++ring) {
      if (best_f >= 0 && (ring - 1) * size.minCoeff() > best_d) break;
      for (int i = c.x() - ring; i <= c.x() + ring; ++i) {
        for (int j = c.y() - ring; j <= c.y() + ring; ++j) {
          if (i < 0 || j < 0 || i >= cells || j >= cells) continue;
          if (std::max(std::abs(i - c.x()), std::abs(j - c.y())) != ring) continue;
          for (int f : bucket[static_cast<size_t>(i) * cells + j]) {
            double d;
            const Eigen::Vector3d l = ClampedBarycentric(p, corner(f, 0), corner(f, 1), corner(f, 2), &d);
            if (d < best_d) {
              best_d = d;
              best_f = f;
              best_l = l;
            }
          }
        }
      }
    }
    for (int k = 0; k < 3; ++k)
      if (best_l(k) != 0.0) triplets.emplace_back(v, coarse_rest.triangles(best_f, k), best_l(k));
  }
  Eigen::SparseMatrix<double> prolongation(fine_rest.num_vertices(), coarse_rest.num_vertices());
  prolongation.setFromTriplets(triplets.begin(), triplets.end());
  return prolongation;
}

namespace {

// Levels coarsest first; states[0] is the start, states[i] receives level i's solution.
SolveSummary Cascade(const std::vector<ClothProblem*>& levels, std::vector<Vertices>* states,
                     const SolveOptions& options) {
  if (levels.size() < 2) throw InputError("cascadic: at least two levels (coarse and fine)");
  const auto start = Clock::now();
  states->resize(levels.size());
  SolveOptions coarse_options = options;
  coarse_options.tolerance = 10.0 * options.tolerance;
  int coarse_iterations = 0;
  double coarse_seconds = 0.0;
  for (size_t level = 0;; ++level) {
    const bool finest = level + 1 == levels.size();
    SolveOptions level_options = finest ? options : coarse_options;
    level_options.max_seconds = std::max(1e-3, options.max_seconds - Since(start));
    if (level > 0) {
      const Eigen::SparseMatrix<double> prolongation =
          BarycentricProlongation(levels[level - 1]->rest(), levels[level]->rest());
      (*states)[level] = prolongation * (*states)[level - 1];
    }
    SolveSummary s = SolveStatic(levels[level], &(*states)[level], level_options);
    s.method = "cascadic";
    if (!finest && !s.converged) {
      s.message = (levels.size() == 2 ? std::string("coarse level: ")
                                      : "level " + std::to_string(level + 1) + " of " +
                                            std::to_string(levels.size()) + ": ") +
                  s.message;
      s.coarse_iterations = coarse_iterations + s.iterations;
      s.coarse_seconds = coarse_seconds + s.seconds;
      s.iterations = 0;
      return s;
    }
    if (finest) {
      s.coarse_iterations = coarse_iterations;
      s.coarse_seconds = coarse_seconds;
      s.seconds = Since(start);
      return s;
    }
    coarse_iterations += s.iterations;
    coarse_seconds += s.seconds;
  }
}

}  // namespace

SolveSummary SolveCascadic(ClothProblem* coarse, ClothProblem* fine, Vertices* x_coarse,
                           Vertices* x_fine, const SolveOptions& options) {
  std::vector<Vertices> states = {*x_coarse};
  SolveSummary s = Cascade({coarse, fine}, &states, options);
  *x_coarse = states[0];
  if (states[1].rows() > 0) *x_fine = states[1];
  return s;
}

SolveSummary SolveCascadic(const std::vector<ClothProblem*>& levels, Vertices* x,
                           const SolveOptions& options) {
  std::vector<Vertices> states = {*x};
  SolveSummary s = Cascade(levels, &states, options);
  if (states.back().rows() > 0) *x = states.back();
  return s;
}

}  // namespace textile
