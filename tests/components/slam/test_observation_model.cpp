// Tests of the range-bearing observation model: Jacobians against numeric
// differentiation, bearing wrapping, the inverse model, the landmark EKF update
// against hand-computed numbers and the observation likelihood against an
// independently written bivariate normal density.

#include <cmath>
#include <random>

#include <Eigen/Core>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "pixyslam/slam/observation_model.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Observation h(pose, landmark) as a plain vector.
Eigen::Vector2d h(const Pose2& pose, const Eigen::Vector2d& lm) { return predict_observation(pose, lm).z; }

// Central difference of h; the bearing difference is wrapped so that a bearing
// near +-pi that crosses the cut does not produce a 2 pi jump.
Eigen::Vector2d central_diff(const Eigen::Vector2d& plus, const Eigen::Vector2d& minus, double step) {
  return Eigen::Vector2d((plus.x() - minus.x()) / (2.0 * step), wrap_angle(plus.y() - minus.y()) / (2.0 * step));
}

void expect_jacobians_match_numeric(const Pose2& pose, const Eigen::Vector2d& lm) {
  const PredictedObservation p = predict_observation(pose, lm);
  const double step = 1e-6;
  const double scale = 1.0 + 1.0 / (lm - pose.head<2>()).norm();  // bearing Jacobian grows as 1/r
  for (int j = 0; j < 3; ++j) {
    Pose2 plus = pose, minus = pose;
    plus(j) += step;
    minus(j) -= step;
    const Eigen::Vector2d numeric = central_diff(h(plus, lm), h(minus, lm), step);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(p.h_pose(i, j), numeric(i), 1e-6 * scale)
          << "h_pose(" << i << "," << j << ") pose " << pose.transpose() << " lm " << lm.transpose();
    }
  }
  for (int j = 0; j < 2; ++j) {
    Eigen::Vector2d plus = lm, minus = lm;
    plus(j) += step;
    minus(j) -= step;
    const Eigen::Vector2d numeric = central_diff(h(pose, plus), h(pose, minus), step);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(p.h_landmark(i, j), numeric(i), 1e-6 * scale)
          << "h_landmark(" << i << "," << j << ") pose " << pose.transpose() << " lm " << lm.transpose();
    }
  }
}

TEST(ObservationModel, PredictsRangeAndBearingOfSimpleGeometry) {
  // Robot at (1, 1) facing +y; landmark 2 m ahead and one 3 m to its right.
  const Pose2 pose(1.0, 1.0, kPi / 2);
  const Eigen::Vector2d ahead = h(pose, Eigen::Vector2d(1.0, 3.0));
  EXPECT_NEAR(ahead.x(), 2.0, 1e-12);
  EXPECT_NEAR(ahead.y(), 0.0, 1e-12);
  const Eigen::Vector2d right = h(pose, Eigen::Vector2d(4.0, 1.0));
  EXPECT_NEAR(right.x(), 3.0, 1e-12);
  EXPECT_NEAR(right.y(), -kPi / 2, 1e-12);
  // The predicted bearing is always wrapped: heading -3 rad, landmark at world angle +3 rad.
  const Pose2 p2(0.0, 0.0, -3.0);
  const Eigen::Vector2d z = h(p2, Eigen::Vector2d(std::cos(3.0), std::sin(3.0)));
  EXPECT_NEAR(z.y(), 6.0 - 2.0 * kPi, 1e-12);
}

TEST(ObservationModel, JacobiansMatchCentralDifferencesAtRandomPoses) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> pos(-10.0, 10.0);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  std::uniform_real_distribution<double> dist(0.3, 20.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Pose2 pose(pos(prng), pos(prng), ang(prng));
    const double phi = ang(prng);
    const double r = dist(prng);
    const Eigen::Vector2d lm = pose.head<2>() + r * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    expect_jacobians_match_numeric(pose, lm);
  }
}

