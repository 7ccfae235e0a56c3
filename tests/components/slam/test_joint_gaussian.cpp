// Tests of JointGaussian, the pose-and-landmarks Gaussian of delayed sampling:
// it agrees with the FastSLAM 2.0 proposal and landmark initialisation where
// they overlap, conditioning on a pose is exact, relative observations do not
// make the absolute heading observable (first-estimates Jacobians), and a loop
// closure moves the pose and the landmarks seen from it together.

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "pixyslam/slam/joint_gaussian.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/observation_model.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {
namespace {

PoseGaussian pose_gaussian(const Pose2& mean, const Eigen::Vector3d& variances) {
  PoseGaussian g;
  g.mean = mean;
  g.cov = variances.asDiagonal();
  g.cov(0, 1) = g.cov(1, 0) = 0.3 * std::sqrt(variances(0) * variances(1));
  return g;
}

Eigen::Matrix2d noise(double range_sigma, double bearing_sigma) {
  return Eigen::Vector2d(range_sigma * range_sigma, bearing_sigma * bearing_sigma).asDiagonal();
}

// An exact observation of `landmark` from `pose`.
Eigen::Vector2d observe(const Pose2& pose, const Eigen::Vector2d& landmark) {
  return predict_observation(pose, landmark).z;
}

// PackedSymmetric: the lower triangle column after column; a round trip
// through it gives the symmetric matrix back, a column segment is contiguous
// in the packed array, and growing keeps every entry and adds zeros.
TEST(PackedSymmetric, StoresTheLowerTriangleColumnByColumn) {
  Eigen::MatrixXd m(4, 4);
  m << 1, 2, 3, 4,
       2, 5, 6, 7,
       3, 6, 8, 9,
       4, 7, 9, 10;
  Eigen::MatrixXd upper_garbage = m;
  upper_garbage(0, 3) = 99.0;  // only the lower triangle is read
  PackedSymmetric p(upper_garbage);
  EXPECT_EQ(p.size(), 4);
  EXPECT_EQ(p.packed(), (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(p.full(), m);
  EXPECT_EQ(p(0, 3), 4.0);
  EXPECT_EQ(p(3, 0), 4.0);
  EXPECT_EQ(p.column(1, 2), Eigen::Vector2d(6, 7));
  EXPECT_EQ(p.diagonal_block<2>(2), (Eigen::Matrix2d() << 8, 9, 9, 10).finished());
  p.column(2, 2) *= 2.0;
  EXPECT_EQ(p.lower(3, 2), 18.0);
  p.grow(2);
  EXPECT_EQ(p.size(), 6);
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(6, 6);
  grown.topLeftCorner<4, 4>() = m;
  grown(2, 2) = 16.0;
  grown(3, 2) = grown(2, 3) = 18.0;
  EXPECT_EQ(p.full(), grown);
  p.clear();
  EXPECT_EQ(p.size(), 0);
}

// JointGaussian keeps its covariance packed (PackedSymmetric). A plain dense
// EKF over the same state, written out here with full matrices, must give the
// same covariance through every operation: motion (one step and composed),
// mapped and new landmarks, updates on pose and landmark blocks, and the
// frame's re-linearisation.
TEST(JointGaussian, PackedCovarianceMatchesADenseEkf) {
  std::mt19937_64 prng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  MotionNoise mn;
  mn.v_sigma_m_per_sqrt_s = 0.05;
  mn.w_sigma_rad_per_sqrt_s = 0.1;
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(0.5, -0.3, 0.4), Eigen::Vector3d(0.03, 0.02, 0.05)));
  Eigen::MatrixXd p = g.cov.full();
  const auto grow = [&](const Eigen::MatrixXd& cross, const Eigen::Matrix2d& block) {
    const Eigen::Index n = p.rows();
    Eigen::MatrixXd q(n + 2, n + 2);
    q << p, cross.transpose(), cross, block;
    p = q;
  };
  const auto expect_same = [&](const char* step) {
    ASSERT_EQ(g.cov.size(), p.rows()) << step;
    const double scale = p.cwiseAbs().maxCoeff();
    EXPECT_LE((g.cov.full() - p).cwiseAbs().maxCoeff(), 1e-12 * scale) << step;
    EXPECT_TRUE(g.pose().cov.isApprox(p.topLeftCorner<3, 3>(), 1e-12)) << step;
  };
  for (int frame = 0; frame < 6; ++frame) {
    // Motion: one step, then a composed run of steps.
    const Eigen::Vector3d before = g.mean.head<3>();
    const MotionStep step = motion_step(before, 0.3, 0.2, 0.1, mn);
    g.propagate(0.3, 0.2, 0.1, mn);
    Eigen::MatrixXd f = Eigen::MatrixXd::Identity(p.rows(), p.cols());
    f.topLeftCorner<3, 3>() = step.f;
    p = f * p * f.transpose();
    p.topLeftCorner<3, 3>() += step.q;
    expect_same("propagate");
    ComposedMotion motion;
    for (int k = 0; k < 5; ++k) motion.add(0.2 + 0.05 * k, -0.1 * k, 0.03, mn);
    const double c = std::cos(g.mean(2)), s = std::sin(g.mean(2));
    f.topLeftCorner<3, 3>() = motion.jacobian(c, s);
    g.apply_motion(motion);
    p = f * p * f.transpose();
    p.topLeftCorner<3, 3>() += motion.noise(c, s);
    expect_same("apply_motion");

    g.begin_frame();
    const Eigen::Vector3d frame_pose = g.mean.head<3>();
    // A mapped landmark, independent of the state.
    Eigen::Matrix2d lm_cov;
    lm_cov << 0.02, 0.005, 0.005, 0.03;
    const Eigen::Vector2d lm = frame_pose.head<2>() + Eigen::Vector2d(2.0 + unit(prng), unit(prng));
    g.add_known(static_cast<std::uint32_t>(2 * frame), lm, lm_cov);
    grow(Eigen::MatrixXd::Zero(2, p.rows()), lm_cov);
    expect_same("add_known");
    // A first sighting, correlated with the pose: Gx P_x., Gx Pxx Gx^T + Gz R Gz^T.
    const Eigen::Vector2d z(1.5 + 0.5 * unit(prng), 0.4 * unit(prng));
    const Eigen::Matrix2d r = noise(0.1, 0.03);
    const double heading = frame_pose(2) + z.y();
    Eigen::Matrix<double, 2, 3> gx;
    gx << 1.0, 0.0, -z.x() * std::sin(heading), 0.0, 1.0, z.x() * std::cos(heading);
    Eigen::Matrix2d gz;
    gz << std::cos(heading), -z.x() * std::sin(heading), std::sin(heading), z.x() * std::cos(heading);
    g.add_new(static_cast<std::uint32_t>(2 * frame + 1), z, r);
    const Eigen::MatrixXd cross = gx * p.topRows<3>();
    grow(cross, gx * p.topLeftCorner<3, 3>() * gx.transpose() + gz * r * gz.transpose());
    expect_same("add_new");
    // Updates on every landmark: P <- P - K S K^T with H on the pose and landmark blocks.
    for (int i = 0; i < g.landmark_count(); i += 1 + frame % 2) {
      const Eigen::Vector2d zi = observe(g.mean.head<3>(), g.landmark_mean(i)) + Eigen::Vector2d(0.05, 0.01);
      const JointFit fit = fit_observation(g, i, zi, r);
      Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2, p.rows());
      h.leftCols<3>() = fit.h_pose;
      h.middleCols<2>(3 + 2 * i) = fit.h_landmark;
      EXPECT_TRUE(fit.s.isApprox(h * p * h.transpose() + r, 1e-10)) << "S of landmark " << i;
      ASSERT_TRUE(apply_observation(g, fit));
      const Eigen::MatrixXd k = p * h.transpose() * fit.s.inverse();
      p -= k * fit.s * k.transpose();
      expect_same("apply_observation");
    }
    // Re-linearisation at the frame's end: Fc P Fc^T.
    const Eigen::Vector2d moved = g.mean.head<2>() - frame_pose.head<2>();
    g.end_frame();
    if (moved.norm() <= 0.25) {
      Eigen::MatrixXd fc = Eigen::MatrixXd::Identity(p.rows(), p.cols());
      fc(0, 2) = -moved.y();
      fc(1, 2) = moved.x();
      p = fc * p * fc.transpose();
    }
    expect_same("end_frame");
    for (int i = 0; i < g.landmark_count(); ++i) {
      const Eigen::Index j = 3 + 2 * i;
      EXPECT_TRUE(g.landmark_cov(i).isApprox(p.block<2, 2>(j, j), 1e-12));
      EXPECT_TRUE(g.pose_landmark_cov(i).isApprox(p.block<3, 2>(0, j), 1e-10));
    }
  }
  EXPECT_EQ(g.landmark_count(), 12);
}

