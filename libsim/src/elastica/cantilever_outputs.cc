#include "textile/sim/elastica/cantilever_outputs.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;
constexpr double kDegree = std::numbers::pi / 180.0;

std::string Number(double v, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

// Peirce's factor c/L = (cos(θ/2) / (8 tan θ))^(1/3).
double PeirceFactor(double chord_angle) {
  return std::cbrt(std::cos(0.5 * chord_angle) / (8.0 * std::tan(chord_angle)));
}

// The chord angle of the strip at overhang L, minus the barrier angle; increasing in L.
// Remembers the last tip angle to warm-start the next shooting.
class ChordExcess {
 public:
  ChordExcess(const BendingLaw& law, double areal_density, const CrossingOptions& options)
      : law_(law),
        areal_density_(areal_density),
        barrier_angle_(options.barrier_angle),
        max_seconds_(options.max_seconds),
        solve_max_seconds_(options.elastica.max_seconds) {
    elastica_ = options.elastica;
    elastica_.arc_lengths.clear();
    elastica_.num_samples = 2;
    elastica_.sensitivities = false;
  }

  // False when the solve fails (message in failure()). Values are remembered per length, so
  // that asking again (GSL's root solver re-evaluates the bracket ends) gives the same sign.
  bool Evaluate(double length, double* excess) {
    for (const auto& [l, e] : memo_) {
      if (l == length) {
        *excess = e;
        return true;
      }
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (elapsed >= max_seconds_) {
      failure_ = "time cap of " + Number(max_seconds_) +
                 " s (CrossingOptions::max_seconds) reached after " + std::to_string(solves_) +
                 " elastica solves";
      return false;
    }
    elastica_.max_seconds = std::min(solve_max_seconds_, max_seconds_ - elapsed);
    ++solves_;
    // A previous tip angle is a good start unless the strip hung nearly vertically (then the
    // angle alone has lost the information, and the solver's own estimate is better).
    elastica_.tip_angle_guess = last_tip_angle_ < kHalfPi - 1e-3
                                    ? last_tip_angle_
                                    : std::numeric_limits<double>::quiet_NaN();
    last_ = SolveHeavyElastica(law_, areal_density_, length, elastica_);
    if (!last_.converged) {
      failure_ = "elastica at L = " + Number(units::MToMm(length), 10) +
                 " mm did not converge: " + last_.message;
      return false;
    }
    last_tip_angle_ = last_.tip_angle;
    *excess = std::atan2(-last_.tip_y, last_.tip_x) - barrier_angle_;
    memo_.emplace_back(length, *excess);
    return true;
  }

  const ElasticaProfile& last() const { return last_; }
  void Forget() { memo_.clear(); }
  const std::string& failure() const { return failure_; }
  int solves() const { return solves_; }

 private:
  const BendingLaw& law_;
  double areal_density_, barrier_angle_;
  double max_seconds_, solve_max_seconds_;  // the search's cap, each solve's own
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  ElasticaOptions elastica_;
  ElasticaProfile last_;
  double last_tip_angle_ = std::numeric_limits<double>::quiet_NaN();
  std::string failure_;
  int solves_ = 0;
  std::vector<std::pair<double, double>> memo_;  // (L, excess)
};

// GSL wants a plain function; a failed solve is flagged and reported as a finite value so that
// GSL never sees NaN (its default error handler would abort).
struct BrentContext {
  ChordExcess* excess;
  bool failed = false;
};

double BrentFunction(double length, void* params) {
  auto* context = static_cast<BrentContext*>(params);
  double value = 0.0;
  if (context->failed || !context->excess->Evaluate(length, &value)) {
    context->failed = true;
    return 0.0;
  }
  return value;
}

struct RootSolverDeleter {
  void operator()(gsl_root_fsolver* s) const { gsl_root_fsolver_free(s); }
};

}  // namespace

bool CrossingOptions::Check(std::string* why) const {
  std::ostringstream s;
  std::string elastica_why;
  if (!(barrier_angle > 0.0 && barrier_angle < kHalfPi)) {
    s << "barrier_angle must be in (0, pi/2) rad, got " << barrier_angle;
  } else if (!(std::isfinite(max_length) && max_length > 0.0)) {
    s << "max_length must be a finite number > 0 m, got " << max_length;
  } else if (!(rel_tol >= 1e-13 && rel_tol <= 1e-3)) {
    s << "rel_tol must be in [1e-13, 1e-3], got " << rel_tol;
  } else if (max_iterations < 2) {
    s << "max_iterations must be >= 2, got " << max_iterations;
  } else if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    s << "max_seconds must be a finite number >= 0, got " << max_seconds;
  } else if (ElasticaOptions e = elastica; e.arc_lengths.clear(), !e.Check(&elastica_why)) {
    s << "elastica: " << elastica_why;
  }
  if (why != nullptr) *why = s.str();
  return s.str().empty();
}

