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

void ComposedMotion::add(double v_mps, double w_radps, double dt_s, const MotionNoise& noise) {
  if (dt_s <= 0.0) return;
  const MotionStep step = motion_step(local_, v_mps, w_radps, dt_s, noise);
  q_ = step.f * q_ * step.f.transpose() + step.q;
  local_ = step.mean;
  ++steps_;
}

Pose2 ComposedMotion::moved_mean(const Pose2& pose, double c, double s) const {
  return Pose2(pose.x() + c * local_.x() - s * local_.y(), pose.y() + s * local_.x() + c * local_.y(),
               wrap_angle(pose.z() + local_.z()));
}

Eigen::Matrix3d ComposedMotion::jacobian(double c, double s) const {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = -(s * local_.x() + c * local_.y());
  f(1, 2) = c * local_.x() - s * local_.y();
  return f;
}

Eigen::Matrix3d ComposedMotion::noise(double c, double s) const {
  Eigen::Matrix3d b = Eigen::Matrix3d::Identity();
  b(0, 0) = c;
  b(0, 1) = -s;
  b(1, 0) = s;
  b(1, 1) = c;
  return b * q_ * b.transpose();
}

Eigen::Matrix3d ComposedMotion::mean_noise(double c, double s, double cc, double ss, double cs) const {
  // B q B^T with B = diag(R, 1): the xy block is R q_xy R^T, the x-theta column R q_xt.
  const double a = q_(0, 0), b = q_(0, 1), d = q_(1, 1), e = q_(0, 2), f = q_(1, 2);
  Eigen::Matrix3d out;
  out(0, 0) = cc * a - 2.0 * cs * b + ss * d;
  out(1, 1) = ss * a + 2.0 * cs * b + cc * d;
  out(0, 1) = out(1, 0) = cs * (a - d) + (cc - ss) * b;
  out(0, 2) = out(2, 0) = c * e - s * f;
  out(1, 2) = out(2, 1) = s * e + c * f;
  out(2, 2) = q_(2, 2);
  return out;
}

void ComposedMotion::apply(PoseGaussian& g) const {
  if (empty()) return;
  const double c = std::cos(g.mean.z());
  const double s = std::sin(g.mean.z());
  const Eigen::Matrix3d f = jacobian(c, s);
  g.cov = f * g.cov * f.transpose() + noise(c, s);
  g.mean = moved_mean(g.mean, c, s);
}

}  // namespace pixyslam::slam
