#pragma once

#include <Eigen/Core>

#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// Range-bearing observation model (seed paper Eq. 3-4, FastSLAM 2.0 h(theta, s)):
//   dx = mx - x, dy = my - y, q = dx^2 + dy^2,
//   z = (sqrt(q), atan2(dy, dx) - theta),
//   H_landmark = [dx/r, dy/r; -dy/q, dx/q]   (paper Eq. 4, G),
//   H_pose     = [-dx/r, -dy/r, 0; dy/q, -dx/q, -1].
struct PredictedObservation {
  Eigen::Vector2d z = Eigen::Vector2d::Zero();  // (range m, bearing rad)
  Eigen::Matrix<double, 2, 3> h_pose = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d h_landmark = Eigen::Matrix2d::Zero();
};

PredictedObservation predict_observation(const Pose2& pose, const Eigen::Vector2d& landmark);

// z_measured - z_predicted with the bearing difference wrapped to (-pi, pi].
Eigen::Vector2d innovation(const Eigen::Vector2d& z_measured, const Eigen::Vector2d& z_predicted);

// Inverse model for a first sighting: mean = pose + r (cos(theta+b), sin(theta+b)),
// covariance G^-1 R G^-T with G the landmark Jacobian at that mean.
void initialise_landmark(const Pose2& pose, const Eigen::Vector2d& z, const Eigen::Matrix2d& r,
                         Eigen::Vector2d& mean, Eigen::Matrix2d& cov);

// Landmark EKF update given a (sampled) pose: S = G P G^T + R, K = P G^T S^-1,
// mean += K nu, P = (I - K G) P (I - K G)^T + K R K^T (Joseph form).
void update_landmark(const Pose2& pose, const Eigen::Vector2d& z, const Eigen::Matrix2d& r,
                     Eigen::Vector2d& mean, Eigen::Matrix2d& cov);

// How one observation of a mapped landmark fits a pose Gaussian (FastSLAM 2.0):
// S = H_pose Sigma H_pose^T + H_landmark P H_landmark^T + R, the innovation at the
// Gaussian's mean, its squared Mahalanobis distance and log N(z; z_hat, S).
struct ObservationFit {
  Eigen::Vector2d innovation = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> h_pose = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d s = Eigen::Matrix2d::Identity();
  double mahalanobis2 = 0.0;
  double log_likelihood = 0.0;
};

ObservationFit fit_observation(const PoseGaussian& pose, const Eigen::Vector2d& landmark_mean,
                               const Eigen::Matrix2d& landmark_cov, const Eigen::Vector2d& z,
                               const Eigen::Matrix2d& r);

// Folds the observation into the pose proposal (Montemerlo et al. 2003, Eq. for
// Sigma_x and mu_x, in covariance form so a rank-deficient motion covariance is
// fine): K = Sigma H^T S^-1, mu += K nu, Sigma = (I - K H) Sigma.
void fold_into_proposal(PoseGaussian& pose, const ObservationFit& fit);

}  // namespace pixyslam::slam