std::string BarrierCrossing::BriefReport() const {
  std::ostringstream s;
  s.precision(6);
  s << "Barrier crossing at " << barrier_angle / kDegree << " deg: ";
  if (!converged) {
    s << "FAILED: " << message;
  } else {
    s << "L* = " << units::MToMm(overhang) << " mm, tip (" << units::MToMm(tip_x) << ", "
      << units::MToMm(tip_y) << ") mm, kappa(0) = " << units::SiCurvatureToKes(clamp_curvature)
      << " /cm; " << elastica_solves << " elastica solves";
  }
  return s.str();
}

BarrierCrossing FindBarrierCrossing(const BendingLaw& law, double areal_density,
                                    const CrossingOptions& options) {
  if (std::string why; !options.Check(&why)) throw InputError("crossing options: " + why);
  if (!(std::isfinite(areal_density) && areal_density > 0.0))
    throw InputError("areal density must be a finite number > 0 kg/m², got " +
                     Number(areal_density));

  BarrierCrossing crossing;
  crossing.barrier_angle = options.barrier_angle;
  ChordExcess excess(law, areal_density, options);
  int iterations = 0;
  auto fail = [&](const std::string& message) {
    crossing.message = message;
    crossing.elastica_solves = excess.solves();
    return crossing;
  };

  // Start at the linear law's answer with B(0): c = ℓ = (B/ρg)^(1/3), L = c / Peirce factor.
  const double bending_length = std::cbrt(law.Stiffness(0.0) / (areal_density * units::kGravity));
  double lo = std::min(bending_length / PeirceFactor(options.barrier_angle), options.max_length);
  double f_lo = 0.0;
  ++iterations;
  if (!excess.Evaluate(lo, &f_lo)) return fail(excess.failure());
  double hi = lo, f_hi = f_lo;
  if (f_lo < 0.0) {
    // Double until the tip passes the barrier, up to the longest sample.
    while (f_hi < 0.0) {
      if (hi >= options.max_length) {
        return fail("does not reach the barrier within " +
                    Number(units::MToMm(options.max_length)) + " mm (chord angle there " +
                    Number((f_hi + options.barrier_angle) / kDegree, 4) + " deg)");
      }
      if (++iterations > options.max_iterations) return fail("bracketing did not finish");
      lo = hi;
      f_lo = f_hi;
      hi = std::min(2.0 * hi, options.max_length);
      if (!excess.Evaluate(hi, &f_hi)) return fail(excess.failure());
    }
  } else {
    // Halve until the tip is above the barrier (the chord angle -> 0 as L -> 0).
    while (f_lo >= 0.0) {
      if (++iterations > options.max_iterations) {
        return fail("the tip is past the barrier at every overhang down to " +
                    Number(units::MToMm(lo)) + " mm");
      }
      hi = lo;
      f_hi = f_lo;
      lo = 0.5 * lo;
      if (!excess.Evaluate(lo, &f_lo)) return fail(excess.failure());
    }
  }

  // Brent on the bracket. The chord angle is smooth in L, so this converges superlinearly.
  std::unique_ptr<gsl_root_fsolver, RootSolverDeleter> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent));
  BrentContext context{&excess};
  gsl_function function{&BrentFunction, &context};
  // gsl_root_fsolver_set evaluates both ends again; the two solves are cheap (warm started).
  gsl_root_fsolver_set(solver.get(), &function, lo, hi);
  if (context.failed) return fail(excess.failure());
  bool done = false;
  while (!done) {
    if (++iterations > options.max_iterations) {
      return fail("Brent did not converge in " + std::to_string(options.max_iterations) +
                  " iterations (bracket [" + Number(units::MToMm(lo), 12) + ", " +
                  Number(units::MToMm(hi), 12) + "] mm)");
    }
    gsl_root_fsolver_iterate(solver.get());
    if (context.failed) return fail(excess.failure());
    lo = gsl_root_fsolver_x_lower(solver.get());
    hi = gsl_root_fsolver_x_upper(solver.get());
    done = gsl_root_test_interval(lo, hi, 0.0, options.rel_tol) == GSL_SUCCESS;
  }

  // Report the strip at the root itself.
  const double root = gsl_root_fsolver_root(solver.get());
  double f_root = 0.0;
  if (!excess.Evaluate(root, &f_root)) return fail(excess.failure());
  if (excess.last().length != root) {
    // The root was a memoised evaluation; solve once more for the strip itself.
    excess.Forget();
    if (!excess.Evaluate(root, &f_root)) return fail(excess.failure());
  }
  const ElasticaProfile& at_root = excess.last();
  crossing.converged = true;
  crossing.overhang = root;
  crossing.tip_x = at_root.tip_x;
  crossing.tip_y = at_root.tip_y;
  crossing.tip_angle = at_root.tip_angle;
  crossing.clamp_curvature = at_root.clamp_curvature;
  crossing.elastica_solves = excess.solves();
  crossing.message = "converged, chord angle within " + Number(std::abs(f_root) / kDegree, 2) +
                     " deg of the barrier";
  return crossing;
}

