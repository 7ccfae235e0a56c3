// Tests of the unicycle motion model: exact motions, the quarter-circle limit,
// and the propagated covariance against Monte Carlo sampling.

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(MotionModel, StraightLine) {
  const Pose2 a = move(Pose2(1.0, 2.0, 0.0), 0.5, 0.0, 2.0);
  EXPECT_NEAR(a.x(), 2.0, 1e-15);
  EXPECT_NEAR(a.y(), 2.0, 1e-15);
  EXPECT_NEAR(a.z(), 0.0, 1e-15);
  // Heading 60 deg: 3 m along (cos 60, sin 60).
  const Pose2 b = move(Pose2(0.0, 0.0, kPi / 3), 1.5, 0.0, 2.0);
  EXPECT_NEAR(b.x(), 1.5, 1e-12);
  EXPECT_NEAR(b.y(), 3.0 * std::sqrt(3.0) / 2.0, 1e-12);
  EXPECT_NEAR(b.z(), kPi / 3, 1e-15);
  // Driving backwards.
  const Pose2 c = move(Pose2(0.0, 0.0, kPi / 2), -1.0, 0.0, 1.0);
  EXPECT_NEAR(c.x(), 0.0, 1e-12);
  EXPECT_NEAR(c.y(), -1.0, 1e-12);
}

TEST(MotionModel, PureRotationAndWrap) {
  const Pose2 a = move(Pose2(1.0, -1.0, 0.2), 0.0, 0.5, 1.0);
  EXPECT_DOUBLE_EQ(a.x(), 1.0);
  EXPECT_DOUBLE_EQ(a.y(), -1.0);
  EXPECT_NEAR(a.z(), 0.7, 1e-15);
  // 3 + 0.5 = 3.5 rad wraps to 3.5 - 2 pi.
  const Pose2 b = move(Pose2(0.0, 0.0, 3.0), 0.0, 1.0, 0.5);
  EXPECT_NEAR(b.z(), 3.5 - 2.0 * kPi, 1e-12);
  const Pose2 c = move(Pose2(0.0, 0.0, -3.0), 0.0, -1.0, 0.5);
  EXPECT_NEAR(c.z(), 2.0 * kPi - 3.5, 1e-12);
}

TEST(MotionModel, SingleStepUsesTheMidpointHeading) {
  // d = 1, a = 0.4: x += cos(0.2), y += sin(0.2).
  const Pose2 p = move(Pose2(0.0, 0.0, 0.0), 0.5, 0.2, 2.0);
  EXPECT_NEAR(p.x(), std::cos(0.2), 1e-15);
  EXPECT_NEAR(p.y(), std::sin(0.2), 1e-15);
  EXPECT_NEAR(p.z(), 0.4, 1e-15);
}

// Drives the quarter circle of radius v/w = 0.5 m in `steps` steps.
Pose2 quarter_circle(int steps) {
  const double v = 0.2, w = 0.4;
  const double total = (kPi / 2) / w;
  Pose2 p(0.0, 0.0, 0.0);
  for (int i = 0; i < steps; ++i) p = move(p, v, w, total / steps);
  return p;
}

TEST(MotionModel, QuarterCircleApproachesTheExactArc) {
  // Exact end of a left quarter circle of radius 0.5 from the origin heading +x:
  // (0.5, 0.5), heading pi/2.
  const Pose2 coarse = quarter_circle(10);
  const Pose2 fine = quarter_circle(10000);
  const double err_coarse = std::hypot(coarse.x() - 0.5, coarse.y() - 0.5);
  const double err_fine = std::hypot(fine.x() - 0.5, fine.y() - 0.5);
  EXPECT_LT(err_fine, 1e-7);
  EXPECT_NEAR(fine.z(), kPi / 2, 1e-12);
  // The midpoint rule converges (second order): the fine error is far smaller.
  EXPECT_LT(err_fine, 1e-4 * err_coarse + 1e-12);
  // Even 10 steps are close (midpoint chords fall short by O(a^2)).
  EXPECT_LT(err_coarse, 5e-3);
}