TEST(ObservationModel, JacobiansMatchCentralDifferencesWithBearingNearPi) {
  // Landmarks (almost) straight behind the robot: the bearing is within 1e-7 of
  // +pi or -pi, so the finite-difference steps cross the wrap.
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose2 pose(0.5 * trial - 3.0, 2.0 - 0.1 * trial, ang(prng));
    for (const double offset : {-1e-7, 0.0, 1e-7, 1e-3, -1e-3}) {
      const double phi = pose.z() + kPi + offset;  // world angle of the landmark
      const Eigen::Vector2d lm = pose.head<2>() + 2.5 * Eigen::Vector2d(std::cos(phi), std::sin(phi));
      const Eigen::Vector2d z = h(pose, lm);
      EXPECT_NEAR(std::abs(z.y()), kPi, 1.1e-3);
      EXPECT_GT(z.y(), -kPi);
      EXPECT_LE(z.y(), kPi);
      expect_jacobians_match_numeric(pose, lm);
    }
  }
}

TEST(ObservationModel, JacobiansHaveTheDocumentedClosedForm) {
  // dx = 3, dy = 4, r = 5, q = 25.
  const PredictedObservation p = predict_observation(Pose2(1.0, 2.0, 0.3), Eigen::Vector2d(4.0, 6.0));
  EXPECT_NEAR(p.h_landmark(0, 0), 0.6, 1e-15);
  EXPECT_NEAR(p.h_landmark(0, 1), 0.8, 1e-15);
  EXPECT_NEAR(p.h_landmark(1, 0), -4.0 / 25.0, 1e-15);
  EXPECT_NEAR(p.h_landmark(1, 1), 3.0 / 25.0, 1e-15);
  EXPECT_NEAR(p.h_pose(0, 0), -0.6, 1e-15);
  EXPECT_NEAR(p.h_pose(0, 1), -0.8, 1e-15);
  EXPECT_NEAR(p.h_pose(0, 2), 0.0, 1e-15);
  EXPECT_NEAR(p.h_pose(1, 0), 4.0 / 25.0, 1e-15);
  EXPECT_NEAR(p.h_pose(1, 1), -3.0 / 25.0, 1e-15);
  EXPECT_NEAR(p.h_pose(1, 2), -1.0, 1e-15);
}

TEST(ObservationModel, InnovationWrapsTheBearing) {
  // Measured 3.1, predicted -3.1: the short way round is -(2 pi - 6.2).
  const Eigen::Vector2d nu = innovation(Eigen::Vector2d(2.0, 3.1), Eigen::Vector2d(1.5, -3.1));
  EXPECT_NEAR(nu.x(), 0.5, 1e-15);
  EXPECT_NEAR(nu.y(), 6.2 - 2.0 * kPi, 1e-12);
  const Eigen::Vector2d nu2 = innovation(Eigen::Vector2d(1.0, -3.0), Eigen::Vector2d(1.0, 3.0));
  EXPECT_NEAR(nu2.y(), 2.0 * kPi - 6.0, 1e-12);
  // Range is never wrapped.
  const Eigen::Vector2d nu3 = innovation(Eigen::Vector2d(10.0, 0.1), Eigen::Vector2d(1.0, 0.2));
  EXPECT_NEAR(nu3.x(), 9.0, 1e-15);
  EXPECT_NEAR(nu3.y(), -0.1, 1e-15);
}

