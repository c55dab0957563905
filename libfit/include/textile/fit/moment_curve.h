#ifndef TEXTILE_FIT_MOMENT_CURVE_H_
#define TEXTILE_FIT_MOMENT_CURVE_H_

// Moment-curvature curves beside a fitted law: measured (κ, M) pairs as other tools and bending
// testers write them, and the law's 1-σ band from its fit's covariance.
//
//   textile::MomentCurvePairs peer = textile::ReadMomentCurvatureCsv("peer.csv");
//   // peer.kappa [1/m], peer.moment [N]
//   double sd = textile::MomentSigma(law, covariance, 10.0);  // 1-σ of M(10 /m) [N]

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "textile/sim/law/bending_law.h"
#include "textile/sim/law/material.h"

namespace textile {

struct MomentCurvePairs {
  std::string source;
  std::vector<double> kappa;   // #N curvatures [1/m]
  std::vector<double> moment;  // #N moments per unit width [N] (= N·m/m)
};

// Parses CSV text whose header names a curvature column and a moment column, in SI
// (`kappa_per_m`, `M_N`) or lab units (`kappa_per_cm`, `M_gfcm_per_cm`); other columns are
// ignored, so a simulator's `x_mm,y_mm,kappa_per_m,M_N` reads as well. A UTF-8 byte-order mark,
// '#' comments and blank lines are skipped. Throws InputError "<source>:<line>: <problem>" for
// a header without both columns, a row with too few cells, a cell that is not a finite number,
// a negative curvature or moment, or fewer than 2 rows.
MomentCurvePairs ParseMomentCurvatureCsv(const std::string& text, const std::string& source);
// Reads (16 MB cap) and parses a file; throws InputError naming it.
MomentCurvePairs ReadMomentCurvatureCsv(const std::string& path);

// 1-σ of the law's moment M(κ) [N] at curvature κ [1/m] from the 3×3 covariance of
// (b1 [N·m], b2 [N·m], c1 [N·m²]): sqrt(gᵀ C g) with g = ∂M/∂(b1, b2, c1)
// (BendingLaw::MomentGradient). Linear propagation: the band of the law's own uncertainty, not
// of laws the model cannot represent.
double MomentSigma(const BendingLaw& law, const Eigen::Matrix3d& covariance, double kappa);

// The covariance of (b1, b2, c1) [SI] that a fitted material's report carries
// (`fit.covariance_kes`, textile fit), when every sd of the report is known and the law is eq. 1;
// else none, with why in *why ("no band: b2_sd is undetermined"). Throws InputError naming
// `source` for a covariance that is not a 3×3 array of numbers.
std::optional<Eigen::Matrix3d> FitCovariance(const Material& material, const std::string& source,
                                             std::string* why);

// The largest curvature the fit's data reached [1/m] (`fit.kappa_max_per_cm`, textile fit):
// the band of FitCovariance means nothing beyond it. None when the material carries no fit
// report or the report has no such number.
std::optional<double> FitCurvatureReach(const Material& material);

}  // namespace textile

#endif  // TEXTILE_FIT_MOMENT_CURVE_H_
