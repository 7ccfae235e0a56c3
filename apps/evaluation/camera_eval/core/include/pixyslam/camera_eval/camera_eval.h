#pragma once

#include <map>
#include <string>

#include "pixyslam/sim/synthetic_camera.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/slam_options.h"

namespace pixyslam::camera_eval {

// The synthetic camera driven through a simulated world: every camera frame
// rendered from the true pose, detected, and the blocks turned into landmark
// ids and ranges the way the pixy bridge does (SignatureMap, Eq. 5 and 6).
struct EvalOptions {
  sim::WorldOptions world;
  sim::SyntheticCameraOptions camera;
  camera::DetectorOptions detector = camera::default_detector_options();
  double max_range_m = 2.0;  // poles beyond are too small to count as "in view" (a band under 5 px)
  std::uint64_t seed = 1;
  slam::FilterOptions filter;  // for the map check
};

struct PoleStats {
  int in_view = 0;    // frames with the pole wholly in the image, unoccluded, within max_range_m
  int detected = 0;   // of those, frames in which its id was detected
};

struct EvalResult {
  std::map<int, PoleStats> poles;
  int frames = 0;
  int wrong_ids = 0;             // detections of an id whose pole is not where the block is
  int range_samples_1m = 0;      // detections of poles at 0.9..1.1 m
  double range_error_1m = 0.0;   // mean |range - true| / true over those
  double bearing_rms_rad = 0.0;  // over all correct detections
  double ms_per_frame = 0.0;     // detection only (render excluded)
  // The detections (Eq. 5, 6) through FastSLAM 2.0 with the world's odometry:
  pixy::DetectionCounters checks;  // what the bridge's checks rejected
  int map_landmarks = 0;
  int map_wrong_ids = 0;         // map landmarks whose id is no pole, or over 0.5 m from its pole
  double pose_ate_m = 0.0;
  double detection_rate() const;
};

// pixy: the bridge's options (signature map, camera model); the synthetic
// poles get each landmark's code as their bands (tags top to bottom).
EvalResult evaluate(const EvalOptions& options, const pixy::SignatureMap& signatures, const pixy::CameraModel& model);

}  // namespace pixyslam::camera_eval
