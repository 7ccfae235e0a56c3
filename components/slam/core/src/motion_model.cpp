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

void propagate(PoseGaussian& g, double v_mps, double w_radps, double dt_s, const MotionNoise& noise) {
  if (dt_s <= 0.0) return;
  const double d = v_mps * dt_s;
  const double a = w_radps * dt_s;
  const double heading = g.mean.z() + 0.5 * a;
  const double c = std::cos(heading);
  const double s = std::sin(heading);

  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = -d * s;
  f(1, 2) = d * c;
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
  const Eigen::Vector2d q(var_d, var_a);

  g.cov = f * g.cov * f.transpose() + v * q.asDiagonal() * v.transpose();
  g.mean = Pose2(g.mean.x() + d * c, g.mean.y() + d * s, wrap_angle(g.mean.z() + a));
}

}  // namespace pixyslam::slam
