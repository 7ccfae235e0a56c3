#pragma once

#include <vector>

#include <Eigen/Core>

namespace pixyslam::eval {

// Planar rigid transform without scale: p' = R(theta_rad) p + translation.
// theta_rad is counter-clockwise in radians, translation in metres, expressed in
// the target frame (the frame the transformed points land in).
struct Rigid2 {
  double theta_rad = 0.0;
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();

  Eigen::Vector2d apply(const Eigen::Vector2d& p) const;
};

// Least-squares rotation + translation (no scale) mapping the points `from` onto
// the corresponding points `to` (same index = same point), closed form: centre
// both sets on their centroids, theta = atan2(sum cross, sum dot), translation =
// centroid(to) - R centroid(from). Throws std::invalid_argument if the sizes
// differ or fewer than 2 pairs are given. Coincident points give theta = 0.
Rigid2 fit_rigid_2d(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);

// Wraps an angle in radians to (-pi, pi]; -pi maps to +pi. NaN stays NaN.
double wrap_angle(double a);

}  // namespace pixyslam::eval
