#include "textile/sim/law/monte_carlo.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/law/material_parameters.h"

namespace textile {
namespace {

// A square root L of the covariance (L Lᵀ = C), taken on the matrix scaled to a unit
// diagonal so that b's and c1's different sizes cost no precision; a negative round-off
// eigenvalue counts as 0.
Eigen::Matrix3d CovarianceRoot(const Eigen::Matrix3d& c) {
  const Eigen::Vector3d d = c.diagonal().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Vector3d inverse = d.unaryExpr([](double v) { return v > 0.0 ? 1.0 / v : 0.0; });
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(inverse.asDiagonal() * c *
                                                              inverse.asDiagonal());
  const Eigen::Vector3d root = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return d.asDiagonal() * eigen.eigenvectors() * root.asDiagonal();
}

// Standard normal draws by Box-Muller on the twister's raw output: the same numbers on every
// standard library (std::normal_distribution's algorithm is not specified).
class NormalDraws {
 public:
  explicit NormalDraws(unsigned seed) : engine_(seed) {}
  double Next() {
    if (spare_) {
      const double v = *spare_;
      spare_.reset();
      return v;
    }
    const double u1 = Uniform(), u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1)), a = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(a);
    return r * std::cos(a);
  }

 private:
  double Uniform() { return (static_cast<double>(engine_()) + 0.5) / 4294967296.0; }  // (0, 1)
  std::mt19937 engine_;
  std::optional<double> spare_;
};

// The material with the `bending` law's constants k [SI], or none when they make no valid law.
std::optional<Material> WithLawConstants(const Material& m, const Eigen::Vector3d& k) {
  if (!BendingLaw::Invalidity(k(0), k(1), k(2)).empty()) return std::nullopt;
  Material drawn = m;
  drawn.bending = BendingLaw::FromSi(k(0), k(1), k(2));
  if (std::string why; !drawn.Check(&why)) return std::nullopt;
  return drawn;
}

}  // namespace

CovarianceSamples SampleFitCovariance(const Material& m, int count, unsigned seed) {
  if (count < 2) throw InputError("Monte Carlo: need at least 2 samples, got " + std::to_string(count));
  std::string why;
  const std::optional<Eigen::Matrix3d> covariance = MaterialFitCovariance(m, &why);
  if (!covariance) throw InputError("Monte Carlo: " + why);
  if (m.bending.is_spline()) throw InputError("Monte Carlo: a spline law has no b1, b2, c1 to draw");
  const Eigen::Matrix3d root = CovarianceRoot(*covariance);
  const Eigen::Vector3d mean(m.bending.b1(), m.bending.b2(), m.bending.c1());
  NormalDraws normal(seed);
  CovarianceSamples s;
  const int max_draws = 20 * count;
  for (int draw = 0; static_cast<int>(s.materials.size()) < count; ++draw) {
    if (draw == max_draws)
      throw ComputeError("Monte Carlo: only " + std::to_string(s.materials.size()) + " of " +
                         std::to_string(max_draws) +
                         " draws from the fit's covariance make a valid law; the covariance "
                         "reaches far outside the law's range, so a sampled σ means little");
    Eigen::Vector3d z;
    for (int i = 0; i < 3; ++i) z(i) = normal.Next();
    if (std::optional<Material> drawn = WithLawConstants(m, mean + root * z))
      s.materials.push_back(std::move(*drawn));
    else
      ++s.rejected;
  }
  return s;
}

MonteCarloSpread SummariseMonteCarlo(const std::vector<double>& values, int rejected_draws,
                                     double linear_sigma) {
  MonteCarloSpread s;
  s.rejected_draws = rejected_draws;
  s.linear_sigma = linear_sigma;
  std::vector<double> ran;
  for (double v : values) {
    if (std::isfinite(v))
      ran.push_back(v);
    else
      ++s.failed;
  }
  s.samples = static_cast<int>(values.size());
  const double n = static_cast<double>(ran.size());
  if (ran.size() >= 2) {
    double sum = 0.0;
    for (double v : ran) sum += v;
    s.mean = sum / n;
    double squares = 0.0;
    for (double v : ran) squares += (v - s.mean) * (v - s.mean);
    s.sigma = std::sqrt(squares / (n - 1.0));
    s.sigma_relative_error = 1.0 / std::sqrt(2.0 * (n - 1.0));
    if (std::isfinite(linear_sigma) && linear_sigma > 0.0) s.ratio = s.sigma / linear_sigma;
  }
  std::string note;
  if (ran.size() < 2) {
    note = "no σ: fewer than 2 samples ran";
  } else if (std::isnan(s.ratio)) {
    note = "σ over " + std::to_string(ran.size()) + " samples (±" +
           NumberText(100.0 * s.sigma_relative_error, 2) + " % sampling error); no linear σ to compare";
  } else {
    // Within 20 %, the tolerance, where the sampling error can tell (2 sds ≤ 20 %: 51
    // samples or more); beyond 2 sds from 1, a difference at any size.
    const double off = std::abs(s.ratio - 1.0), two_sd = 2.0 * s.sigma_relative_error;
    const std::string verdict =
        off > std::max(0.2, two_sd) ? "the result is not linear over the covariance; trust the sampled σ"
        : two_sd <= 0.2             ? "the linear σ holds (within 20 %)"
                                    : "inconclusive: " + std::to_string(ran.size()) +
                                          " samples cannot tell a 20 % difference (51 can)";
    note = "σ over " + std::to_string(ran.size()) + " samples is " + NumberText(s.ratio, 3) +
           " × the linear σ (±" + NumberText(100.0 * s.sigma_relative_error, 2) +
           " % sampling error): " + verdict;
  }
  if (s.failed > 0)
    note += "; " + std::to_string(s.failed) + " of " + std::to_string(s.samples) +
            " samples failed and are left out";
  if (rejected_draws > 0)
    note += "; " + std::to_string(rejected_draws) +
            " draws made no valid law and were drawn again (the distribution is truncated)";
  s.note = note;
  return s;
}

nlohmann::json MonteCarloJson(const MonteCarloSpread& s, double to_unit, const std::string& unit) {
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"samples", s.samples},
          {"rejected_draws", s.rejected_draws},
          {"failed", s.failed},
          {"mean", number(s.mean * to_unit)},
          {"sigma", number(s.sigma * to_unit)},
          {"sigma_relative_error", number(s.sigma_relative_error)},
          {"linear_sigma", number(s.linear_sigma * to_unit)},
          {"ratio", number(s.ratio)},
          {"unit", unit},
          {"seconds", s.seconds},
          {"note", s.note}};
}

}  // namespace textile