TEST(MotionModel, PropagateMeanEqualsMove) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const MotionNoise noise{0.05, 0.1, 0.02, 0.03};
  for (int trial = 0; trial < 100; ++trial) {
    PoseGaussian g;
    g.mean = Pose2(5.0 * u(prng), 5.0 * u(prng), kPi * u(prng));
    g.cov = Eigen::Matrix3d::Identity() * 0.01;
    const double v = u(prng), w = 2.0 * u(prng), dt = 0.5 * (1.0 + u(prng)) + 1e-3;
    const Pose2 expected = move(g.mean, v, w, dt);
    propagate(g, v, w, dt, noise);
    EXPECT_NEAR(g.mean.x(), expected.x(), 1e-14);
    EXPECT_NEAR(g.mean.y(), expected.y(), 1e-14);
    EXPECT_NEAR(wrap_angle(g.mean.z() - expected.z()), 0.0, 1e-14);
    EXPECT_GT(g.mean.z(), -kPi);
    EXPECT_LE(g.mean.z(), kPi);
  }
}

Eigen::Matrix3d sample_cov(const std::vector<Eigen::Vector3d>& xs) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : xs) mean += x;
  mean /= static_cast<double>(xs.size());
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (const auto& x : xs) c += (x - mean) * (x - mean).transpose();
  return c / static_cast<double>(xs.size() - 1);
}

// Monte Carlo: initial pose ~ N(mean0, cov0), distance ~ N(v dt, var_d),
// rotation ~ N(w dt, var_a), pushed through move(); returns the sample covariance
// of (x, y, theta), theta unwrapped around the nominal end heading.
Eigen::Matrix3d monte_carlo_cov(const PoseGaussian& g0, double v, double w, double dt, double var_d,
                                double var_a, int samples, std::mt19937& prng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Matrix3d l = g0.cov.llt().matrixL();
  const Pose2 nominal = move(g0.mean, v, w, dt);
  std::vector<Eigen::Vector3d> xs;
  xs.reserve(samples);
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector3d e(n01(prng), n01(prng), n01(prng));
    const Pose2 start = g0.mean + l * e;
    const double d = v * dt + std::sqrt(var_d) * n01(prng);
    const double a = w * dt + std::sqrt(var_a) * n01(prng);
    Pose2 end = move(start, d / dt, a / dt, dt);
    end.z() = nominal.z() + wrap_angle(end.z() - nominal.z());
    xs.push_back(end);
  }
  return sample_cov(xs);
}

void expect_cov_close(const Eigen::Matrix3d& actual, const Eigen::Matrix3d& expected, double rel) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double scale = std::sqrt(expected(i, i) * expected(j, j));
      EXPECT_NEAR(actual(i, j), expected(i, j), rel * scale)
          << "(" << i << "," << j << ")\nactual\n" << actual << "\nMonte Carlo\n" << expected;
    }
  }
}

TEST(MotionModel, PropagatedCovarianceMatchesMonteCarloFromAPoint) {
  // Given a known start pose, the covariance is V diag(var_d, var_a) V^T only.
  std::mt19937 prng(42);
  const MotionNoise noise{0.1, 0.08, 0.0, 0.0};
  const double v = 1.0, w = 0.5, dt = 1.0;
  PoseGaussian g;
  g.mean = Pose2(0.3, -0.2, 0.7);
  g.cov = Eigen::Matrix3d::Identity() * 1e-14;  // (Monte Carlo needs a Cholesky factor)
  const PoseGaussian g0 = g;
  propagate(g, v, w, dt, noise);
  const double var_d = 0.1 * 0.1 * dt, var_a = 0.08 * 0.08 * dt;
  const Eigen::Matrix3d mc = monte_carlo_cov(g0, v, w, dt, var_d, var_a, 200000, prng);
  expect_cov_close(g.cov, mc, 0.03);
  // Rotation variance adds exactly.
  EXPECT_NEAR(g.cov(2, 2), var_a + 1e-14, 1e-15);
}

