#ifndef TEXTILE_FIT_SEAM_FIT_H_
#define TEXTILE_FIT_SEAM_FIT_H_

// The seam influence factor B_f(d) = a2 d² + a1 d + a0 (Pabst et al. 2008, section 4.2,
// Table 2; d in mm from the seam line) fitted to measured (d, factor) pairs: ACPM200 rays
// (the virtual one's result JSON, docs/spec/cli.md) or a CSV `d_mm,factor[,sd]`. Weighted linear
// least squares (GSL gsl_multifit_wlinear) with the parameter covariance; the result is a seam
// profile (libsim seam.h) of type "fitted" with a `fit` report.
//
//   std::vector<textile::SeamSample> data = textile::ReadSeamSamples("acpm-result.json");
//   textile::SeamFitOptions options;
//   options.layers = 4;
//   textile::SeamFitSummary fit = textile::FitSeamFactor(data, options);
//   // fit.profile.coefficients_mm ≈ {2e-4, -0.0702, 9.07}, fit.covariance, fit.range_mm
//   if (fit.poor) std::cerr << "warning: " << fit.poor_reason << "\n";
//
// "Poor" (the fit is still returned; the CLI warns, or refuses with --strict):
//  - with sd on every point: χ² too large for the stated sd, i.e. the χ² upper-tail
//    probability Q(χ², dof) < 1e-3 (the quadratic, or the sd, is wrong);
//  - without sd: r² < 0.9 (the quadratic explains less than 90 % of the factor's variance)
//    and the rms residual is above 5 % of the mean factor. r² alone misfires on a flat
//    profile (an along seam on the shell ACPM): there is no variance to explain, and round-off
//    scatter of 0.001 gave r² = 0.03.
// Without sd the covariance is (XᵀX)⁻¹ scaled by the residual variance χ²/dof (as if every
// point had the same unknown sd); with exactly three points and no sd it is unknown and left out.
//
// The influence range d_max of the written profile is the largest d fitted unless given: S
// follows B_f where the data are and fades to 1 beyond (seam.h), so the polynomial is never
// extrapolated. A d_max beyond the data extrapolates B_f and is refused where B_f would rise
// there (a seam stiffer away from its line); one inside the data cuts them off (a note says
// by how much).

#include <Eigen/Core>
#include <array>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"
#include "textile/sim/law/seam.h"

namespace textile {

// One measured factor at a distance from the seam line.
struct SeamSample {
  double d_mm = 0.0;    // distance from the seam line [mm], ≥ 0
  double factor = 1.0;  // stiffness relative to the fabric without seams [-], > 0
  double sd = std::numeric_limits<double>::quiet_NaN();  // 1-σ of factor [-]; NaN: unknown
};

// Parses CSV text with the header `d_mm,factor` or `d_mm,factor,sd` ('#' comments and blank
// lines skipped). Throws InputError "<source>:<line>: <problem>" for a malformed row, a
// non-finite value, d < 0, factor ≤ 0 or sd ≤ 0.
std::vector<SeamSample> ParseSeamSamplesCsv(const std::string& text, const std::string& source);

// Reads the rays of an ACPM result (docs/spec/cli.md: {"rays": [{"d_mm", "factor", ...}], ...}).
// Rays without a seam distance (d_mm null: a plain sample) are refused. An optional "factor_sd" per
// ray is taken as sd. Throws InputError "<source>: rays[i].<field>: <problem>".
std::vector<SeamSample> SeamSamplesFromAcpmJson(const nlohmann::json& result,
                                                const std::string& source);

// The seam layers an ACPM result records (`seam.profile.layers`), or 0 when it records none
// (no seam object or profile). Throws InputError "<source>: seam.profile.layers ..." for a
// value that is not a whole number in [1, 20].
int SeamLayersFromAcpmJson(const nlohmann::json& result, const std::string& source);

// What a measurement file holds: the samples and, for an ACPM result, its seam's layers.
struct SeamMeasurement {
  std::vector<SeamSample> samples;
  int layers = 0;  // seam.profile.layers of an ACPM result; 0: not recorded (or a CSV)
};

// Reads a file: JSON (an ACPM result) if its first non-blank character is '{', else CSV. A
// leading UTF-8 byte-order mark (Excel's "CSV UTF-8") is skipped. Throws InputError naming the
// file for unreadable files and every problem above.
SeamMeasurement ReadSeamMeasurement(const std::string& path);
std::vector<SeamSample> ReadSeamSamples(const std::string& path);  // its samples

struct SeamFitOptions {
  int layers = 2;             // the seam's fabric layers (Table 1), 1..20
  std::string name;           // free text for the seam file
  // d_max of the written profile (seam.h) [mm]; B_f must stay in (0, 100] on [0, d_max], else
  // the fit cannot serve as a seam profile. NaN: the largest d fitted (at least 1 mm).
  double influence_mm = std::numeric_limits<double>::quiet_NaN();
  double poor_probability = 1e-3;  // weighted: poor when Q(χ², dof) is below this
  double poor_r2 = 0.9;            // unweighted: poor when r² is below this ...
  double poor_relative_rms = 0.05;  // ... and the rms residual above this times the mean factor
  // An explicit d_max beyond the data is refused when B_f rises there by more than this [-].
  double rise_tolerance = 0.01;

