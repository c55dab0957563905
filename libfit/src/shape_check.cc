#include "textile/fit/shape_check.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "textile/fit/direct_fit.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

// Thinning: every k-th point, the last always kept, so that the check costs the same for a
// 12 MP and a 50 MP photo.
constexpr size_t kMaxPoints = 120;
// Any density: the shape depends on M/ρ only.
constexpr double kAnyDensity = 0.2;  // [kg/m²]

Profile Thinned(const Profile& p) {
  if (p.size() <= kMaxPoints) return p;
  Profile out;
  out.source = p.source;
  const double step = static_cast<double>(p.size() - 1) / (kMaxPoints - 1);
  for (size_t k = 0; k < kMaxPoints; ++k) {
    const size_t i = std::min(p.size() - 1, static_cast<size_t>(std::llround(k * step)));
    if (!out.s.empty() && p.s[i] <= out.s.back()) continue;
    out.s.push_back(p.s[i]);
    out.x.push_back(p.x[i]);
    out.y.push_back(p.y[i]);
  }
  return out;
}

std::string Mm(double m) {
  std::ostringstream s;
  s.precision(3);
  s << m * 1e3 << " mm";
  return s.str();
}

}  // namespace

ShapeCheck CheckCantileverShape(const Profile& profile) {
  CheckProfile(profile);
  const Profile p = Thinned(profile);
  ShapeCheck out;
  out.points = static_cast<int>(p.size());
  DirectFitSummary fit;
  try {
    fit = FitDirect({p}, kAnyDensity);
  } catch (const InputError& e) {
    fit.message = e.what();
  }
  out.converged = fit.converged;
  if (!fit.converged) {
    out.message = "no heavy cantilever fits this profile (" + fit.message + ")";
    return out;
  }
  out.rms = fit.rms;
  out.max = fit.profiles.front().max;
  out.pattern = fit.fit_pattern;
  out.plausible = fit.rms <= kShapeCheckMaxRms;
  out.message = out.plausible
                    ? "the best heavy cantilever lies within " + Mm(fit.rms) + " rms (max " +
                          Mm(out.max) + ") of the profile"
                    : "the profile is no heavy cantilever within " + Mm(kShapeCheckMaxRms) +
                          ": the best one lies " + Mm(fit.rms) + " rms (max " + Mm(out.max) +
                          ") from it; a part lying on the platform, a wrong tip or a trace "
                          "that followed a shadow?";
  return out;
}

}  // namespace textile