TEST(ObservationModel, InitialiseLandmarkInvertsTheModel) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> pos(-5.0, 5.0);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  std::uniform_real_distribution<double> range(0.2, 15.0);
  std::uniform_real_distribution<double> sig(0.01, 0.3);
  for (int trial = 0; trial < 200; ++trial) {
    const Pose2 pose(pos(prng), pos(prng), ang(prng));
    const Eigen::Vector2d z(range(prng), ang(prng));
    const double sr = sig(prng), sb = 0.3 * sig(prng);
    Eigen::Matrix2d r;
    r << sr * sr, 0.0, 0.0, sb * sb;
    Eigen::Vector2d mean;
    Eigen::Matrix2d cov;
    initialise_landmark(pose, z, r, mean, cov);

    // Predicting the observation of the initialised mean returns z.
    const Eigen::Vector2d back = h(pose, mean);
    EXPECT_NEAR(back.x(), z.x(), 1e-9);
    EXPECT_NEAR(wrap_angle(back.y() - z.y()), 0.0, 1e-9);

    // G^-1 for range-bearing is [cos phi, -r sin phi; sin phi, r cos phi]
    // (phi = world bearing), written out here rather than inverted numerically.
    const double phi = pose.z() + z.y();
    const double c = std::cos(phi), s = std::sin(phi), rr = z.x();
    const double j00 = c, j01 = -rr * s, j10 = s, j11 = rr * c;
    const double r0 = r(0, 0), r1 = r(1, 1);
    const double e00 = j00 * j00 * r0 + j01 * j01 * r1;
    const double e01 = j00 * j10 * r0 + j01 * j11 * r1;
    const double e11 = j10 * j10 * r0 + j11 * j11 * r1;
    const double tol = 1e-9 * (1.0 + e00 + e11);
    EXPECT_NEAR(cov(0, 0), e00, tol);
    EXPECT_NEAR(cov(0, 1), e01, tol);
    EXPECT_NEAR(cov(1, 0), e01, tol);
    EXPECT_NEAR(cov(1, 1), e11, tol);
  }
}

TEST(ObservationModel, InitialiseLandmarkSimpleCase) {
  // Robot at (1, 2) facing +y sees a landmark 3 m away, 90 deg to its left:
  // the landmark is at (-2, 2); range variance lies along x, bearing along y.
  Eigen::Vector2d mean;
  Eigen::Matrix2d cov;
  Eigen::Matrix2d r;
  r << 0.01, 0.0, 0.0, 0.0004;
  initialise_landmark(Pose2(1.0, 2.0, kPi / 2), Eigen::Vector2d(3.0, kPi / 2), r, mean, cov);
  EXPECT_NEAR(mean.x(), -2.0, 1e-12);
  EXPECT_NEAR(mean.y(), 2.0, 1e-12);
  EXPECT_NEAR(cov(0, 0), 0.01, 1e-12);              // range variance
  EXPECT_NEAR(cov(1, 1), 9.0 * 0.0004, 1e-12);      // (r sigma_b)^2
  EXPECT_NEAR(cov(0, 1), 0.0, 1e-12);
}