TEST(MotionModel, PropagatedCovarianceMatchesMonteCarloWithPriorAndDistanceNoise) {
  // Given a correlated prior and all the noise terms, the linearised
  // F cov F^T + V Q V^T matches the sampled covariance within a few percent
  // (noise kept small enough that linearisation error is well below that).
  std::mt19937 prng(42);
  MotionNoise noise{0.06, 0.05, 0.05, 0.04};
  noise.rotation_sigma_per_sqrt_rad = 0.03;
  const double v = 0.8, w = -0.6, dt = 1.5;
  PoseGaussian g;
  g.mean = Pose2(1.0, 2.0, -2.5);
  g.cov << 0.004, 0.001, 0.0005,
           0.001, 0.003, -0.0004,
           0.0005, -0.0004, 0.0025;
  const PoseGaussian g0 = g;
  propagate(g, v, w, dt, noise);
  const double dist = std::abs(v * dt);
  const double var_d = 0.06 * 0.06 * dt + 0.05 * 0.05 * dist;
  const double var_a = 0.05 * 0.05 * dt + 0.04 * 0.04 * dist + 0.03 * 0.03 * std::abs(w * dt);
  const Eigen::Matrix3d mc = monte_carlo_cov(g0, v, w, dt, var_d, var_a, 200000, prng);
  expect_cov_close(g.cov, mc, 0.03);
}

TEST(MotionModel, CovarianceStaysSymmetricPositiveSemiDefinite) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const MotionNoise noise{0.01, 0.03, 0.02, 0.01};
  PoseGaussian g;
  for (int step = 0; step < 2000; ++step) {
    propagate(g, 0.5 * u(prng), 1.5 * u(prng), 0.1 * (1.0 + u(prng)), noise);
    ASSERT_TRUE(g.cov.allFinite());
    const double scale = g.cov.cwiseAbs().maxCoeff();
    ASSERT_LE((g.cov - g.cov.transpose()).cwiseAbs().maxCoeff(), 1e-12 * scale) << "step " << step;
    const Eigen::Vector3d eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(g.cov).eigenvalues();
    ASSERT_GE(eig.minCoeff(), -1e-12 * scale) << "step " << step;
  }
  // Noise accumulates: heading variance is at least the sum of w_sigma^2 dt.
  EXPECT_GT(g.cov(2, 2), 0.0);
}

TEST(MotionModel, RotationNoiseScalesWithTheTurnedAngle) {
  // Pure rotation by a = w dt from a known pose: heading variance is
  // w_sigma^2 dt + rotation_sigma^2 |a|, for left and right turns alike.
  MotionNoise noise{0.0, 0.1, 0.0, 0.0};
  noise.rotation_sigma_per_sqrt_rad = 0.2;
  for (const double w : {0.8, -0.8}) {
    PoseGaussian g;
    propagate(g, 0.0, w, 2.0, noise);
    EXPECT_NEAR(g.cov(2, 2), 0.01 * 2.0 + 0.04 * 1.6, 1e-15) << "w " << w;
  }
}

TEST(MotionModel, NonPositiveDtDoesNothing) {
  const MotionNoise noise{0.1, 0.1, 0.1, 0.1};
  PoseGaussian g;
  g.mean = Pose2(1.0, 2.0, 0.5);
  g.cov << 0.04, 0.01, 0.0, 0.01, 0.05, 0.002, 0.0, 0.002, 0.01;
  const PoseGaussian before = g;
  propagate(g, 1.0, 0.5, 0.0, noise);
  EXPECT_EQ(g.mean, before.mean);
  EXPECT_EQ(g.cov, before.cov);
  propagate(g, 1.0, 0.5, -0.3, noise);
  EXPECT_EQ(g.mean, before.mean);
  EXPECT_EQ(g.cov, before.cov);
}

