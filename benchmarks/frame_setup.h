#pragma once

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "pixyslam/slam/fastslam2.h"

namespace pixyslam::bench {

// A filter with M particles sharing a prior map of K landmarks on a square grid
// centred on the robot, and a generator of frames: odometry then 3 detections of
// landmarks within 3 m, observed from the (static) true pose with small noise.
class FrameWorkload {
 public:
  FrameWorkload(int particles, int landmarks, slam::ResampleMode mode = slam::ResampleMode::kEveryFrame)
      : rng_(42) {
    slam::FilterOptions o;
    o.particles = particles;
    o.seed = 1;
    o.resample_mode = mode;
    o.range_sigma_m = 0.07;
    o.bearing_sigma_rad = 0.027;
    filter_ = std::make_unique<slam::FastSlam2>(o, slam::Pose2::Zero());
    const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(landmarks))));
    const double spacing = 0.5;
    std::vector<slam::LandmarkEstimate> map;
    for (int i = 0; i < landmarks; ++i) {
      slam::LandmarkEstimate e;
      e.id = i;
      e.mean = Eigen::Vector2d((i % side - side / 2) * spacing + 0.25, (i / side - side / 2) * spacing + 0.25);
      e.cov = Eigen::Matrix2d::Identity() * 0.01;
      e.times_observed = 1;
      map.push_back(e);
      if (e.mean.norm() < 3.0 && e.mean.norm() > 0.2) near_.push_back(e);
    }
    filter_->set_prior_map(map);
  }

  void step() {
    t_ += 0.1;
    filter_->add_odometry({t_, 0.0, 0.0});
    slam::ObservationFrame f{t_, {}};
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_int_distribution<std::size_t> pick(0, near_.size() - 1);
    for (int k = 0; k < 3; ++k) {
      const slam::LandmarkEstimate& e = near_[pick(rng_)];
      slam::RangeBearing z;
      z.landmark_id = e.id;
      z.range_m = e.mean.norm() + 0.02 * n(rng_);
      z.bearing_rad = std::atan2(e.mean.y(), e.mean.x()) + 0.01 * n(rng_);
      f.detections.push_back(z);
    }
    filter_->add_observations(f);
  }

  const slam::FastSlam2& filter() const { return *filter_; }

 private:
  std::unique_ptr<slam::FastSlam2> filter_;
  std::vector<slam::LandmarkEstimate> near_;
  std::mt19937 rng_;
  double t_ = 0.0;
};

}  // namespace pixyslam::bench
