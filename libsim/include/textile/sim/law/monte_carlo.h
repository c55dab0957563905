#ifndef TEXTILE_SIM_LAW_MONTE_CARLO_H_
#define TEXTILE_SIM_LAW_MONTE_CARLO_H_

// A Monte Carlo check of a linear σ (docs/methods/sensitivity.md, "Monte Carlo"): materials
// drawn from the fit's covariance of the `bending` law's {b1, b2, c1}, each simulated, and the
// spread of the result beside the sensitivities' √(gᵀ C g):
//
//   const textile::CovarianceSamples draws = textile::SampleFitCovariance(m, 30, 1);
//   std::vector<double> q;
//   for (const textile::Material& s : draws.materials) q.push_back(Simulate(s));
//   const textile::MonteCarloSpread spread =
//       textile::SummariseMonteCarlo(q, draws.rejected, linear_sigma);

#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "textile/sim/law/material.h"

namespace textile {

// `count` materials whose `bending` law's {b1, b2, c1} are drawn from the normal distribution
// of the fit's covariance (MaterialFitCovariance) about the material's own, everything else
// unchanged. A draw that makes no valid law (e.g. κ0 < 0) is drawn again and counted in
// `rejected`: the samples are the distribution truncated to valid laws. Deterministic for a
// seed (a Mersenne twister and Box-Muller, the same on every platform).
// Throws InputError when count < 2 or the material carries no usable covariance (the reason
// MaterialFitCovariance gives), ComputeError when fewer than one draw in 20 makes a valid law.
struct CovarianceSamples {
  std::vector<Material> materials;
  int rejected = 0;
};
CovarianceSamples SampleFitCovariance(const Material& material, int count, unsigned seed);

// The spread of a scalar result Q over the samples.
struct MonteCarloSpread {
  int samples = 0;         // simulated
  int rejected_draws = 0;  // draws outside the valid laws, drawn again
  int failed = 0;          // samples whose simulation failed (NaN), left out
  double mean = std::numeric_limits<double>::quiet_NaN();
  double sigma = std::numeric_limits<double>::quiet_NaN();  // sample sd; NaN under 2 values
  // Its own 1-σ sampling error, relative: 1/√(2 (n − 1)) for n values.
  double sigma_relative_error = std::numeric_limits<double>::quiet_NaN();
  double linear_sigma = std::numeric_limits<double>::quiet_NaN();  // the sensitivities' σ
  double ratio = std::numeric_limits<double>::quiet_NaN();         // sigma / linear_sigma
  double seconds = 0.0;
  std::string note;  // how the two σ compare, and what was left out
};
// values: Q of each sample, NaN where its simulation failed; linear_sigma NaN when none.
MonteCarloSpread SummariseMonteCarlo(const std::vector<double>& values, int rejected_draws,
                                     double linear_sigma);

// The result files' `monte_carlo` object: {samples, rejected_draws, failed, mean, sigma,
// sigma_relative_error, linear_sigma, ratio, unit, seconds, note}, Q's figures times
// `to_unit` (1e3 for metres to mm), NaN as null.
nlohmann::json MonteCarloJson(const MonteCarloSpread& spread, double to_unit,
                              const std::string& unit);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_MONTE_CARLO_H_
