#include "textile/fit/validate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

#include "textile/fit/fit_report.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/polyline.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

std::string Mm(double m, int digits = 3) { return NumberText(units::MToMm(m), digits); }

void Join(const std::string& part, const char* separator, std::string* text) {
  *text += (text->empty() ? "" : separator) + part;
}

// The fitted law as the material every simulation takes, named "validated fit"
// (FittedLawMaterial: none when a material file would refuse it, the reason in *why).
std::optional<Material> MaterialOfLaw(const BendingLaw& law, double areal_density,
                                      std::string* why) {
  std::optional<Material> m = FittedLawMaterial(law, areal_density, why);
  if (m) m->name = "validated fit";
  return m;
}

// Grades a comparison against the tolerance tol [m]: the failed criteria in k->why.
void Grade(double tol, ModelComparison* k) {
  const ProfileComparison& c = k->comparison;
  const double tip = std::hypot(c.tip_dx, c.tip_dy);
  const double tol_mm = units::MToMm(tol);
  k->why.clear();
  if (c.rms > tol) Join("rms " + Mm(c.rms) + " mm > " + NumberText(tol_mm), ", ", &k->why);
  if (c.max > kMaxOverRms * tol)
    Join("max " + Mm(c.max) + " mm > " + NumberText(kMaxOverRms * tol_mm), ", ", &k->why);
  if (tip > kMaxOverRms * tol)
    Join("tip " + Mm(tip) + " mm > " + NumberText(kMaxOverRms * tol_mm), ", ", &k->why);
  k->pass = k->why.empty();
}

// The models' curves of one cantilever against one profile.
struct Simulated {
  ModelComparison elastica, shell;
  double model_gap = kNan;  // shell vs elastica, max [m]
  std::string shell_notes;
};

// Simulates the strip of `material` at `overhang` [m], lifted by `offset` [m] and turned by
// `rotation` [rad] about the edge, by the models asked for, and grades each against `measured`.
// Throws ComputeError when a model fails (named by `what`).
Simulated SimulateAndGrade(const Material& material, const Profile& measured, double overhang,
                           double offset, double rotation, bool elastica, bool shell,
                           const ValidationOptions& options, const std::string& what) {
  Simulated s;
  if (elastica) {
    s.elastica.run = true;
    s.elastica.comparison = CompareWithElastica(material.bending, material.areal_density, measured,
                                                overhang, offset, rotation);
    Grade(options.tolerance, &s.elastica);
  }
  if (shell) {
    const ShellCantilever sc =
        SolveShellCantilever(material, overhang, options.strip_width, options.shell);
    if (!sc.converged) throw ComputeError(what + ": " + sc.message);
    // The shell's curve turned by the fitted rig rotation about the edge (0 for a level rig).
    std::vector<double> sx(sc.x.size()), sy(sc.y.size());
    const double cr = std::cos(rotation), sr = std::sin(rotation);
    for (size_t j = 0; j < sc.x.size(); ++j) {
      sx[j] = cr * sc.x[j] - sr * sc.y[j];
      sy[j] = sr * sc.x[j] + cr * sc.y[j];
    }
    s.shell.run = true;
    s.shell.comparison = CompareWithCurve(measured, sx, sy, offset);
    s.shell.solves = sc.solves;
    s.shell_notes = sc.notes;
    Grade(options.tolerance, &s.shell);
    if (elastica) {
      // How far the shell's curve lies from the elastica's (both lifted by the offset).
      for (double& y : sy) y += offset;
      s.model_gap = MaxDistanceToPolyline(s.elastica.comparison.model_x,
                                          s.elastica.comparison.model_y, sx, sy);
    }
  }
  return s;
}

// "elastica: ...; shell: ..." over the models that ran and failed; empty when all passed.
std::string WhyModelsFailed(const ModelComparison& elastica, const ModelComparison& shell) {
  std::string why;
  if (elastica.run && !elastica.pass) Join("elastica: " + elastica.why, "; ", &why);
  if (shell.run && !shell.pass) Join("shell: " + shell.why, "; ", &why);
  return why;
}

// The state the stages below share.
struct Validation {
  const std::vector<Profile>& profiles;
  double areal_density;
  const ValidationOptions& options;
  ValidationSummary out;
};

// Stage 1: the direct fit of every profile, as `textile fit` runs it. False (message set) when
// the fit fails or gives a law no material file takes.
bool FitAllProfiles(Validation* v) {
  ValidationSummary& out = v->out;
  std::vector<std::string> notes;
  out.fit = FitDirectCheckingTilt(v->profiles, v->areal_density, v->options.fit, &notes,
                                  &out.fit_options);
  for (const std::string& n : notes) out.notes.push_back({validation_note::kFit, n});
  if (!out.fit.converged || !out.fit.law) {
    out.message = "fit: " + out.fit.message;
    return false;
  }
  std::string why;
  const auto material = MaterialOfLaw(*out.fit.law, v->areal_density, &why);
  if (!material) {
    out.message = "fit gave an implausible law: " + why;
    return false;
  }
  out.material = *material;
  return true;
}

