#pragma once

#include <string>

#include "pixyslam/slam/sensor_queue.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::slam_node {

// Everything the estimator process is configured with (config/slam_estimator.yaml).
struct EstimatorOptions {
  slam::FilterOptions filter;            // `filter:` (see config/slam_mrclam.yaml for the keys)
  slam::Pose2 initial_pose = slam::Pose2::Zero();  // `estimator.initial_pose` {x_m, y_m, theta_rad}
  slam::SensorQueueOptions queue;        // `estimator.odometry_max_delay_s`, `observation_max_delay_s`
  bool use_detection_sigmas = true;      // per-detection sigmas from the camera, else filter's
  int published_particle_poses = 100;    // MapState.particle_poses subsample size (<= 512)
  std::string landmarks = "best";        // MapState landmarks: "best" particle or "mixture"
  double status_period_s = 10.0;         // counters to the log every so often (0: never)
  dds::DdsOptions dds;                   // `dds:`
};

// Reads `filter:`, `estimator:` and `dds:` from one file; unknown keys, wrong
// types and out-of-range values throw config::ConfigError naming file and key.
EstimatorOptions read_estimator_options_file(const std::string& path);

}  // namespace pixyslam::slam_node