double HalfRuleBendingLength(double overhang) { return 0.5 * overhang; }

double PeirceBendingLength(double overhang, double chord_angle) {
  if (!(std::isfinite(overhang) && overhang > 0.0))
    throw InputError("overhang must be a finite number > 0 m, got " + Number(overhang));
  if (!(chord_angle > 0.0 && chord_angle < kHalfPi))
    throw InputError("chord angle must be in (0, pi/2) rad, got " + Number(chord_angle));
  return overhang * PeirceFactor(chord_angle);
}

double FlexuralRigidity(double areal_density, double bending_length) {
  return areal_density * units::kGravity * bending_length * bending_length * bending_length;
}

double ClassicOutputs::rigidity_micro_nm() const {
  return units::SiRigidityToMicroNm(flexural_rigidity);
}
double ClassicOutputs::rigidity_mg_cm() const { return units::SiRigidityToMgCm(flexural_rigidity); }
double ClassicOutputs::rigidity_gf_cm() const { return units::SiRigidityToGfCm(flexural_rigidity); }

std::string ClassicOutputs::RelationToLaw(const BendingLaw& law) const {
  std::ostringstream s;
  s.precision(4);
  if (law.is_spline()) {
    s << "G = " << flexural_rigidity / law.b1() << " B(0) = " << flexural_rigidity / law.b2()
      << " B(end) (spline law: B(0) = " << law.b1_kes()
      << ", B beyond the last knot = " << law.b2_kes() << " gf·cm)";
    return s.str();
  }
  s << "G = " << flexural_rigidity / law.b1() << " b1 = " << flexural_rigidity / law.b2()
    << " b2 (b1 = " << law.b1_kes() << ", b2 = " << law.b2_kes() << " gf·cm)";
  return s.str();
}

std::string ClassicOutputs::BriefReport() const {
  std::ostringstream s;
  s.precision(6);
  s << "L = " << units::MToMm(overhang) << " mm at " << chord_angle / kDegree << " deg ("
    << (half_rule ? "L/2 rule" : "Peirce's formula") << "): c = " << units::MToMm(bending_length)
    << " mm, G = " << rigidity_micro_nm() << " µN·m = " << rigidity_mg_cm()
    << " mg·cm = " << rigidity_gf_cm() << " gf·cm";
  return s.str();
}

ClassicOutputs ComputeClassicOutputs(double areal_density, double overhang, double chord_angle) {
  if (!(std::isfinite(areal_density) && areal_density > 0.0))
    throw InputError("areal density must be a finite number > 0 kg/m², got " +
                     Number(areal_density));
  ClassicOutputs out;
  out.areal_density = areal_density;
  out.overhang = overhang;
  out.chord_angle = chord_angle;
  out.half_rule = std::abs(chord_angle - kStandardBarrierAngle) <= 1e-9;
  // PeirceBendingLength validates overhang and angle for both rules.
  const double peirce = PeirceBendingLength(overhang, chord_angle);
  out.bending_length = out.half_rule ? HalfRuleBendingLength(overhang) : peirce;
  out.flexural_rigidity = FlexuralRigidity(areal_density, out.bending_length);
  return out;
}

}  // namespace textile
