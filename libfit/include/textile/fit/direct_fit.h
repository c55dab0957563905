#ifndef TEXTILE_FIT_DIRECT_FIT_H_
#define TEXTILE_FIT_DIRECT_FIT_H_

// The direct fit (docs/spec/cantilever.md, "Direct fit"): the constants {b1, b2, c1} of Pabst eq. 1
// such that heavy-elastica profiles match one or several measured profiles of the same strip.
//
//   std::vector<textile::Profile> profiles = {textile::ReadProfileCsv("strip_40.csv"),
//                                             textile::ReadProfileCsv("strip_60.csv")};
//   textile::DirectFitOptions options;                 // offset fitted, Cauchy loss 0.5 mm
//   textile::DirectFitSummary fit = textile::FitDirect(profiles, 0.2 /* kg/m² */, options);
//   if (!fit.converged) throw textile::ComputeError(fit.message);
//   std::cout << fit.BriefReport() << "\n";           // law, 1-σ, RMS in mm, what is observed
//
// Unknowns: the law p = (ln b1, ln b2, ln κ0) (κ0 ≥ 0 by construction), each profile's
// overhang length L_i (the arc length a photo yields is biased by noise, so L is fitted, not
// taken from the data), and the rig: a vertical offset of the mid-line (it starts half a
// thickness above the edge) and optionally a small rotation. Residuals are the normal distances
// of the measured points to the model curve, each under a robust loss, plus the tip position.
// Derivatives are analytic: the elastica's variational equations give d/d{b1, b2, c1}, and the
// scaling law of the elastica gives d/dL from those (see docs/methods/fitting.md). Only M/ρ is
// identifiable from shape, so the areal density must be given.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "textile/fit/profile.h"
#include "textile/sim/law/bending_law.h"

namespace textile {

struct DirectFitOptions {
  // Fit the vertical offset of the mid-line at the edge (t/2 for a strip of thickness t).
  bool fit_offset = true;
  // When fit_offset is false: the known offset [m] (e.g. half the measured thickness).
  double offset = 0.0;
  // Fit a small rotation of the rig (camera roll not removed by the extractor) [rad].
  bool fit_rotation = false;
  // Scale of the Cauchy loss on each point's distance [m]; 0 for plain least squares. Points
  // much further than this from the curve (stray fibres, specks) lose their pull.
  double robust_scale = 0.5e-3;
  // Elastica samples per profile used to interpolate the model curve.
  int curve_samples = 41;
  // Elastica tolerance inside the fit; the final law is independent of it to ~1e-8.
  double elastica_tol = 1e-9;
  int max_iterations = 100;
  double max_seconds = 30.0;
  // When the joint RMS exceeds this [m] and every profile alone fits at least 3× better, the
  // profiles are refused as different strips (or a bad extraction).
  double outlier_profile_rms = 0.5e-3;

  bool Check(std::string* why) const;
};

// What one profile contributed.
struct ProfileFitReport {
  std::string source;
  double overhang = 0.0;     // fitted overhang L_i [m]
  double data_length = 0.0;  // arc length of the data [m] (biased long by noise)
  double rms = 0.0;          // RMS normal distance of its points [m]
  double max = 0.0;          // largest normal distance [m]
  double clamp_curvature = 0.0;  // κ(0) of the fitted model [1/m]
};

struct DirectFitSummary {
  bool converged = false;
  std::string message;        // why it failed, or "converged"
  std::optional<BendingLaw> law;  // the fitted law (b2 capped to what is observed, see below)

  // 1-σ uncertainties of b1, b2 [N·m] and c1 [N·m²] (NaN where not determined) and their
  // covariance, from the Gauss-Newton Hessian scaled by the residual variance.
  double b1_sd = 0.0, b2_sd = 0.0, c1_sd = 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();

  // Observability (docs/spec/cantilever.md): the largest curvature the data reach, and which
  // constants the data determine. When κ0 ≥ kappa_max the linear branch is never reached: b2 is not
  // observed, and the law is reported with κ0 set to kappa_max (the quadratic up to the data's
  // reach, then its last slope), not an invented b2.
  double kappa_max = 0.0;  // [1/m]
  bool b1_observed = true, b2_observed = true, c1_observed = true;
  std::string observability;  // one sentence for people

  double offset = 0.0;    // fitted vertical offset at the edge [m]
  double rotation = 0.0;  // fitted rig rotation [rad]
  double rms = 0.0;       // over all points [m]
  std::vector<ProfileFitReport> profiles;
  // The objective minimised, ½ Σ ρ(r²) over the points' robust loss and the tips' plain
  // residuals (plus the negligible prior) [mm²], with the number of residuals and of free
  // parameters: what comparing two fits of the same data needs.
  double cost = 0.0;
  int num_residuals = 0;
  int num_free_parameters = 0;

  // The points' own scatter (pooled over profiles: each point's distance from the line through
  // its neighbours, median-based) [m]. A fit whose rms exceeds 3× this and 0.05 mm is one the law
  // does not follow: then fit_pattern says where and how it misses (residual runs, rms on each
  // branch of eq. 1), and FitDirect has tried its second start.
  double point_scatter = 0.0;
  std::string fit_pattern;  // empty when the law follows the data
  // The start the fit was solved from: "Peirce" (a linear law from the tip angle) or "Clapp"
  // (the data's own M-κ regression, clapp.h), tried when the first fails or lacks fit.
  std::string start;

  int iterations = 0;
  double seconds = 0.0;

  std::string BriefReport() const;
};

// Fits the law to profiles of one strip. areal_density [kg/m²] > 0. Throws InputError for bad
// input (no profiles, invalid options, a profile that does not fit with the others); returns
// converged = false with a message when the optimisation fails.
DirectFitSummary FitDirect(const std::vector<Profile>& profiles, double areal_density,
                           const DirectFitOptions& options = {});

// FitDirect as the commands run it (fit, validate). With options.fit_rotation false it also fits
// a rig rotation and returns that fit when the data show a tilt: a likelihood-ratio test on the
// objective both minimise at three sd and a tilt of at least 0.1° (docs/methods/fitting.md, "A rig that
// is not level"). `notes` (may be null) receives what a user should know of a fit that
// succeeded: a tilt found, one the data do not show clearly but that would move b1 or b2 by more
// than two sd, a fitted offset that is no half thickness. `used` (may be null) receives the
// options of the fit returned. Throws as FitDirect.
DirectFitSummary FitDirectCheckingTilt(const std::vector<Profile>& profiles, double areal_density,
                                       const DirectFitOptions& options,
                                       std::vector<std::string>* notes,
                                       DirectFitOptions* used = nullptr);

// Initial bending stiffness from a profile's tip (Peirce's formula on the chord angle): the
// linear-law B [N·m] that a lab would quote. Used to start fits; exposed for tests.
double PeirceStiffnessEstimate(const Profile& profile, double areal_density);

}  // namespace textile

#endif  // TEXTILE_FIT_DIRECT_FIT_H_