TEST(MotionModel, StandingStillAddsOnlyTimeNoise) {
  // v = w = 0 for dt: position variance grows by v_sigma^2 dt along the heading,
  // heading variance by w_sigma^2 dt; the distance and rotation terms add nothing.
  MotionNoise noise{0.1, 0.2, 5.0, 5.0};
  noise.rotation_sigma_per_sqrt_rad = 5.0;
  PoseGaussian g;
  g.mean = Pose2(0.0, 0.0, 0.0);
  propagate(g, 0.0, 0.0, 2.0, noise);
  EXPECT_NEAR(g.cov(0, 0), 0.01 * 2.0, 1e-15);
  EXPECT_NEAR(g.cov(1, 1), 0.0, 1e-15);
  EXPECT_NEAR(g.cov(2, 2), 0.04 * 2.0, 1e-15);
  EXPECT_EQ(g.mean, Pose2(0.0, 0.0, 0.0));
}

// The composed motion is propagate() step by step, rotated into any heading.
TEST(ComposedMotion, EqualsStepByStepPropagationFromAnyPose) {
  MotionNoise noise;
  noise.v_sigma_m_per_sqrt_s = 0.02;
  noise.w_sigma_rad_per_sqrt_s = 0.05;
  noise.rotation_sigma_per_sqrt_rad = 0.1;
  noise.distance_sigma_per_sqrt_m = 0.03;
  std::mt19937_64 prng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ComposedMotion composed;
  std::vector<std::array<double, 3>> steps;
  for (int k = 0; k < 40; ++k) {
    steps.push_back({0.4 * u(prng), 1.2 * u(prng), 0.015 * (2.0 + u(prng))});
    composed.add(steps.back()[0], steps.back()[1], steps.back()[2], noise);
  }
  for (const double heading : {0.0, 1.0, -2.5, 3.1}) {
    PoseGaussian stepwise{Pose2(1.5, -0.7, heading), Eigen::Matrix3d::Zero()};
    stepwise.cov << 0.04, 0.01, 0.002, 0.01, 0.09, -0.003, 0.002, -0.003, 0.01;
    PoseGaussian at_once = stepwise;
    for (const auto& s : steps) propagate(stepwise, s[0], s[1], s[2], noise);
    composed.apply(at_once);
    EXPECT_LT((at_once.mean.head<2>() - stepwise.mean.head<2>()).norm(), 1e-12) << heading;
    EXPECT_NEAR(wrap_angle(at_once.mean.z() - stepwise.mean.z()), 0.0, 1e-12) << heading;
    EXPECT_LT((at_once.cov - stepwise.cov).norm(), 1e-12) << heading << "\n" << at_once.cov << "\n" << stepwise.cov;
  }
  // The weighted sum of the rotated noise from the sums of cos, sin and their products.
  const std::vector<double> headings = {0.3, -1.2, 2.9}, weights = {0.5, 0.2, 0.3};
  Eigen::Matrix3d direct = Eigen::Matrix3d::Zero();
  double c = 0, s = 0, cc = 0, ss = 0, cs = 0;
  for (std::size_t i = 0; i < headings.size(); ++i) {
    const double ci = std::cos(headings[i]), si = std::sin(headings[i]);
    direct += weights[i] * composed.noise(ci, si);
    c += weights[i] * ci;
    s += weights[i] * si;
    cc += weights[i] * ci * ci;
    ss += weights[i] * si * si;
    cs += weights[i] * ci * si;
  }
  EXPECT_LT((composed.mean_noise(c, s, cc, ss, cs) - direct).norm(), 1e-15);
  composed.clear();
  EXPECT_TRUE(composed.empty());
}

}  // namespace
}  // namespace pixyslam::slam