// Stage 2: goodness of fit, every profile at its fitted overhang with the full fit's law.
void CompareInSample(Validation* v) {
  ValidationSummary& out = v->out;
  const ValidationOptions& o = v->options;
  out.pass = true;
  for (size_t i = 0; i < v->profiles.size(); ++i) {
    const Profile& p = v->profiles[i];
    ProfileValidation k;
    k.source = p.source;
    k.data_length = p.s.back();
    k.overhang = out.fit.profiles[i].overhang;
    Simulated s = SimulateAndGrade(out.material, p, k.overhang, out.fit.offset, out.fit.rotation,
                                   o.run_elastica, o.run_shell, o, p.source);
    k.elastica = std::move(s.elastica);
    k.shell = std::move(s.shell);
    k.model_gap = s.model_gap;
    if (k.shell.run) {
      out.shell_notes = s.shell_notes;
      out.shell_solves += k.shell.solves;
    }
    k.why = WhyModelsFailed(k.elastica, k.shell);
    k.pass = k.why.empty();
    out.pass = out.pass && k.pass;
    out.profiles.push_back(std::move(k));
  }
}

// The training fit's covariance of {b1, b2, c1} with the constants it did not determine (sd
// NaN) left out: their σ is unknown, not zero, so the spread is a lower bound then.
Eigen::Matrix3d DeterminedCovariance(const DirectFitSummary& fit, bool* complete) {
  Eigen::Matrix3d c = fit.covariance;
  *complete = true;
  const double sd[3] = {fit.b1_sd, fit.b2_sd, fit.c1_sd};
  for (int k = 0; k < 3; ++k) {
    if (std::isfinite(sd[k])) continue;
    *complete = false;
    c.row(k).setZero();
    c.col(k).setZero();
  }
  return c;
}

// Stage 3, one profile: the law fitted to the others predicts it at its overhang.
HeldOutProfile PredictHeldOut(Validation* v, size_t i) {
  const ValidationSummary& full = v->out;
  const ValidationOptions& o = v->options;
  const Profile& held = v->profiles[i];
  HeldOutProfile h;
  h.index = i;
  h.source = held.source;
  h.overhang = full.fit.profiles[i].overhang;
  std::vector<Profile> others;
  for (size_t j = 0; j < v->profiles.size(); ++j)
    if (j != i) others.push_back(v->profiles[j]);
  DirectFitSummary fit;
  try {
    fit = FitDirectCheckingTilt(others, v->areal_density, o.fit, nullptr);
  } catch (const InputError& e) {
    h.why = std::string("the fit to the other profiles refused them: ") + e.what();
    return h;
  }
  if (!fit.converged || !fit.law) {
    h.why = "the fit to the other profiles failed: " + fit.message;
    return h;
  }
  std::string implausible;
  const auto material = MaterialOfLaw(*fit.law, v->areal_density, &implausible);
  if (!material) {
    h.why = "the fit to the other profiles gave an implausible law: " + implausible;
    return h;
  }
  h.predicted = true;
  h.law = fit.law;
  h.fit_rms = fit.rms;
  Simulated s =
      SimulateAndGrade(*material, held, h.overhang, fit.offset, fit.rotation, o.run_elastica,
                       o.run_shell && o.hold_out_shell, o, held.source + " (held out)");
  const Eigen::Matrix3d cov = DeterminedCovariance(fit, &h.sigma_complete);
  const CurveSpread sigma =
      ElasticaSpread(*fit.law, v->areal_density, held, h.overhang, fit.offset, fit.rotation, cov);
  const CurveSpread none{kNan, kNan, kNan};
  h.elastica.sigma = s.elastica.run ? sigma : none;
  h.shell.sigma = s.shell.run ? sigma : none;
  h.elastica.check = std::move(s.elastica);
  h.shell.check = std::move(s.shell);
  h.why = WhyModelsFailed(h.elastica.check, h.shell.check);
  h.ok = h.why.empty();
  return h;
}

// Stage 3: leave-one-out over every profile, the verdict and its notes.
void PredictEachHeldOut(Validation* v) {
  ValidationSummary& out = v->out;
  const ValidationOptions& o = v->options;
  if (!o.hold_out || v->profiles.size() < 2) {
    out.holdout_verdict = HoldoutVerdict::kNone;
    out.notes.push_back(
        {validation_note::kNothingHeldOut,
         o.hold_out ? "one profile: nothing is held out, only the goodness of fit is graded; "
                      "profiles at two or more overhangs test whether the law predicts one it "
                      "was not fitted to"
                    : "nothing is held out (hold-out off): only the goodness of fit is graded"});
    return;
  }
  bool all_ok = true;
  for (size_t i = 0; i < v->profiles.size(); ++i) {
    HeldOutProfile h = PredictHeldOut(v, i);
    if (!h.predicted) {
      out.notes.push_back(
          {validation_note::kHeldOutFitFailed, h.source + " was not predicted: " + h.why});
    } else {
      if (!h.sigma_complete) {
        out.notes.push_back({validation_note::kSigmaIncomplete,
                             h.source + ": the fit to the other profiles does not determine "
                                        "every constant; its σ leaves the undetermined ones out "
                                        "and is a lower bound"});
      }
      const double rms_sigma = h.elastica.check.run ? h.elastica.sigma.rms : h.shell.sigma.rms;
      if (2.0 * rms_sigma > o.tolerance) {
        out.notes.push_back(
            {validation_note::kPredictionUncertain,
             h.source + ": the prediction's own 2σ (" + Mm(2.0 * rms_sigma) +
                 " mm rms) exceeds the tolerance: the other profiles determine the law too "
                 "loosely for this test to be sharp"});
      }
    }
    all_ok = all_ok && h.ok;
    out.holdout.push_back(std::move(h));
  }
  out.holdout_verdict = all_ok ? HoldoutVerdict::kPass : HoldoutVerdict::kFail;
}

}  // namespace

