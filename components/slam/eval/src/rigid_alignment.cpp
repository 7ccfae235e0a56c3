#include "pixyslam/eval/rigid_alignment.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pixyslam::eval {

Eigen::Vector2d Rigid2::apply(const Eigen::Vector2d& p) const {
  const double c = std::cos(theta_rad);
  const double s = std::sin(theta_rad);
  return Eigen::Vector2d(c * p.x() - s * p.y(), s * p.x() + c * p.y()) + translation;
}

Rigid2 fit_rigid_2d(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to) {
  if (from.size() != to.size()) {
    throw std::invalid_argument("fit_rigid_2d: point lists differ in size (" + std::to_string(from.size()) +
                                " vs " + std::to_string(to.size()) + ")");
  }
  if (from.size() < 2) {
    throw std::invalid_argument("fit_rigid_2d: need at least 2 point pairs, got " + std::to_string(from.size()));
  }
  const double n = static_cast<double>(from.size());
  Eigen::Vector2d centroid_from = Eigen::Vector2d::Zero();
  Eigen::Vector2d centroid_to = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    centroid_from += from[i];
    centroid_to += to[i];
  }
  centroid_from /= n;
  centroid_to /= n;

  // Rotation maximising sum q_i . R p_i for the centred pairs (p_i, q_i).
  double dot_sum = 0.0;
  double cross_sum = 0.0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector2d p = from[i] - centroid_from;
    const Eigen::Vector2d q = to[i] - centroid_to;
    dot_sum += p.dot(q);
    cross_sum += p.x() * q.y() - p.y() * q.x();
  }

  Rigid2 result;
  result.theta_rad = std::atan2(cross_sum, dot_sum);
  result.translation = Eigen::Vector2d::Zero();
  result.translation = centroid_to - result.apply(centroid_from);
  return result;
}

double wrap_angle(double a) {
  constexpr double kPi = 3.14159265358979323846;
  double r = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  if (r <= -kPi) r += 2.0 * kPi;
  return r;
}

}  // namespace pixyslam::eval
