#include "pixyslam/slam/motion_model.h"

#include <cmath>

namespace pixyslam::slam {

Pose2 move(const Pose2& pose, double v_mps, double w_radps, double dt_s) {
  const double d = v_mps * dt_s;
  const double a = w_radps * dt_s;
  const double heading = pose.z() + 0.5 * a;
  return Pose2(pose.x() + d * std::cos(heading), pose.y() + d * std::sin(heading),
               wrap_angle(pose.z() + a));
}

MotionStep motion_step(const Pose2& pose, double v_mps, double w_radps, double dt_s, const MotionNoise& noise) {
  MotionStep step;
  step.mean = pose;
  if (dt_s <= 0.0) return step;
  const double d = v_mps * dt_s;
  const double a = w_radps * dt_s;
  const double heading = pose.z() + 0.5 * a;
  const double c = std::cos(heading);
  const double s = std::sin(heading);
  step.f(0, 2) = -d * s;
  step.f(1, 2) = d * c;
  Eigen::Matrix<double, 3, 2> v;
  v << c, -0.5 * d * s,
       s, 0.5 * d * c,
       0.0, 1.0;
  const double dist = std::abs(d);
  const double var_d = noise.v_sigma_m_per_sqrt_s * noise.v_sigma_m_per_sqrt_s * dt_s +
                       noise.distance_sigma_per_sqrt_m * noise.distance_sigma_per_sqrt_m * dist;
  const double var_a = noise.w_sigma_rad_per_sqrt_s * noise.w_sigma_rad_per_sqrt_s * dt_s +
                       noise.heading_sigma_rad_per_sqrt_m * noise.heading_sigma_rad_per_sqrt_m * dist +
                       noise.rotation_sigma_per_sqrt_rad * noise.rotation_sigma_per_sqrt_rad * std::abs(a);
  step.q = v * Eigen::Vector2d(var_d, var_a).asDiagonal() * v.transpose();
  step.mean = Pose2(pose.x() + d * c, pose.y() + d * s, wrap_angle(pose.z() + a));
  return step;
}

void propagate(PoseGaussian& g, double v_mps, double w_radps, double dt_s, const MotionNoise& noise) {
  if (dt_s <= 0.0) return;
  const MotionStep step = motion_step(g.mean, v_mps, w_radps, dt_s, noise);
  g.cov = step.f * g.cov * step.f.transpose() + step.q;
  g.mean = step.mean;
}

}  // namespace pixyslam::slam
