#ifndef TEXTILE_FIT_VALIDATE_H_
#define TEXTILE_FIT_VALIDATE_H_

// Validation of a fitted bending law against cantilever profiles (docs/guide/validate.md): the
// direct fit on all profiles, then two questions.
//
//   std::vector<textile::Profile> profiles = ...;         // one strip at 40, 60, 80 mm
//   textile::ValidationOptions options;                   // 0.5 mm, elastica and shell
//   textile::ValidationSummary v = textile::ValidateFit(profiles, 0.2 /* kg/m² */, options);
//   if (!v.completed) throw textile::ComputeError(v.message);
//   std::cout << v.BriefReport() << "\n";
//   if (v.holdout_verdict == textile::HoldoutVerdict::kFail) ...  // the law predicts badly
//
// 1. Goodness of fit: the fitted law simulated at every profile's fitted overhang, by the
//    exact heavy elastica and by the 3D shell model (acpm_shell.h), against the profile it was
//    fitted to. This checks the fit and the models, not the law: a law with three constants
//    fitted to a profile nearly always lies on it.
// 2. Held-out prediction (two or more profiles): leave-one-out. For each profile in turn the
//    law is fitted to the others (FitDirectCheckingTilt, as `textile fit` would fit them) and
//    the left-out profile is predicted at its overhang with that law and that fit's rig
//    offset and rotation, by the same models, graded by the same criteria. Each prediction
//    carries the 1-σ spread the training fit's covariance gives it (ElasticaSpread,
//    profile_compare.h). A prediction is ok when its own error is within the tolerance; its σ
//    does not widen the tolerance (a poorly determined law would pass more easily, the worse
//    the data), but a σ that is large against the tolerance is said in a note.
//
// Both verdicts grade a comparison alike: rms ≤ tolerance, max and tip distance ≤
// kMaxOverRms × tolerance.

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "textile/fit/direct_fit.h"
#include "textile/fit/profile.h"
#include "textile/fit/profile_compare.h"
#include "textile/sim/scenes/acpm_shell.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/note.h"

namespace textile {

// A single point or the tip may stray this many times the rms tolerance (a frayed fibre, a
// speck) before a comparison fails.
inline constexpr double kMaxOverRms = 3.0;

struct ValidationOptions {
  // RMS normal distance a simulated curve may miss a profile by [m], in (0, 0.05]; the largest
  // distance and the tip distance may reach kMaxOverRms times it. 0.5 mm: more than the whole
  // error budget of a photographed profile (docs/guide/validate.md, "Verdicts").
  double tolerance = 0.5e-3;
  // Which models simulate the cantilevers (at least one).
  bool run_elastica = true;
  bool run_shell = true;
  // Strip width of the shell model [m], in [0.005, 0.2] (a 0.1 mm wide shell did not settle).
  double strip_width = 0.025;
  // Leave-one-out prediction of each profile (needs two or more profiles).
  bool hold_out = true;
  // The shell also predicts each held-out profile (one more shell solve per profile). The
  // elastica alone answers the question the held-out part asks, whether the law predicts; the
  // shell's prediction adds its own discretisation to that (docs/guide/validate.md, "Speed").
  bool hold_out_shell = true;
  // Options of every direct fit (the full fit and each leave-one-out fit).
  DirectFitOptions fit;
  // Settings of every shell solve.
  ShellAcpmSettings shell;