TEST(JointGaussian, KnownLandmarkGivesTheFastSlam2ProposalAndLikelihood) {
  const PoseGaussian pose = pose_gaussian(Pose2(1.0, 2.0, 0.3), Eigen::Vector3d(0.04, 0.02, 0.01));
  const Eigen::Vector2d lm(3.5, 3.0);
  Eigen::Matrix2d lm_cov;
  lm_cov << 0.05, 0.01, 0.01, 0.03;
  const Eigen::Vector2d z(2.6, -0.05);
  const Eigen::Matrix2d r = noise(0.1, 0.03);

  JointGaussian g;
  g.begin(pose);
  g.begin_frame();
  const int i = g.add_known(7, lm, lm_cov);
  const JointFit joint = fit_observation(g, i, z, r);
  const ObservationFit plain = fit_observation(pose, lm, lm_cov, z, r);
  EXPECT_TRUE(joint.s.isApprox(plain.s, 1e-12)) << joint.s << "\nvs\n" << plain.s;
  EXPECT_NEAR(joint.log_likelihood, plain.log_likelihood, 1e-12);
  EXPECT_NEAR(joint.mahalanobis2, plain.mahalanobis2, 1e-12);

  ASSERT_TRUE(apply_observation(g, joint));
  PoseGaussian proposal = pose;
  fold_into_proposal(proposal, plain);
  const PoseGaussian marginal = g.pose();
  EXPECT_TRUE(marginal.mean.isApprox(proposal.mean, 1e-12)) << marginal.mean.transpose();
  EXPECT_TRUE(marginal.cov.isApprox(proposal.cov, 1e-10)) << marginal.cov << "\nvs\n" << proposal.cov;
}

