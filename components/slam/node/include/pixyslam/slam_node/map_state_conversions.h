#pragma once

#include <cstdint>
#include <vector>

#include "map_state.h"
#include "landmark_observation.h"
#include "odometry.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/sensor_queue.h"

namespace pixyslam::slam_node {

// Message <-> core conversions of the estimator, in one place. Times: the core
// runs on seconds since `epoch_ns` (double keeps ns resolution that way).
slam::OdometryInput to_odometry_input(const msg::Odometry& m, std::uint64_t epoch_ns);
// Detections in the camera frame; the camera sits at the robot origin facing
// forward, so they are robot-frame range/bearing. Sigmas are kept when
// `use_detection_sigmas`, else zero (= the filter's configured noise).
slam::ObservationInput to_observation_input(const msg::LandmarkObservation& m,
                                            std::uint64_t epoch_ns, bool use_detection_sigmas);

// What the estimator knows after one step, besides the filter itself.
struct StepInfo {
  std::uint64_t epoch_ns = 0;
  double update_time_s = 0.0;
  std::uint64_t odometry_seq = 0;
  std::uint64_t observation_seq = 0;
  std::uint64_t samples_late = 0;
};

// Fills `out` (reused between calls to keep its buffers) from the filter:
// pose estimate, particle subsample (evenly strided, at most `max_particle_poses`),
// landmarks of the best particle or the mixture, counters.
void fill_map_state(const slam::FastSlam2& filter, const StepInfo& info, int max_particle_poses,
                    bool mixture_landmarks, msg::MapState& out);

std::uint64_t to_stamp_ns(double t_s, std::uint64_t epoch_ns);
msg::Pose2D to_pose_msg(const slam::Pose2& p);

}  // namespace pixyslam::slam_node
