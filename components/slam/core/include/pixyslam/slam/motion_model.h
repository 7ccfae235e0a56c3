#pragma once

#include <Eigen/Core>

#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// Noise of the unicycle model, as white noise densities on the velocities: over
// an interval dt the travelled distance gets variance v_sigma^2 * dt and the
// rotation w_sigma^2 * dt (units m/sqrt(s), rad/sqrt(s)), independent of the
// odometry rate. The *_per_sqrt_m terms add variance proportional to the distance
// travelled (sigma^2 * |d|), also rate-independent.
struct MotionNoise {
  double v_sigma_m_per_sqrt_s = 0.01;
  double w_sigma_rad_per_sqrt_s = 0.03;
  double distance_sigma_per_sqrt_m = 0.0;
  double heading_sigma_rad_per_sqrt_m = 0.0;
  // Rotation variance proportional to the commanded rotation (sigma^2 * |a|):
  // wheels slip and motors lag when the robot turns.
  double rotation_sigma_per_sqrt_rad = 0.0;
};

// Gaussian over a pose: mean and 3x3 covariance.
struct PoseGaussian {
  Pose2 mean = Pose2::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
};

// Unicycle (paper Eq. 2, in this project's heading convention) integrated over dt
// with the midpoint rule: d = v dt, a = w dt,
//   x += d cos(theta + a/2), y += d sin(theta + a/2), theta += a.
Pose2 move(const Pose2& pose, double v_mps, double w_radps, double dt_s);

// One step of move() linearised at pose: the moved mean, F = d move / d pose and
// the noise covariance V Q V^T (V = d move / d (d, a), Q = diag(var d, var a)).
struct MotionStep {
  Pose2 mean = Pose2::Zero();
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
};
MotionStep motion_step(const Pose2& pose, double v_mps, double w_radps, double dt_s, const MotionNoise& noise);

// Propagates a pose Gaussian through move(): mean moved, covariance
// F cov F^T + V Q V^T with F = d move / d pose and V = d move / d (d, a).
void propagate(PoseGaussian& g, double v_mps, double w_radps, double dt_s, const MotionNoise& noise);

}  // namespace pixyslam::slam