bool ValidationOptions::Check(std::string* why) const {
  std::string w;
  if (!(tolerance > 0.0) || !(tolerance <= 0.05))
    w = "tolerance must lie in (0, 50] mm, got " + NumberText(units::MToMm(tolerance)) + " mm";
  else if (!run_elastica && !run_shell)
    w = "no model to simulate: run the elastica, the shell or both";
  else if (hold_out && !run_elastica && !hold_out_shell)
    w = "hold-out with the shell alone needs hold_out_shell: no model would predict";
  else if (!(strip_width >= 0.005) || !(strip_width <= 0.2))
    w = "strip width must lie in [5, 200] mm, got " + NumberText(units::MToMm(strip_width)) + " mm";
  else if (std::string f; !fit.Check(&f))
    w = "fit: " + f;
  else if (std::string s; !shell.Check(&s))
    w = "shell: " + s;
  if (why) *why = w;
  return w.empty();
}

const char* HoldoutVerdictName(HoldoutVerdict verdict) {
  switch (verdict) {
    case HoldoutVerdict::kPass:
      return "pass";
    case HoldoutVerdict::kFail:
      return "fail";
    case HoldoutVerdict::kNone:
      break;
  }
  return "none";
}

std::string ValidationSummary::FailureReason() const {
  std::string why;
  for (const ProfileValidation& k : profiles)
    if (!k.pass) Join(k.source + ": " + k.why, "; ", &why);
  for (const HeldOutProfile& h : holdout)
    if (!h.ok) Join(h.source + " held out: " + h.why, "; ", &why);
  return why;
}

std::vector<std::string> ValidationSummary::NoteTexts(std::string_view code) const {
  std::vector<std::string> texts;
  for (const Note& n : notes)
    if (n.code == code) texts.push_back(n.text);
  return texts;
}

std::string ValidationSummary::BriefReport() const {
  if (!completed) return "validation failed: " + message;
  std::ostringstream s;
  const BendingLaw& law = material.bending;
  s << "law: b1 = " << NumberText(law.b1_kes(), 5) << " gf·cm, b2 = " << NumberText(law.b2_kes(), 5)
    << " gf·cm, c1 = " << NumberText(law.c1_kes(), 5) << " gf·cm² (fit rms " << Mm(fit.rms) << " mm over "
    << profiles.size() << " profile(s))\n";
  s << "goodness of fit: " << (pass ? "PASS" : "FAIL");
  for (ModelComparison ProfileValidation::*model :
       {&ProfileValidation::elastica, &ProfileValidation::shell}) {
    std::string rms;
    for (const ProfileValidation& k : profiles)
      if ((k.*model).run) Join(Mm((k.*model).comparison.rms), ", ", &rms);
    if (!rms.empty())
      s << "; " << (model == &ProfileValidation::elastica ? "elastica" : "shell") << " rms " << rms
        << " mm";
  }
  s << "\nheld out: "
    << (holdout_verdict == HoldoutVerdict::kPass   ? "PASS"
        : holdout_verdict == HoldoutVerdict::kFail ? "FAIL"
                                                   : "nothing held out");
  // Each held-out profile's rms by the first model run ("-": not predicted).
  std::string out_rms;
  for (const HeldOutProfile& h : holdout) {
    const ModelComparison& m = h.elastica.check.run ? h.elastica.check : h.shell.check;
    Join(h.predicted ? Mm(m.comparison.rms) : "-", ", ", &out_rms);
  }
  if (!out_rms.empty()) {
    s << "; predicted by the others' law, " << (options.run_elastica ? "elastica" : "shell")
      << " rms " << out_rms << " mm";
  }
  s << " (tolerance: rms ≤ " << Mm(options.tolerance, 6) << " mm, max and tip ≤ "
    << Mm(kMaxOverRms * options.tolerance, 6) << " mm)";
  return s.str();
}

ValidationSummary ValidateFit(const std::vector<Profile>& profiles, double areal_density,
                              const ValidationOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("validation options: " + why);
  Validation v{profiles, areal_density, options, {}};
  v.out.options = options;
  try {
    if (!FitAllProfiles(&v)) return std::move(v.out);
    CompareInSample(&v);
    PredictEachHeldOut(&v);
  } catch (const ComputeError& e) {
    v.out.message = e.what();
    return std::move(v.out);
  }
  v.out.completed = true;
  return std::move(v.out);
}

}  // namespace textile
