// Tests of weight normalisation, effective sample size and low-variance
// (systematic) resampling.

#include <cmath>
#include <cstddef>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/slam/resampling.h"

namespace pixyslam::slam {
namespace {

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

TEST(Resampling, NormalisedWeightsSumToOneAndKeepRatios) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-20.0, 5.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> logw(1 + trial * 7);
    for (double& l : logw) l = u(prng);
    const std::vector<double> w = normalised_weights(logw);
    ASSERT_EQ(w.size(), logw.size());
    EXPECT_NEAR(sum(w), 1.0, 1e-12);
    for (std::size_t i = 1; i < w.size(); ++i) {
      // w_i / w_0 = exp(l_i - l_0)
      EXPECT_NEAR(std::log(w[i]) - std::log(w[0]), logw[i] - logw[0], 1e-9);
    }
  }
}

TEST(Resampling, NormalisedWeightsSurviveVeryNegativeLogWeights) {
  // exp(-1e4) underflows to 0 for every particle; subtracting the maximum first
  // must still give finite weights proportional to exp(0), exp(-1), exp(-2).
  const std::vector<double> w = normalised_weights({-1e4, -1e4 - 1.0, -1e4 - 2.0});
  ASSERT_EQ(w.size(), 3u);
  for (double x : w) EXPECT_TRUE(std::isfinite(x));
  const double z = 1.0 + std::exp(-1.0) + std::exp(-2.0);
  EXPECT_NEAR(w[0], 1.0 / z, 1e-12);
  EXPECT_NEAR(w[1], std::exp(-1.0) / z, 1e-12);
  EXPECT_NEAR(w[2], std::exp(-2.0) / z, 1e-12);

  const std::vector<double> equal = normalised_weights(std::vector<double>(4, -1e4));
  for (double x : equal) EXPECT_NEAR(x, 0.25, 1e-15);

  // A hugely worse particle gets weight 0, not NaN.
  const std::vector<double> mixed = normalised_weights({0.0, -1e4, 0.0});
  EXPECT_NEAR(mixed[0], 0.5, 1e-15);
  EXPECT_EQ(mixed[1], 0.0);
  EXPECT_NEAR(mixed[2], 0.5, 1e-15);

  // Large positive log weights do not overflow.
  const std::vector<double> big = normalised_weights({1e4, 1e4});
  EXPECT_NEAR(big[0], 0.5, 1e-15);
  EXPECT_NEAR(big[1], 0.5, 1e-15);

  EXPECT_TRUE(normalised_weights({}).empty());
}

TEST(Resampling, EffectiveSampleSize) {
  for (const std::size_t n : {1u, 2u, 10u, 1000u}) {
    const std::vector<double> uniform(n, 1.0 / static_cast<double>(n));
    EXPECT_NEAR(effective_sample_size(uniform), static_cast<double>(n), 1e-9 * static_cast<double>(n));
    std::vector<double> one_hot(n, 0.0);
    one_hot[n / 2] = 1.0;
    EXPECT_DOUBLE_EQ(effective_sample_size(one_hot), 1.0);
  }
  // Two of four particles carry all the weight equally: N_eff = 2.
  EXPECT_NEAR(effective_sample_size({0.5, 0.0, 0.5, 0.0}), 2.0, 1e-12);
}