TEST(JointGaussian, NewLandmarkFromACertainPoseMatchesInitialisation) {
  PoseGaussian pose;
  pose.mean = Pose2(0.5, -1.0, 1.2);
  JointGaussian g;
  g.begin(pose);
  g.begin_frame();
  const Eigen::Vector2d z(2.0, 0.4);
  const Eigen::Matrix2d r = noise(0.07, 0.027);
  const int i = g.add_new(3, z, r);
  Eigen::Vector2d mean;
  Eigen::Matrix2d cov;
  initialise_landmark(pose.mean, z, r, mean, cov);
  EXPECT_TRUE(g.landmark_mean(i).isApprox(mean, 1e-12));
  EXPECT_TRUE(g.landmark_cov(i).isApprox(cov, 1e-12)) << g.landmark_cov(i) << "\nvs\n" << cov;
  EXPECT_TRUE((g.pose_landmark_cov(i).isZero(0.0)));
}

TEST(JointGaussian, ConditioningOnAShiftedPoseMovesTheLandmarkWithIt) {
  // Position-only pose uncertainty: a landmark seen from it moves rigidly with it.
  const PoseGaussian pose = pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(0.09, 0.04, 0.0));
  JointGaussian g;
  g.begin(pose);
  g.begin_frame();
  const Eigen::Vector2d z(3.0, 0.5);
  const Eigen::Matrix2d r = noise(0.07, 0.027);
  g.add_new(11, z, r);
  const Pose2 shifted(0.2, -0.1, 0.0);
  const auto conditioned = condition_on_pose(g, shifted);
  ASSERT_EQ(conditioned.size(), 1u);
  EXPECT_EQ(conditioned[0].slot, 11u);
  Eigen::Vector2d expected_mean;
  Eigen::Matrix2d expected_cov;
  initialise_landmark(shifted, z, r, expected_mean, expected_cov);
  EXPECT_TRUE(conditioned[0].mean.isApprox(expected_mean, 1e-9)) << conditioned[0].mean.transpose();
  // Given the pose, only the measurement noise is left.
  EXPECT_TRUE(conditioned[0].cov.isApprox(expected_cov, 1e-6)) << conditioned[0].cov << "\nvs\n" << expected_cov;
  EXPECT_LT(conditioned[0].cov.trace(), g.landmark_cov(0).trace());
}

