#ifndef TEXTILE_FIT_CLAPP_H_
#define TEXTILE_FIT_CLAPP_H_

// The moment-curvature law from cantilever profiles by the method of Clapp, Peng, Ghosh and
// Eischen (1990), as summarised by Pabst et al. section 3.1: the baseline that the direct
// elastica fit (direct_fit.h) must beat on the same data. See docs/methods/clapp.md.
//
//   std::vector<textile::Profile> profiles = {textile::ReadProfileCsv("strip_40mm.csv"),
//                                             textile::ReadProfileCsv("strip_60mm.csv")};
//   textile::ClappResult r = textile::FitClapp(profiles, textile::units::GsmToSi(200.0));
//   if (!r.success) { std::cerr << r.message << "\n"; return 3; }
//   std::cout << r.BriefReport() << "\n";
//   double b1 = r.law->b1();                                   // [N·m]
//
// Per profile (same strip, one overhang length each):
//   1. digitised points (x, y) -> polar coordinates about the edge: r = |(x, y)|,
//      φ = atan2(-y, x), the angle below horizontal;
//   2. least-squares polynomial φ(r) of order 5 (Clapp's choice);
//   3. along the smooth curve x = r cos φ(r), y = -r sin φ(r): curvature κ, arc length s and
//      the moment per unit width m(s) = ρ g ∫_s^L (x(s') - x(s)) ds' (docs/spec/cantilever.md);
//   4. (κ, m) pairs at evenly spaced arc lengths.
// The pairs of all profiles are pooled and eq. 1 of Pabst et al. ({b1, b2, c1}) is regressed
// on them by least squares in M (Ceres), with κ0 ≥ 0 guaranteed by the parametrisation
// (ln b1, ln b2, ln κ0).

#include <optional>
#include <string>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/sim/law/bending_law.h"

namespace textile {

// Robust loss on the moment residuals. Clapp et al. used ordinary least squares (kNone).
enum class ClappLoss { kNone, kHuber, kCauchy };

// Weights of the digitised points in the least-squares polynomial φ(r).
//   kUniform: every point's angle residual φ_i - φ(r_i) counts alike ("standard least
//             squares", Pabst et al. 3.1), so a position error σ weighs σ / r near the edge.
//   kRadius:  residuals r_i (φ_i - φ(r_i)), i.e. the distance across the curve; the same
//             polynomial family, weighted as position noise actually is. Not Clapp's.
enum class ClappWeighting { kUniform, kRadius };

struct ClappOptions {
  // Order of the polynomial φ(r) [-]; Clapp et al. used 5.
  int polynomial_order = 5;
  // Weights of the polynomial fit (see ClappWeighting); Clapp et al.: uniform.
  ClappWeighting weighting = ClappWeighting::kUniform;
  // (κ, M) pairs taken per profile, evenly spaced in arc length along the smooth curve from
  // the edge (s = 0) to the end of the evaluated range [-]; ≥ 3.
  int points_per_profile = 50;
  // Fraction of the curve's length at the free tip left out of the (κ, M) pairs [-], in
  // [0, 0.5). There m -> 0 and the polynomial's end is least reliable. 0 keeps the whole
  // curve: nothing in the method's published summary says Clapp et al. dropped the tip.
  double tip_exclusion = 0.0;
  // Digitised points closer to the edge than this are not used for the polynomial [m], ≥ 0.
  // The polar angle is undefined at r = 0 (such points are always dropped), and a position
  // error σ becomes an angle error σ / r near the edge: with uniform weights, 0.1 mm of noise
  // on points within 1 mm of the edge ruins the whole fit (docs/methods/clapp.md). A hand digitiser
  // would not pick points there either; 3 and 5 mm did best of 0-5 mm in our study.
  double min_radius = 3e-3;
  // Robust loss on the (scaled) moment residuals, and its scale as a fraction of the largest
  // observed moment (> 0; ignored for kNone).
  ClappLoss loss = ClappLoss::kNone;
  double loss_scale = 0.05;
  // Starts of the regression, κ0 spread over the observed curvature range [-]; ≥ 1. The best
  // (lowest cost) converged start is kept: eq. 1 is not convex in κ0.
  int num_starts = 6;
  // Ceres iterations per start; ≥ 1.
  int max_iterations = 200;
  // Wall-clock cap on the whole fit [s], finite and ≥ 0. A fit takes milliseconds; the caps
  // above bound its work, this bounds its time on a slow or loaded machine. Checked before
  // each start and passed to Ceres as the time left; a fit that reaches it returns
  // success = false with a "time cap" message and no law (a best start found so far is not
  // trusted: the starts not run might fit better). 0 stops before the first start (for tests).
  double max_seconds = 10.0;

