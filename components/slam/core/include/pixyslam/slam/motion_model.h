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

// Several motion steps composed once for every pose. A step depends on the
// heading only through a rotation, so the steps are integrated in the frame of
// the start heading (one sin/cos per step, shared by all particles) and then
// applied to any pose by rotating: for a pose of heading theta with
// B = diag(R(theta), 1) and the composed displacement delta = R(theta) local.xy,
//   mean <- (x, y) + delta, theta + local.theta;
//   F = I + [0 0 -delta_y; 0 0 delta_x; 0 0 0]  (the step Jacobians are
//       unipotent and multiply by adding their displacements);
//   cov <- F cov F^T + B q B^T, q the steps' noise accumulated in that frame
//       (q <- F_k q F_k^T + Q_k).
// Exactly the result of propagate() step by step, up to rounding.
class ComposedMotion {
 public:
  void add(double v_mps, double w_radps, double dt_s, const MotionNoise& noise);
  bool empty() const { return steps_ == 0; }
  void clear() { *this = ComposedMotion(); }
  double rotation() const { return local_.z(); }
  // The composed displacement in the start heading's frame.
  Eigen::Vector2d displacement() const { return local_.head<2>(); }

  // The moved mean of a pose whose heading has cos c and sin s.
  Pose2 moved_mean(const Pose2& pose, double c, double s) const;
  // F above for that heading.
  Eigen::Matrix3d jacobian(double c, double s) const;
  // B q B^T above for that heading.
  Eigen::Matrix3d noise(double c, double s) const;
  void apply(PoseGaussian& g) const;
  // sum_i w_i noise(c_i, s_i) from the weighted sums of c, s, c^2, s^2 and c s
  // (the weights summing to 1).
  Eigen::Matrix3d mean_noise(double c, double s, double cc, double ss, double cs) const;

 private:
  Pose2 local_ = Pose2::Zero();  // displacement and rotation in the start heading's frame
  Eigen::Matrix3d q_ = Eigen::Matrix3d::Zero();
  int steps_ = 0;
};

}  // namespace pixyslam::slam