// Random normalised weights of a few shapes: smooth, spiky and sparse.
std::vector<double> random_weights(std::size_t n, int shape, std::mt19937& prng) {
  std::exponential_distribution<double> expo(1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> w(n);
  for (double& x : w) {
    x = expo(prng);
    if (shape == 1) x = std::pow(x, 6.0);         // a few dominant particles
    if (shape == 2 && u(prng) < 0.7) x = 0.0;     // many exact zeros
  }
  if (sum(w) == 0.0) w[0] = 1.0;
  const double s = sum(w);
  for (double& x : w) x /= s;
  return w;
}

std::vector<int> counts_of(const std::vector<std::size_t>& picks, std::size_t n) {
  std::vector<int> c(n, 0);
  for (std::size_t i : picks) ++c.at(i);
  return c;
}

TEST(Resampling, SystematicCopiesEachParticleFloorOrCeilOfNw) {
  std::mt19937 prng(42);
  std::mt19937_64 rng(42);
  for (const std::size_t n : {1u, 2u, 3u, 7u, 50u, 100u, 1000u}) {
    for (int shape = 0; shape < 3; ++shape) {
      for (int trial = 0; trial < 100; ++trial) {
        const std::vector<double> w = random_weights(n, shape, prng);
        const std::vector<std::size_t> picks = systematic_resample(w, rng);
        ASSERT_EQ(picks.size(), n);
        for (std::size_t k = 1; k < n; ++k) ASSERT_LE(picks[k - 1], picks[k]) << "indices must not decrease";
        const std::vector<int> c = counts_of(picks, n);
        for (std::size_t i = 0; i < n; ++i) {
          const double nw = static_cast<double>(n) * w[i];
          ASSERT_GE(c[i], std::floor(nw - 1e-9)) << "n " << n << " i " << i << " N w " << nw;
          ASSERT_LE(c[i], std::ceil(nw + 1e-9)) << "n " << n << " i " << i << " N w " << nw;
          if (w[i] == 0.0) {
            ASSERT_EQ(c[i], 0) << "a zero-weight particle was drawn";
          }
        }
      }
    }
  }
}

TEST(Resampling, SystematicWithUniformWeightsKeepsEveryParticleOnce) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 100; ++trial) {
    const std::vector<double> w(64, 1.0 / 64.0);
    const std::vector<std::size_t> picks = systematic_resample(w, rng);
    for (std::size_t k = 0; k < picks.size(); ++k) ASSERT_EQ(picks[k], k);
  }
}

TEST(Resampling, SystematicWithOneHotPicksOnlyThatParticle) {
  std::mt19937_64 rng(42);
  std::vector<double> w(20, 0.0);
  w[13] = 1.0;
  const std::vector<std::size_t> picks = systematic_resample(w, rng);
  for (std::size_t i : picks) EXPECT_EQ(i, 13u);
  w.assign(20, 0.0);
  w.back() = 1.0;
  for (std::size_t i : systematic_resample(w, rng)) EXPECT_EQ(i, 19u);
  w.assign(20, 0.0);
  w.front() = 1.0;
  for (std::size_t i : systematic_resample(w, rng)) EXPECT_EQ(i, 0u);
}

TEST(Resampling, SystematicIsUnbiased) {
  // Over many draws the mean count of particle i is N w_i.
  std::mt19937 prng(42);
  std::mt19937_64 rng(42);
  const std::size_t n = 10;
  const std::vector<double> w = random_weights(n, 0, prng);
  std::vector<double> mean_count(n, 0.0);
  const int draws = 20000;
  for (int d = 0; d < draws; ++d) {
    const std::vector<int> c = counts_of(systematic_resample(w, rng), n);
    for (std::size_t i = 0; i < n; ++i) mean_count[i] += c[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    mean_count[i] /= draws;
    // The count is floor or ceil of N w (variance <= 1/4): standard error < 0.004.
    EXPECT_NEAR(mean_count[i], static_cast<double>(n) * w[i], 0.02) << "particle " << i;
  }
}

TEST(Resampling, SystematicIsDeterministicGivenTheRngState) {
  std::mt19937 prng(42);
  const std::vector<double> w = random_weights(200, 1, prng);
  std::mt19937_64 a(7), b(7);
  EXPECT_EQ(systematic_resample(w, a), systematic_resample(w, b));
}

TEST(Resampling, SystematicRejectsEmptyWeights) {
  std::mt19937_64 rng(42);
  EXPECT_THROW(systematic_resample({}, rng), std::invalid_argument);
}

}  // namespace
}  // namespace pixyslam::slam
