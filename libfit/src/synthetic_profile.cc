#include "textile/fit/synthetic_profile.h"

#include <cmath>
#include <random>
#include <sstream>

#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {

bool SyntheticOptions::Check(std::string* why) const {
  std::ostringstream problem;
  if (num_points < kMinProfilePoints) {
    problem << "num_points must be >= " << kMinProfilePoints << ", got " << num_points;
  } else if (!(arc_jitter >= 0.0 && arc_jitter < 0.5)) {
    problem << "arc_jitter must be in [0, 0.5), got " << arc_jitter;
  } else if (!(noise_sigma >= 0.0) || !std::isfinite(noise_sigma)) {
    problem << "noise_sigma must be a finite length >= 0 [m], got " << noise_sigma;
  } else if (!std::isfinite(vertical_offset)) {
    problem << "vertical_offset must be finite [m], got " << vertical_offset;
  } else if (!(std::abs(rotation) <= 0.2)) {
    problem << "rotation must be within ±0.2 rad, got " << rotation;
  }
  if (why != nullptr) *why = problem.str();
  return problem.str().empty();
}

Profile SyntheticProfile(const BendingLaw& law, double areal_density, double overhang,
                         const SyntheticOptions& options) {
  if (std::string why; !options.Check(&why)) throw InputError("synthetic profile: " + why);
  if (!(overhang > 0.0) || !std::isfinite(overhang)) {
    throw InputError("synthetic profile: overhang must be a positive length [m]");
  }
  std::mt19937_64 rng(options.seed);

  // Sample arc lengths: uniform, interior points optionally jittered; both ends kept exact.
  const int n = options.num_points;
  const double spacing = overhang / (n - 1);
  ElasticaOptions elastica_options;
  elastica_options.rel_tol = options.elastica_rel_tol;
  elastica_options.arc_lengths.resize(n);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < n; ++i) {
    double s = spacing * i;
    if (i > 0 && i < n - 1 && options.arc_jitter > 0.0)
      s += options.arc_jitter * spacing * unit(rng);
    elastica_options.arc_lengths[i] = s;
  }
  elastica_options.arc_lengths.back() = overhang;

  const ElasticaProfile strip = SolveHeavyElastica(law, areal_density, overhang, elastica_options);
  if (!strip.converged) throw ComputeError("synthetic profile: elastica failed: " + strip.message);

  std::ostringstream source;
  source.precision(6);
  if (law.is_spline()) {
    source << "synthetic{spline law, " << law.knot_kappa().size()
           << " knots to kappa=" << units::SiCurvatureToKes(law.kappa0()) << " /cm; ";
  } else {
    source << "synthetic{b1=" << law.b1_kes() << ",b2=" << law.b2_kes() << ",c1=" << law.c1_kes()
           << " KES; ";
  }
  source << units::SiToGsm(areal_density) << " g/m2; L=" << units::MToMm(overhang)
         << " mm; sigma=" << units::MToMm(options.noise_sigma) << " mm; seed=" << options.seed
         << "}";
  Profile profile;
  profile.source = source.str();
  profile.s = strip.s;
  profile.x.resize(n);
  profile.y.resize(n);
  const double c = std::cos(options.rotation), sn = std::sin(options.rotation);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const double x = strip.x[i], y = strip.y[i] + options.vertical_offset;
    profile.x[i] = c * x - sn * y;
    profile.y[i] = sn * x + c * y;
    if (options.noise_sigma > 0.0) {
      profile.x[i] += options.noise_sigma * noise(rng);
      profile.y[i] += options.noise_sigma * noise(rng);
    }
  }
  if (options.chord_arc_length) {
    profile.s[0] = 0.0;
    for (int i = 1; i < n; ++i) {
      profile.s[i] = profile.s[i - 1] +
                     std::hypot(profile.x[i] - profile.x[i - 1], profile.y[i] - profile.y[i - 1]);
    }
  }
  return profile;
}

}  // namespace textile