  // True when the options are usable; otherwise false with the reason in *why (if non-null).
  bool Check(std::string* why) const;
};

// One (κ, M) pair of the smooth curve.
struct ClappPoint {
  double kappa = 0.0;   // curvature [1/m], positive when bending downwards
  double moment = 0.0;  // moment per unit width [N] (= N·m/m)
  double s = 0.0;       // arc length from the edge along the smooth curve [m]
  int profile = 0;      // index into the input profiles
};

// The smooth curve of one profile: φ(r) = Σ_k coefficients[k] (r / r_scale)^k [rad].
struct ClappProfileFit {
  std::string source;                // Profile::source, for messages
  std::vector<double> coefficients;  // #(order + 1) polynomial coefficients [rad], in r / r_scale
  double r_scale = 0.0;              // distance of the tip (last point) from the edge [m]
  int points_used = 0;               // digitised points that entered the polynomial
  double residual_rms = 0.0;         // RMS of r_i (φ_i - φ(r_i)), data vs curve [m]
  double curve_length = 0.0;         // arc length of the smooth curve to r_scale [m]
  double data_length = 0.0;          // the profile's last s [m], for comparison
  double kappa_at_edge = 0.0;        // curvature of the smooth curve at r = 0 [1/m]

  // φ(r) [rad] at distance r [m] from the edge.
  double Phi(double r) const;
};

struct ClappResult {
  bool success = false;
  std::string message;            // what went wrong, or notes on a successful fit
  std::optional<BendingLaw> law;  // the fitted law; set iff success
  // 1-σ standard deviations of b1, b2 [N·m] and c1 [N·m²], propagated from the covariance of
  // (ln b1, ln b2, ln κ0) scaled by the residual variance. NaN when unavailable (rank
  // deficient: e.g. a linear law, or κ0 beyond the data); then covariance_available = false.
  // The (κ, M) pairs come from one smooth curve per profile and are strongly correlated, so
  // these are optimistic: they measure the regression, not the polynomial step.
  double sd_b1 = 0.0, sd_b2 = 0.0, sd_c1 = 0.0;
  bool covariance_available = false;
  // Largest |κ| among the pairs [1/m]: the law is only supported by data on [0, kappa_max].
  double kappa_max = 0.0;
  // True when κ0 < kappa_max, i.e. the data reach the linear branch and constrain b2.
  bool b2_observed = false;
  double moment_rms = 0.0;                // RMS of M_law(κ_i) - M_i over the pairs [N]
  std::vector<ClappPoint> points;         // the pooled (κ, M) pairs, profile by profile
  std::vector<ClappProfileFit> profiles;  // one per input profile, same order

  // A few lines for people: constants in KES units with 1-σ, κ range, residuals.
  std::string BriefReport() const;
};

// Fits the law of Pabst et al. eq. 1 to cantilever profiles of one strip by Clapp's method.
// @param profiles       #P ≥ 1 profiles of the same strip (different overhang lengths), in the
//                       frame of docs/spec/cantilever.md: origin at the edge, x towards the
//                       overhang, y up, s from the edge, all [m]; each must pass CheckProfile
// @param areal_density  ρ [kg/m²], > 0 (only M/ρ is identifiable from shape)
// @param options        see ClappOptions
// Throws InputError for bad options, a bad profile or too few usable points for the
// polynomial (the message names the profile). A regression that does not converge returns
// success = false with a message, never a law.
ClappResult FitClapp(const std::vector<Profile>& profiles, double areal_density,
                     const ClappOptions& options = {});

// The smooth-curve half of the method for one profile (steps 1-4 above), exposed for tests
// and plots. Throws InputError like FitClapp.
// @param profile        one profile [m]
// @param areal_density  ρ [kg/m²], > 0
// @param points         output, #options.points_per_profile (κ, M) pairs (profile index 0)
ClappProfileFit FitClappProfile(const Profile& profile, double areal_density,
                                const ClappOptions& options, std::vector<ClappPoint>* points);

}  // namespace textile

#endif  // TEXTILE_FIT_CLAPP_H_