  bool Check(std::string* why) const;
};

struct SeamFitSummary {
  std::array<double, 3> coefficients_mm{};  // {a2 [1/mm²], a1 [1/mm], a0}
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of (a2, a1, a0)
  bool covariance_known = false;  // false only for 3 points without sd
  std::array<double, 2> range_mm{};  // smallest and largest d fitted [mm]
  int num_points = 0;
  int distinct_distances = 0;
  int dof = 0;             // num_points - 3
  bool weighted = false;   // every point had an sd
  double chi2 = 0.0;       // Σ w r² (w = 1/sd², or 1 unweighted)
  double chi2_probability = std::numeric_limits<double>::quiet_NaN();  // Q(χ², dof), weighted
  double rms = 0.0;        // unweighted RMS residual of the factor [-]
  double rms_relative = 0.0;  // rms / mean factor [-]
  double max_residual = 0.0;  // largest |residual| [-]
  double r2 = 0.0;         // 1 - SS_res / SS_tot (unweighted); NaN if the factors are all equal
  bool poor = false;
  std::string poor_reason;  // why, when poor
  double influence_mm = 0.0;         // d_max written [mm]
  bool influence_from_data = false;  // d_max is the largest d fitted (not given)
  // What the user should know about the written S(d), one sentence each, with its code:
  // "influence_beyond_data" (an explicit d_max beyond the data), "influence_inside_data" (d_max
  // cuts data off), "fade_overshoot" (the fade overshoots a fit that rises at d_max).
  std::vector<Note> notes;

  SeamProfile profile;  // type "fitted", ready for SeamProfileToJson (fit report included)

  nlohmann::json Report() const;  // the `fit` object of the seam file
  std::string BriefReport() const;  // one line: B_f(d), 1-σ, rms, r², range, poor
};

// Fits B_f(d) = a2 d² + a1 d + a0. Throws InputError for invalid options, fewer than 3 points,
// fewer than 3 distinct distances (the quadratic is not determined), non-finite values, d < 0,
// factor ≤ 0, sd ≤ 0, sd given on some points only, every factor below 1 (S = max(1, B_f)
// would be 1 everywhere: likely an inverted ratio), or an influence range beyond the data
// where B_f rises by more than rise_tolerance. Throws ComputeError when the fitted
// polynomial cannot serve as a seam profile (B_f ≤ 0 or > 100 somewhere on [0, d_max]).
SeamFitSummary FitSeamFactor(const std::vector<SeamSample>& samples,
                             const SeamFitOptions& options = {});

}  // namespace textile

#endif  // TEXTILE_FIT_SEAM_FIT_H_