// Driving among landmarks first seen from an uncertain heading, observing only
// them: nothing ties the heading to the world frame, so its variance must not
// shrink. (With Jacobians at the updated estimates it drops below the bound
// within three steps here: the classic EKF-SLAM inconsistency.)
TEST(JointGaussian, RelativeObservationsLeaveTheAbsoluteHeadingUncertain) {
  const double heading_var = 0.04;  // 11 deg sd
  MotionNoise motion;
  motion.v_sigma_m_per_sqrt_s = 0.005;
  motion.w_sigma_rad_per_sqrt_s = 0.005;
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(1e-4, 1e-4, heading_var)));
  // The truth is 0.25 rad off the estimate, so the estimates move a lot.
  Pose2 truth(0.0, 0.0, 0.25);
  const Eigen::Vector2d landmarks[3] = {{3.0, 1.0}, {4.0, -1.5}, {2.0, 2.5}};
  const Eigen::Matrix2d r = noise(0.05, 0.02);
  std::mt19937 prng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  g.begin_frame();
  for (int k = 0; k < 3; ++k) g.add_new(static_cast<std::uint32_t>(k), observe(truth, landmarks[k]), r);
  g.end_frame();
  for (int step = 0; step < 60; ++step) {
    const double v = 0.1, w = step < 30 ? 0.15 : -0.15, dt = 0.5;
    g.propagate(v, w, dt, motion);
    truth = move(truth, v, w, dt);
    g.begin_frame();
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector2d z = observe(truth, landmarks[k]);
      z += Eigen::Vector2d(0.05 * n01(prng), 0.02 * n01(prng));
      const JointFit fit = fit_observation(g, k, z, r);
      ASSERT_TRUE(std::isfinite(fit.mahalanobis2));
      ASSERT_TRUE(apply_observation(g, fit));
    }
    g.end_frame();
    ASSERT_TRUE(g.healthy()) << "step " << step;
    ASSERT_GE(g.heading_variance(), 0.97 * heading_var) << "step " << step << ": the heading became observable";
  }
}

TEST(JointGaussian, LoopClosureCorrectsThePoseAndTheLandmarksSeenFromIt) {
  // A long gap left the heading 0.3 rad wrong with a matching variance. A new
  // landmark B is seen from there; then a well known landmark A is re-observed.
  const Pose2 truth(0.0, 0.0, 0.3);
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(0.01, 0.01, 0.09)));
  const Eigen::Vector2d a(4.0, 0.0), b(0.0, 3.0);
  const Eigen::Matrix2d r = noise(0.03, 0.01);
  g.begin_frame();
  const int ib = g.add_new(2, observe(truth, b), r);
  g.end_frame();
  const double b_error_before = (g.landmark_mean(ib) - b).norm();
  EXPECT_GT(b_error_before, 0.5);
  for (int k = 0; k < 5; ++k) {
    g.begin_frame();
    int ia = g.find(1);
    if (ia < 0) ia = g.add_known(1, a, 1e-4 * Eigen::Matrix2d::Identity());
    ASSERT_TRUE(apply_observation(g, fit_observation(g, ia, observe(truth, a), r)));
    ASSERT_TRUE(apply_observation(g, fit_observation(g, ib, observe(truth, b), r)));
    g.end_frame();
  }
  EXPECT_LT(std::abs(wrap_angle(g.mean(2) - truth.z())), 0.03) << g.mean.transpose();
  EXPECT_LT(std::sqrt(g.heading_variance()), 0.03);
  EXPECT_LT((g.landmark_mean(ib) - b).norm(), 0.25 * b_error_before) << g.landmark_mean(ib).transpose();
}