TEST(ObservationModel, UpdateLandmarkHandComputedAlongX) {
  // Pose (0,0,0), prior mean (2,0), P = diag(0.04, 0.09), R = diag(0.01, 0.0025),
  // z = (2.1, 0.05).
  //   dx = 2, dy = 0, r = 2, q = 4  ->  G = [1 0; 0 0.5], z_hat = (2, 0), nu = (0.1, 0.05)
  //   S = G P G^T + R = diag(0.04 + 0.01, 0.25 * 0.09 + 0.0025) = diag(0.05, 0.025)
  //   K = P G^T S^-1 = diag(0.04 * 1 / 0.05, 0.09 * 0.5 / 0.025) = diag(0.8, 1.8)
  //   mean = (2 + 0.8 * 0.1, 0 + 1.8 * 0.05) = (2.08, 0.09)
  //   I - K G = diag(0.2, 0.1); Joseph: diag(0.2^2 * 0.04 + 0.8^2 * 0.01,
  //                                         0.1^2 * 0.09 + 1.8^2 * 0.0025) = diag(0.008, 0.009)
  const double k0 = 0.04 * 1.0 / (0.04 + 0.01);
  const double k1 = 0.09 * 0.5 / (0.25 * 0.09 + 0.0025);
  ASSERT_NEAR(k0, 0.8, 1e-15);
  ASSERT_NEAR(k1, 1.8, 1e-14);
  Eigen::Vector2d mean(2.0, 0.0);
  Eigen::Matrix2d cov;
  cov << 0.04, 0.0, 0.0, 0.09;
  Eigen::Matrix2d r;
  r << 0.01, 0.0, 0.0, 0.0025;
  update_landmark(Pose2(0.0, 0.0, 0.0), Eigen::Vector2d(2.1, 0.05), r, mean, cov);
  EXPECT_NEAR(mean.x(), 2.0 + k0 * 0.1, 1e-12);
  EXPECT_NEAR(mean.y(), 0.0 + k1 * 0.05, 1e-12);
  EXPECT_NEAR(mean.x(), 2.08, 1e-12);
  EXPECT_NEAR(mean.y(), 0.09, 1e-12);
  EXPECT_NEAR(cov(0, 0), 0.008, 1e-12);
  EXPECT_NEAR(cov(1, 1), 0.009, 1e-12);
  EXPECT_NEAR(cov(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(cov(1, 0), 0.0, 1e-12);
}

TEST(ObservationModel, UpdateLandmarkHandComputedRobotFacingY) {
  // Same numbers rotated: pose (1,1,pi/2), prior mean (1,3), P = diag(0.04, 0.09).
  //   dx = 0, dy = 2, r = 2, q = 4  ->  G = [0 1; -0.5 0], z_hat = (2, 0), nu = (0.1, 0.05)
  //   G P G^T = [0.09 0; 0 0.25*0.04] -> S = diag(0.1, 0.0125)
  //   P G^T = [0 -0.02; 0.09 0] -> K = [0 -0.02/0.0125; 0.09/0.1 0] = [0 -1.6; 0.9 0]
  //   mean = (1 - 1.6 * 0.05, 3 + 0.9 * 0.1) = (0.92, 3.09)  (positive bearing = robot's left = -x)
  //   K G = diag(0.8, 0.9) -> (I - K G) P = diag(0.2 * 0.04, 0.1 * 0.09) = diag(0.008, 0.009)
  Eigen::Vector2d mean(1.0, 3.0);
  Eigen::Matrix2d cov;
  cov << 0.04, 0.0, 0.0, 0.09;
  Eigen::Matrix2d r;
  r << 0.01, 0.0, 0.0, 0.0025;
  update_landmark(Pose2(1.0, 1.0, kPi / 2), Eigen::Vector2d(2.1, 0.05), r, mean, cov);
  EXPECT_NEAR(mean.x(), 0.92, 1e-12);
  EXPECT_NEAR(mean.y(), 3.09, 1e-12);
  EXPECT_NEAR(cov(0, 0), 0.008, 1e-12);
  EXPECT_NEAR(cov(1, 1), 0.009, 1e-12);
  EXPECT_NEAR(cov(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(cov(1, 0), 0.0, 1e-12);
}

TEST(ObservationModel, UpdateLandmarkWrapsBearingInnovation) {
  // Landmark straight behind: predicted bearing +pi, measured -pi + 0.02; the
  // innovation is +0.02 rad, a small correction, not a 2 pi one.
  Eigen::Vector2d mean(-2.0, 0.0);
  Eigen::Matrix2d cov;
  cov << 0.04, 0.0, 0.0, 0.04;
  Eigen::Matrix2d r;
  r << 0.01, 0.0, 0.0, 0.01;
  update_landmark(Pose2(0.0, 0.0, 0.0), Eigen::Vector2d(2.0, -kPi + 0.02), r, mean, cov);
  // World angle pi + 0.02: the landmark moves to y < 0, by less than 0.04 m.
  EXPECT_NEAR(mean.x(), -2.0, 1e-3);
  EXPECT_LT(mean.y(), 0.0);
  EXPECT_GT(mean.y(), -0.04);
}

// log N(nu; 0, S) for a 2x2 S written out with scalars.
double log_bivariate_normal(double nu0, double nu1, double a, double b, double d) {
  const double det = a * d - b * b;
  const double m2 = (d * nu0 * nu0 - 2.0 * b * nu0 * nu1 + a * nu1 * nu1) / det;
  return std::log(std::exp(-0.5 * m2) / (2.0 * kPi * std::sqrt(det)));
}

TEST(ObservationModel, FitObservationLogLikelihoodIsABivariateNormal) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    PoseGaussian g;
    g.mean = Pose2(2.0 * u(prng), 2.0 * u(prng), kPi * u(prng));
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a(i) = 0.1 * u(prng);
    g.cov = a * a.transpose() + 1e-4 * Eigen::Matrix3d::Identity();
    const Eigen::Vector2d lm = g.mean.head<2>() + Eigen::Vector2d(3.0 + u(prng), 3.0 * u(prng));
    Eigen::Matrix2d b;
    for (int i = 0; i < 4; ++i) b(i) = 0.1 * u(prng);
    const Eigen::Matrix2d p = b * b.transpose() + 1e-4 * Eigen::Matrix2d::Identity();
    Eigen::Matrix2d r;
    r << 0.0049, 0.0, 0.0, 0.027 * 0.027;
    const Eigen::Vector2d z = h(g.mean, lm) + Eigen::Vector2d(0.1 * u(prng), 0.05 * u(prng));

    const ObservationFit fit = fit_observation(g, lm, p, z, r);

    // Innovation and S from the documented formulas, Jacobians written out by hand.
    const double dx = lm.x() - g.mean.x(), dy = lm.y() - g.mean.y();
    const double q = dx * dx + dy * dy, rr = std::sqrt(q);
    Eigen::Matrix<double, 2, 3> hp;
    hp << -dx / rr, -dy / rr, 0.0, dy / q, -dx / q, -1.0;
    Eigen::Matrix2d hl;
    hl << dx / rr, dy / rr, -dy / q, dx / q;
    const Eigen::Matrix2d s = hp * g.cov * hp.transpose() + hl * p * hl.transpose() + r;
    const double nu0 = z.x() - rr;
    const double nu1 = wrap_angle(z.y() - (std::atan2(dy, dx) - g.mean.z()));
    EXPECT_NEAR(fit.innovation.x(), nu0, 1e-12);
    EXPECT_NEAR(fit.innovation.y(), nu1, 1e-12);
    EXPECT_TRUE(fit.h_pose.isApprox(hp, 1e-12));
    EXPECT_TRUE(fit.s.isApprox(s, 1e-12)) << fit.s << "\nvs\n" << s;

    const double expected = log_bivariate_normal(nu0, nu1, s(0, 0), s(0, 1), s(1, 1));
    EXPECT_NEAR(fit.log_likelihood, expected, 1e-9 * (1.0 + std::abs(expected)));
    const double det = s(0, 0) * s(1, 1) - s(0, 1) * s(0, 1);
    const double m2 = (s(1, 1) * nu0 * nu0 - 2.0 * s(0, 1) * nu0 * nu1 + s(0, 0) * nu1 * nu1) / det;
    EXPECT_NEAR(fit.mahalanobis2, m2, 1e-9 * (1.0 + m2));
  }
}

TEST(ObservationModel, FitObservationLikelihoodPeaksAtZeroInnovation) {
  // With S = diag(0.01, 0.0004) + pose terms zero, a perfect observation has
  // log density -log(2 pi) - 0.5 log(det S).
  PoseGaussian g;
  g.mean = Pose2(0.0, 0.0, 0.0);
  const Eigen::Vector2d lm(2.0, 0.0);
  Eigen::Matrix2d r;
  r << 0.01, 0.0, 0.0, 0.0004;
  const ObservationFit fit = fit_observation(g, lm, Eigen::Matrix2d::Zero(), Eigen::Vector2d(2.0, 0.0), r);
  EXPECT_NEAR(fit.mahalanobis2, 0.0, 1e-15);
  EXPECT_NEAR(fit.log_likelihood, -std::log(2.0 * kPi) - 0.5 * std::log(0.01 * 0.0004), 1e-12);
  // One sigma off in range costs exactly 0.5.
  const ObservationFit off = fit_observation(g, lm, Eigen::Matrix2d::Zero(), Eigen::Vector2d(2.1, 0.0), r);
  EXPECT_NEAR(off.mahalanobis2, 1.0, 1e-12);
  EXPECT_NEAR(fit.log_likelihood - off.log_likelihood, 0.5, 1e-12);
}

}  // namespace
}  // namespace pixyslam::slam
