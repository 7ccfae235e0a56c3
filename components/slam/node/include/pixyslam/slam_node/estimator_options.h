#pragma once

#include <string>
#include <vector>

#include "pixyslam/slam/sensor_queue.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::slam_node {

// `estimator.checkpoint`: the pose and map saved every period_s of filter time
// (and at a clean stop), so a restarted estimator continues the map.
struct CheckpointOptions {
  std::string file;                  // "" = no checkpoints; relative to the config file's folder
  double period_s = 1.0;             // filter time between writes
  bool resume = true;                // start from the file when it is fresh enough
  double max_age_s = 30.0;           // older than this at the first input: start from scratch
  double max_speed_mps = 0.5;        // how fast the robot may have moved while no estimator ran
  double max_turn_rate_radps = 1.0;  // (they widen the resumed pose's covariance)
};

// Everything the estimator process is configured with (config/slam_estimator.yaml).
struct EstimatorOptions {
  slam::FilterOptions filter;            // `filter:` (see config/slam_mrclam.yaml for the keys)
  slam::Pose2 initial_pose = slam::Pose2::Zero();  // `estimator.initial_pose` {x_m, y_m, theta_rad}
  // `estimator.initial_pose.source`: config (the pose above) | ground_truth: the
  // first GroundTruth of this robot (an experiment's known start: recorded data
  // sets, the simulator), waited for up to initial_pose.wait_s before the first
  // filter step (then the pose above, with a warning). The filter reads nothing
  // else of the ground truth.
  std::string initial_pose_source = "config";
  double initial_pose_wait_s = 10.0;
  slam::SensorQueueOptions queue;        // `estimator.odometry_max_delay_s`, `observation_max_delay_s`
  bool use_detection_sigmas = true;      // per-detection sigmas from the camera, else filter's
  int published_particle_poses = 100;    // MapState.particle_poses subsample size (<= 512)
  // `estimator.map_state_period_s`: a MapState after a filter step at most this
  // often in filter time (0: after every step). A recording replayed faster
  // than real time steps at hundreds of Hz per robot; the trajectory files keep
  // every step either way, and the last state is always published.
  double map_state_period_s = 0.0;
  std::string landmarks = "best";        // MapState landmarks: "best" particle or "mixture"
  double status_period_s = 10.0;         // counters to the log every so often (0: never)
  CheckpointOptions checkpoint;          // `estimator.checkpoint`
  dds::DdsOptions dds;                   // `dds:`
};

// The `estimator:` keys: range, unit, default, help.
const parameters::Table<EstimatorOptions>& estimator_parameters();

// `--set` assignments "filter.KEY=V", "estimator.KEY=V", "dds.KEY=V" applied
// and validated; the DDS settings resolved (the environment, then these: dds::resolve_settings).
// Throws std::invalid_argument / config::ConfigError naming the assignment.
void apply_overrides(EstimatorOptions& options, const std::vector<std::string>& assignments);

// The three sections as YAML (the effective configuration).
std::string to_yaml(const EstimatorOptions& options);

// Every parameter of the three sections, for --help.
std::string help_text();

// Reads `filter:`, `estimator:` and `dds:` from one file; unknown keys, wrong
// types and out-of-range values throw config::ConfigError naming file and key.
EstimatorOptions read_estimator_options_file(const std::string& path);

}  // namespace pixyslam::slam_node
