#include "textile/fit/synthetic_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

constexpr double kRho = 0.2;        // 200 g/m² [kg/m²]
constexpr double kOverhang = 0.06;  // [m]
const BendingLaw kFig8 = BendingLaw::FromKes(0.1, 0.0892, -0.0092);

TEST(SyntheticProfile, NoiseFreeMatchesElastica) {
  SyntheticOptions o;
  o.num_points = 41;
  const Profile p = SyntheticProfile(kFig8, kRho, kOverhang, o);
  ElasticaOptions e;
  e.num_samples = 41;
  const ElasticaProfile strip = SolveHeavyElastica(kFig8, kRho, kOverhang, e);
  ASSERT_TRUE(strip.converged) << strip.message;
  ASSERT_EQ(p.size(), 41u);
  // Same solver, same samples: only the rounding of i·L/(n-1) may differ.
  const double kSameSolveTol = 1e-12;  // [m]
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(p.s[i], strip.s[i], kSameSolveTol);
    EXPECT_NEAR(p.x[i], strip.x[i], kSameSolveTol);
    EXPECT_NEAR(p.y[i], strip.y[i], kSameSolveTol);
  }
  EXPECT_EQ(p.s.front(), 0.0);
  EXPECT_EQ(p.s.back(), kOverhang);
  EXPECT_NE(p.source.find("synthetic"), std::string::npos);
  EXPECT_NO_THROW(CheckProfile(p));
}

TEST(SyntheticProfile, DeterministicForASeedDifferentAcrossSeeds) {
  SyntheticOptions o;
  o.noise_sigma = 1e-4;
  o.arc_jitter = 0.3;
  const Profile a = SyntheticProfile(kFig8, kRho, kOverhang, o);
  const Profile b = SyntheticProfile(kFig8, kRho, kOverhang, o);
  o.seed += 1;
  const Profile c = SyntheticProfile(kFig8, kRho, kOverhang, o);
  EXPECT_EQ(a.x, b.x);  // bit for bit
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.s, b.s);
  EXPECT_NE(a.x, c.x);
  EXPECT_NE(a.s, c.s);  // the jitter too depends on the seed
}

TEST(SyntheticProfile, NoiseHasTheRequestedSigma) {
  // 2000 points give 4000 noise samples: the sample standard deviation is within
  // 3 / sqrt(2 · 4000) ≈ 3.4 % of σ with probability 0.997; the mean within 3 σ / sqrt(4000).
  const int n = 2000;
  const double sigma = 1e-4;
  SyntheticOptions o;
  o.num_points = n;
  const Profile clean = SyntheticProfile(kFig8, kRho, kOverhang, o);
  o.noise_sigma = sigma;
  const Profile noisy = SyntheticProfile(kFig8, kRho, kOverhang, o);
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    for (double d : {noisy.x[i] - clean.x[i], noisy.y[i] - clean.y[i]}) {
      sum += d;
      sum_sq += d * d;
    }
  }
  const double mean = sum / (2 * n);
  const double sd = std::sqrt(sum_sq / (2 * n) - mean * mean);
  EXPECT_NEAR(sd, sigma, 3.0 / std::sqrt(4.0 * n) * sigma);
  EXPECT_NEAR(mean, 0.0, 3.0 * sigma / std::sqrt(2.0 * n));
  EXPECT_EQ(noisy.s, clean.s);  // exact arc lengths unless asked otherwise
  EXPECT_NO_THROW(CheckProfile(noisy));
}

TEST(SyntheticProfile, OffsetThenRotationAboutTheEdge) {
  SyntheticOptions o;
  o.num_points = 21;
  const Profile clean = SyntheticProfile(kFig8, kRho, kOverhang, o);
  o.vertical_offset = 0.25e-3;
  o.rotation = 0.03;
  const Profile moved = SyntheticProfile(kFig8, kRho, kOverhang, o);
  const double kTol = 1e-15;  // one rotation in double precision [m]
  const double c = std::cos(o.rotation), s = std::sin(o.rotation);
  for (size_t i = 0; i < clean.size(); ++i) {
    const double y = clean.y[i] + o.vertical_offset;
    EXPECT_NEAR(moved.x[i], c * clean.x[i] - s * y, kTol);
    EXPECT_NEAR(moved.y[i], s * clean.x[i] + c * y, kTol);
  }
  // The first point is the edge lifted by t/2, turned with the rig.
  EXPECT_NEAR(moved.x[0], -s * o.vertical_offset, kTol);
  EXPECT_NEAR(moved.y[0], c * o.vertical_offset, kTol);
  // A rigid motion keeps distances between points.
  for (size_t i = 1; i < clean.size(); ++i) {
    EXPECT_NEAR(std::hypot(moved.x[i] - moved.x[i - 1], moved.y[i] - moved.y[i - 1]),
                std::hypot(clean.x[i] - clean.x[i - 1], clean.y[i] - clean.y[i - 1]), 1e-15);
  }
  EXPECT_NO_THROW(CheckProfile(moved));
}

TEST(SyntheticProfile, ChordArcLengthIsCumulativeAndNoiseLengthensIt) {
  SyntheticOptions o;
  o.chord_arc_length = true;
  const Profile clean = SyntheticProfile(kFig8, kRho, kOverhang, o);
  // Chords of a curve are shorter than its arcs: by ~ L h² κ² / 24, well under 1e-4 L here.
  EXPECT_LT(clean.s.back(), kOverhang);
  EXPECT_GT(clean.s.back(), kOverhang * (1.0 - 1e-4));
  o.noise_sigma = 1e-4;
  const Profile noisy = SyntheticProfile(kFig8, kRho, kOverhang, o);
  EXPECT_EQ(noisy.s.front(), 0.0);
  EXPECT_GT(noisy.s.back(), kOverhang);  // noise adds zig-zag to the chords
  for (size_t i = 1; i < noisy.size(); ++i) {
    EXPECT_NEAR(noisy.s[i] - noisy.s[i - 1],
                std::hypot(noisy.x[i] - noisy.x[i - 1], noisy.y[i] - noisy.y[i - 1]), 1e-15);
  }
  EXPECT_NO_THROW(CheckProfile(noisy));
}

TEST(SyntheticProfile, JitterKeepsEndsAndOrder) {
  SyntheticOptions o;
  o.arc_jitter = 0.45;
  const Profile p = SyntheticProfile(kFig8, kRho, kOverhang, o);
  EXPECT_EQ(p.s.front(), 0.0);
  EXPECT_EQ(p.s.back(), kOverhang);
  EXPECT_NO_THROW(CheckProfile(p));  // includes strictly increasing s
}

TEST(SyntheticProfile, RejectsBadOptions) {
  SyntheticOptions o;
  o.num_points = 3;
  try {
    SyntheticProfile(kFig8, kRho, kOverhang, o);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("num_points"), std::string::npos) << e.what();
  }
  o = {};
  o.noise_sigma = -1.0;
  EXPECT_THROW(SyntheticProfile(kFig8, kRho, kOverhang, o), InputError);
  o = {};
  o.arc_jitter = 0.5;
  EXPECT_THROW(SyntheticProfile(kFig8, kRho, kOverhang, o), InputError);
  EXPECT_THROW(SyntheticProfile(kFig8, kRho, -0.01, {}), InputError);
}

}  // namespace
}  // namespace textile