TEST(JointGaussian, HealthRejectsNonFiniteAndNegativeVariances) {
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(0.01, 0.01, 0.01)));
  EXPECT_TRUE(g.healthy());
  g.mean(0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(g.healthy());
  g.mean(0) = 0.0;
  g.cov.lower(2, 2) = -1e-3;
  EXPECT_FALSE(g.healthy());
  g.clear();
  EXPECT_FALSE(g.active());
}

TEST(JointGaussian, AnUpdateThatWouldBreakTheStateIsRefusedAndChangesNothing) {
  const PoseGaussian pose = pose_gaussian(Pose2(1.0, 2.0, 0.3), Eigen::Vector3d(0.04, 0.02, 0.01));
  const Eigen::Vector2d lm(3.5, 3.0);
  const Eigen::Matrix2d lm_cov = Eigen::Vector2d(0.05, 0.03).asDiagonal();
  JointGaussian g;
  g.begin(pose);
  g.begin_frame();
  const int i = g.add_known(7, lm, lm_cov);
  const Eigen::Vector2d z(2.6, -0.05);
  JointFit fit = fit_observation(g, i, z, noise(0.1, 0.03));
  const JointGaussian before = g;
  // An innovation covariance far smaller than H P H^T makes the gain overshoot:
  // the variances would go negative.
  fit.s = 1e-3 * fit.s;
  EXPECT_FALSE(apply_observation(g, fit));
  EXPECT_EQ(g.mean, before.mean);
  EXPECT_TRUE(g.cov == before.cov);
  fit.s = Eigen::Matrix2d::Zero();  // S^-1 not finite
  EXPECT_FALSE(apply_observation(g, fit));
  EXPECT_TRUE(g.cov == before.cov);
  fit = fit_observation(g, i, z, noise(0.1, 0.03));
  EXPECT_TRUE(apply_observation(g, fit));
  EXPECT_TRUE(g.healthy());
  EXPECT_LT(g.cov.lower(0, 0), before.cov.lower(0, 0));
}

}  // namespace
}  // namespace pixyslam::slam

namespace pixyslam::slam {
namespace {

// The iterated fit is Gauss-Newton on the MAP of one observation: after its
// update the pose and landmark make the MAP cost's gradient vanish, and the
// cost is lower than after the single linearisation at the frame pose, which
// a heading off by 0.7 rad (the pose 2 m from the landmark, 0.5 m uncertain)
// leaves far from the optimum. With the prior at the truth both fits agree.
TEST(JointGaussian, IteratedFitReachesTheMapOfALargeCorrection) {
  const Pose2 truth(0.3, -0.2, 0.7);
  const Eigen::Vector2d landmark(2.0, 1.0);
  const Eigen::Matrix2d r = noise(0.05, 0.02);
  const Eigen::Vector2d z = observe(truth, landmark);
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(0.25, 0.25, 0.25)));
  const int i = g.add_known(7, landmark, 1e-4 * Eigen::Matrix2d::Identity());
  const Eigen::VectorXd x0 = g.mean;
  const Eigen::MatrixXd p_inverse = g.cov.full().inverse();
  const auto cost = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd dx = x - x0;
    dx(2) = wrap_angle(dx(2));
    const Eigen::Vector2d e = innovation(z, predict_observation(x.head<3>(), x.tail<2>()).z);
    return dx.dot(p_inverse * dx) + e.dot(r.inverse() * e);
  };
  const auto gradient_norm = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd dx = x - x0;
    dx(2) = wrap_angle(dx(2));
    const PredictedObservation p = predict_observation(x.head<3>(), x.tail<2>());
    Eigen::Matrix<double, 2, 5> h;
    h << p.h_pose, p.h_landmark;
    return (p_inverse * dx - h.transpose() * r.inverse() * innovation(z, p.z)).norm();
  };

  JointGaussian linear = g;
  ASSERT_TRUE(apply_observation(linear, fit_observation(g, i, z, r)));
  JointGaussian iterated = g;
  const JointFit fit = fit_observation_iterated(g, i, z, r);
  ASSERT_TRUE(apply_observation(iterated, fit));
  EXPECT_LT(gradient_norm(iterated.mean), 1e-6);
  EXPECT_GT(gradient_norm(linear.mean), 1.0);
  EXPECT_LT(cost(iterated.mean), cost(linear.mean));
  EXPECT_LT(fit.mahalanobis2, fit_observation(g, i, z, r).mahalanobis2);
  EXPECT_TRUE(iterated.healthy());

  JointGaussian at_truth;
  at_truth.begin(pose_gaussian(truth, Eigen::Vector3d(0.25, 0.25, 0.25)));
  const int j = at_truth.add_known(7, landmark, 1e-4 * Eigen::Matrix2d::Identity());
  const JointFit once = fit_observation(at_truth, j, z, r);
  const JointFit again = fit_observation_iterated(at_truth, j, z, r);
  EXPECT_NEAR(again.mahalanobis2, once.mahalanobis2, 1e-12);
  EXPECT_TRUE(again.innovation.isApprox(once.innovation, 1e-9) || again.innovation.norm() < 1e-12);
}