  // False, with the reason in *why (if non-null), when a field is out of range.
  bool Check(std::string* why) const;
};

// One model's simulated curve against one profile, graded.
struct ModelComparison {
  bool run = false;  // false: the model was not asked for
  ProfileComparison comparison;
  bool pass = false;  // rms, max and tip within the tolerance
  std::string why;    // the failed criteria, "rms 0.61 mm > 0.5, ..."; empty on pass
  int solves = 0;     // static solves (shell)
};

// Goodness of fit of one profile: the law fitted to all profiles, at its fitted overhang.
struct ProfileValidation {
  std::string source;
  double data_length = 0.0;  // arc length of the data [m]
  double overhang = 0.0;     // fitted overhang L_i [m]
  ModelComparison elastica, shell;
  // Largest distance of the shell's curve from the elastica's [m]; NaN unless both ran.
  double model_gap = std::numeric_limits<double>::quiet_NaN();
  bool pass = false;  // every model run passes
  std::string why;    // "elastica: ...; shell: ..."
};

// One model's prediction of a held-out profile.
struct HeldOutModel {
  ModelComparison check;
  // 1-σ of the prediction from the training fit's covariance (CurveSpread; the elastica's
  // sensitivities for both models) [m]: rms, max, tip. NaN when not available.
  CurveSpread sigma;
};

// A profile left out: the law fitted to the other profiles predicts it.
struct HeldOutProfile {
  size_t index = 0;  // in the profiles given
  std::string source;
  double overhang = 0.0;  // the overhang predicted at: the full fit's L_i [m]
  // The fit to the other profiles: false when it failed or gave a law no material file takes
  // (then `why` says so and nothing is predicted).
  bool predicted = false;
  std::optional<BendingLaw> law;  // fitted without this profile
  double fit_rms = 0.0;           // that fit's rms over its own profiles [m]
  bool sigma_complete = true;     // false: a constant's σ was not determined (left out of σ)
  HeldOutModel elastica, shell;
  bool ok = false;  // predicted, and every model run passes
  std::string why;  // "elastica: ...; shell: ..." or why nothing was predicted
};

enum class HoldoutVerdict {
  kNone,  // nothing held out (one profile, or hold_out off)
  kPass,  // every held-out profile predicted within the tolerance
  kFail,  // at least one not (or not predicted)
};
// "none", "pass", "fail".
const char* HoldoutVerdictName(HoldoutVerdict verdict);

// The codes of ValidationSummary::notes (textile::Note).
namespace validation_note {
// A note of the full fit (tilt, offset; FitDirectCheckingTilt).
inline constexpr char kFit[] = "fit";
// One profile (or hold_out off): no prediction was made.
inline constexpr char kNothingHeldOut[] = "nothing_held_out";
// A leave-one-out fit failed: that profile was not predicted.
inline constexpr char kHeldOutFitFailed[] = "held_out_fit_failed";
// A training fit left a constant undetermined: σ without it.
inline constexpr char kSigmaIncomplete[] = "sigma_incomplete";
// 2σ of a prediction's rms exceeds the tolerance.
inline constexpr char kPredictionUncertain[] = "prediction_uncertain";
}  // namespace validation_note

struct ValidationSummary {
  // False when a computation failed (the fit, a law no material file takes, a shell solve, an
  // elastica); `message` says which and why. A failed verdict is a result, not a failure.
  bool completed = false;
  std::string message;

  DirectFitSummary fit;          // the full fit
  DirectFitOptions fit_options;  // its options (a tilt found: fit_rotation set)
  Material material;             // the fitted law as a material ("validated fit")
  ValidationOptions options;     // as given

  std::vector<ProfileValidation> profiles;  // goodness of fit, one per profile
  bool pass = false;                        // goodness of fit: every profile passes
  std::string shell_notes;                  // how the shell was discretised (the last solve)
  int shell_solves = 0;                     // static solves of the goodness-of-fit shells

  std::vector<HeldOutProfile> holdout;  // one per profile when held out, else empty
  HoldoutVerdict holdout_verdict = HoldoutVerdict::kNone;

  std::vector<Note> notes;  // codes: validation_note

  // Both verdicts pass (goodness of fit, and held out unless nothing was held out).
  bool AllPass() const { return pass && holdout_verdict != HoldoutVerdict::kFail; }
  // Why the verdicts failed, "; "-joined: "<source>: <why>" for each profile that fails the
  // goodness of fit, "<source> held out: <why>" for each held-out profile not ok. Empty when
  // AllPass().
  std::string FailureReason() const;
  // The texts of the notes with this code, in order.
  std::vector<std::string> NoteTexts(std::string_view code) const;

  // A few lines: the law, the goodness of fit, the held-out predictions, the verdicts.
  std::string BriefReport() const;
};

// Validates the direct fit of `profiles` (one strip, areal density [kg/m²] > 0). Throws
// InputError for bad options or input (as FitDirect: no profiles, profiles of different strips);
// returns completed = false with a message when a computation fails.
ValidationSummary ValidateFit(const std::vector<Profile>& profiles, double areal_density,
                              const ValidationOptions& options = {});

}  // namespace textile

#endif  // TEXTILE_FIT_VALIDATE_H_
