#include "textile/sim/law/input_influence.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

// A seam's uncertainty when its file carries no covariance (Table 2 gives none) [relative].
constexpr double kSeamDefaultUncertainty = 0.1;

}  // namespace

ParameterInfluence SceneInfluence(const std::string& name, double value, double display,
                                  const std::string& unit, double d_q_d_p, double uncertainty,
                                  const std::string& source) {
  ParameterInfluence row;
  row.parameter = name;
  row.value = value * display;
  row.unit = unit;
  row.d_q_d_p = d_q_d_p;
  row.d_q_d_ln_p = value * d_q_d_p;
  row.uncertainty_ln = value != 0.0 ? uncertainty / std::abs(value)
                                    : std::numeric_limits<double>::quiet_NaN();
  row.uncertainty_source = source;
  row.change = std::abs(d_q_d_p) * uncertainty;
  return row;
}

SeamProfile SteppedSeamProfile(const SeamProfile& profile, int k, double t) {
  SeamProfile stepped = profile;
  stepped.type = "fitted";
  stepped.coefficients_mm.at(static_cast<size_t>(k)) += t;
  return stepped;
}

double SeamCoefficientStep(const SeamProfile& profile, int k, double relative) {
  return relative * std::max(1.0, std::abs(profile.StiffnessFactor(0.0))) /
         std::pow(profile.influence_mm, 2 - k);
}

namespace {

// How S fades beyond d_max (SeamProfile::Multiplier), from the multiplier itself with
// e0 = S(d_max) − 1 and g the fade times its slope there (a backward difference over 0.1 % of
// d_max: off by fade a2 δ, ~3e-3 for Table 2's): not at all (e0 = 0), by the cubic
// (3 e0 + g ≥ 0) or by the exponential. S jumps where a profile switches to or from the cubic;
// the exponential shrinks to none with e0.
enum class Fade { kNone, kCubic, kExponential };
Fade FadeOf(const SeamProfile& p) {
  const double d = p.influence_mm, delta = 1e-3 * d;
  const double e0 = p.Multiplier(d) - 1.0;
  if (e0 <= 0.0) return Fade::kNone;
  const double g = p.fade_mm * (p.Multiplier(d) - p.Multiplier(d - delta)) / delta;
  return 3.0 * e0 + g >= 0.0 ? Fade::kCubic : Fade::kExponential;
}

}  // namespace

void CheckSeamCoefficientSteps(const SeamProfile& profile, double relative) {
  const auto refuse = [](const std::string& why) {
    throw InputError("seam sensitivities: a difference step of the seam's coefficients " + why +
                     "; name the material's parameters (--sensitivity-params) to leave the "
                     "seam out");
  };
  const Fade fade = FadeOf(profile);
  for (int k = 0; k < kSeamCoefficients; ++k) {
    const double h = SeamCoefficientStep(profile, k, relative);
    for (const double t : {h, -h}) {
      const SeamProfile stepped = SteppedSeamProfile(profile, k, t);
      std::string why;
      if (!stepped.Check(&why)) refuse("leaves their bounds (" + why + ")");
      if ((FadeOf(stepped) == Fade::kCubic) != (fade == Fade::kCubic))
        refuse("switches the fade beyond the influence distance, where S jumps");
    }
  }
}

namespace {

// Coefficient k's uncertainty without a covariance: ±10 % of it, or where it is 0, the one
// that moves B_f by 10 % of B_f(0) at d_max (SeamCoefficientStep) [1/mm^(2-k)].
double DefaultSeamCoefficientUncertainty(const SeamProfile& profile, int k) {
  const double a = profile.coefficients_mm[static_cast<size_t>(k)];
  return a != 0.0 ? kSeamDefaultUncertainty * std::abs(a)
                  : SeamCoefficientStep(profile, k, kSeamDefaultUncertainty);
}

}  // namespace

std::vector<ParameterInfluence> SeamInfluences(const SeamProfile& profile,
                                               const std::vector<double>& d_q_d_a) {
  if (d_q_d_a.size() != kSeamCoefficients)
    throw InputError("seam influences: need one derivative a coefficient (a2, a1, a0)");
  static const std::array<const char*, kSeamCoefficients> kNames{"seam.a2", "seam.a1", "seam.a0"};
  static const std::array<const char*, kSeamCoefficients> kUnits{"1/mm²", "1/mm", "-"};
  const std::optional<Eigen::Matrix3d>& covariance = profile.covariance;
  std::vector<ParameterInfluence> rows;
  double d_scale = 0.0;
  for (int k = 0; k < kSeamCoefficients; ++k) {
    const size_t i = static_cast<size_t>(k);
    const double a = profile.coefficients_mm[i];
    const double sd = covariance ? std::sqrt(std::max(0.0, (*covariance)(k, k)))
                                 : DefaultSeamCoefficientUncertainty(profile, k);
    rows.push_back(SceneInfluence(
        kNames[i], a, 1.0, kUnits[i], d_q_d_a[i], sd,
        covariance ? "the seam's fit covariance"
                   : a != 0.0 ? "default: ±10 % (the seam carries no covariance)"
                              : "default: B_f ±10 % of B_f(0) at d_max (the seam carries no "
                                "covariance)"));
    d_scale += a * d_q_d_a[i];
  }
  ParameterInfluence scale = SceneInfluence("seam.scale", 1.0, 1.0, "-", d_scale,
                                            kSeamDefaultUncertainty,
                                            "default: B_f ±10 % as a whole");
  if (covariance) {  // the three together, with their correlations: √(gᵀ C g)
    const Eigen::Vector3d g(d_q_d_a[0], d_q_d_a[1], d_q_d_a[2]);
    scale.change = std::sqrt(std::max(0.0, g.dot(*covariance * g)));
    scale.uncertainty_ln = d_scale != 0.0 ? scale.change / std::abs(d_scale)
                                          : std::numeric_limits<double>::quiet_NaN();
    scale.uncertainty_source = "the seam's fit covariance, the three coefficients together";
  }
  rows.push_back(std::move(scale));
  return rows;
}

}  // namespace textile
