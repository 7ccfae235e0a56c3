#include "pixyslam/slam/observation_model.h"

#include <cmath>

#include <Eigen/LU>

namespace pixyslam::slam {

PredictedObservation predict_observation(const Pose2& pose, const Eigen::Vector2d& landmark) {
  const double dx = landmark.x() - pose.x();
  const double dy = landmark.y() - pose.y();
  const double q = dx * dx + dy * dy;
  const double r = std::sqrt(q);
  PredictedObservation p;
  p.z = Eigen::Vector2d(r, wrap_angle(std::atan2(dy, dx) - pose.z()));
  p.h_landmark << dx / r, dy / r, -dy / q, dx / q;
  p.h_pose << -dx / r, -dy / r, 0.0, dy / q, -dx / q, -1.0;
  return p;
}

Eigen::Vector2d innovation(const Eigen::Vector2d& z_measured, const Eigen::Vector2d& z_predicted) {
  return Eigen::Vector2d(z_measured.x() - z_predicted.x(), wrap_angle(z_measured.y() - z_predicted.y()));
}

void initialise_landmark(const Pose2& pose, const Eigen::Vector2d& z, const Eigen::Matrix2d& r,
                         Eigen::Vector2d& mean, Eigen::Matrix2d& cov) {
  const double heading = pose.z() + z.y();
  mean = Eigen::Vector2d(pose.x() + z.x() * std::cos(heading), pose.y() + z.x() * std::sin(heading));
  const Eigen::Matrix2d g_inv = predict_observation(pose, mean).h_landmark.inverse();
  cov = g_inv * r * g_inv.transpose();
}

void update_landmark(const Pose2& pose, const Eigen::Vector2d& z, const Eigen::Matrix2d& r,
                     Eigen::Vector2d& mean, Eigen::Matrix2d& cov) {
  const PredictedObservation p = predict_observation(pose, mean);
  const Eigen::Matrix2d& g = p.h_landmark;
  const Eigen::Matrix2d s = g * cov * g.transpose() + r;
  const Eigen::Matrix2d k = cov * g.transpose() * s.inverse();
  mean += k * innovation(z, p.z);
  const Eigen::Matrix2d a = Eigen::Matrix2d::Identity() - k * g;
  cov = a * cov * a.transpose() + k * r * k.transpose();
}

ObservationFit fit_observation(const PoseGaussian& pose, const Eigen::Vector2d& landmark_mean,
                               const Eigen::Matrix2d& landmark_cov, const Eigen::Vector2d& z,
                               const Eigen::Matrix2d& r) {
  const PredictedObservation p = predict_observation(pose.mean, landmark_mean);
  ObservationFit fit;
  fit.innovation = innovation(z, p.z);
  fit.h_pose = p.h_pose;
  fit.s = p.h_pose * pose.cov * p.h_pose.transpose() +
          p.h_landmark * landmark_cov * p.h_landmark.transpose() + r;
  const Eigen::Matrix2d s_inv = fit.s.inverse();
  fit.mahalanobis2 = fit.innovation.dot(s_inv * fit.innovation);
  fit.log_likelihood = -0.5 * fit.mahalanobis2 - std::log(2.0 * M_PI) - 0.5 * std::log(fit.s.determinant());
  return fit;
}

void fold_into_proposal(PoseGaussian& pose, const ObservationFit& fit) {
  const Eigen::Matrix<double, 3, 2> k = pose.cov * fit.h_pose.transpose() * fit.s.inverse();
  pose.mean += k * fit.innovation;
  pose.mean.z() = wrap_angle(pose.mean.z());
  const Eigen::Matrix3d a = Eigen::Matrix3d::Identity() - k * fit.h_pose;
  // Joseph-like symmetric form keeps the covariance positive semi-definite.
  pose.cov = a * pose.cov;
  pose.cov = 0.5 * (pose.cov + pose.cov.transpose());
}

}  // namespace pixyslam::slam