// A heading 0.3 rad uncertain, a landmark first seen 7 m ahead from that pose
// (relative) and one mapped before (known). Split 0.15 rad apart: the
// components are symmetric, their weights and moments make up the heading's
// Gaussian, each component's heading sd is half the spacing, the relative
// landmark stays 7 m ahead of each component's pose (on its arc; the tangent
// of a linear update would put it sqrt(49 + (7 delta)^2) m away), the known
// one stays where it was, and the first estimate turns with the pose.
TEST(JointGaussian, HeadingSplitTurnsRelativeLandmarksOnTheirArcs) {
  const double sigma = 0.3;
  const double spacing = 0.15;
  JointGaussian g;
  g.begin(pose_gaussian(Pose2(1.0, 2.0, 0.5), Eigen::Vector3d(0.04, 0.04, sigma * sigma)));
  const int ahead = g.add_new(3, Eigen::Vector2d(7.0, 0.0), noise(0.05, 0.01));
  const Eigen::Vector2d known_position(-2.0, 4.0);
  const int known = g.add_known(9, known_position, 1e-4 * Eigen::Matrix2d::Identity());
  const std::vector<HeadingComponent> parts = split_heading(g, spacing);
  ASSERT_GE(parts.size(), 11u);
  ASSERT_EQ(parts.size() % 2, 1u);
  double weight = 0.0, mean = 0.0, second = 0.0, largest = 0.0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const JointGaussian& c = parts[k].state;
    const double delta = wrap_angle(c.mean(2) - g.mean(2));
    EXPECT_NEAR(parts[k].weight, parts[parts.size() - 1 - k].weight, 1e-12);
    EXPECT_NEAR(std::sqrt(c.heading_variance()), 0.5 * spacing, 1e-9);
    EXPECT_NEAR((c.landmark_mean(ahead) - c.mean.head<2>()).norm(), 7.0, 1e-9) << delta;
    EXPECT_TRUE(c.landmark_mean(known).isApprox(known_position, 1e-12));
    const Eigen::Vector2d first_ahead = c.landmarks[static_cast<std::size_t>(ahead)].first - c.frame_pose.head<2>();
    EXPECT_NEAR(std::atan2(first_ahead.y(), first_ahead.x()), c.frame_pose(2), 1e-9);
    EXPECT_TRUE(c.healthy());
    weight += parts[k].weight;
    mean += parts[k].weight * delta;
    second += parts[k].weight * (delta * delta + c.heading_variance());
    largest = std::max(largest, std::abs(delta));
  }
  EXPECT_NEAR(weight, 1.0, 1e-12);
  EXPECT_NEAR(mean, 0.0, 1e-12);
  EXPECT_NEAR(second, sigma * sigma, 0.02 * sigma * sigma);
  EXPECT_GE(largest, 2.5 * sigma);
  // Nothing to split when the heading is already as narrow as a component.
  JointGaussian narrow;
  narrow.begin(pose_gaussian(Pose2(0.0, 0.0, 0.0), Eigen::Vector3d(0.04, 0.04, 0.05 * 0.05)));
  EXPECT_TRUE(split_heading(narrow, spacing).empty());
}

}  // namespace
}  // namespace pixyslam::slam
