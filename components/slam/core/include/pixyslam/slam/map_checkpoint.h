#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// What the estimator needs to resume after a crash or restart: the mean pose
// with its covariance and the map, at a stamp (ns, the sensors' clock). Written
// as YAML (version 1) so that a person can read and edit it.
struct MapCheckpoint {
  std::uint64_t stamp_ns = 0;
  slam::PoseGaussian pose;
  std::vector<slam::LandmarkEstimate> landmarks;
  // The odometry command the filter held at stamp_ns, and how long it had
  // held it: the robot most likely went on with it while no estimator ran (a
  // checkpoint without it, version 1, holds none).
  double control_v_mps = 0.0;
  double control_w_radps = 0.0;
  double control_age_s = 0.0;
};

// The filter's estimate as a checkpoint: its mean pose and covariance
// (symmetrised) at stamp_ns, its held control, and its map as the landmarks'
// weighted mixture over the particles (FastSlam2::landmarks_mixture). A
// restarted filter takes that map as a prior it trusts: the mixture's
// covariance holds the particles' spread (the map frame's uncertainty), the
// best particle's does not. Dataset6, 66 restarts 1.4 s after a kill (mrclam_eval
// --resume 1.4, seed 1): the ATE after the restart exceeds the uninterrupted
// run's by 0.022 m on average (p90 0.083 m) from the mixture, 0.062 m (p90
// 0.290 m) from the best particle's map (docs/robustness.md).
MapCheckpoint checkpoint_of(const FastSlam2& filter, std::uint64_t stamp_ns);

std::string to_yaml(const MapCheckpoint& checkpoint);
// Parses to_yaml()'s text; config::ConfigError naming `origin` and the key on
// anything missing, malformed or non-finite, or a covariance that is not
// symmetric positive semi-definite.
MapCheckpoint parse_map_checkpoint(const std::string& text, const std::string& origin);
MapCheckpoint read_map_checkpoint(const std::string& path);
// Writes PATH.tmp, flushes it to disk and renames it over PATH: a crash at any
// moment leaves either the previous checkpoint or the new one, never half of
// one. std::runtime_error naming the path when it cannot.
void write_map_checkpoint(const std::string& path, const MapCheckpoint& checkpoint);

// The pose to resume from, `gap_s` after the checkpoint: moved by the held
// control for as long as the filter would have held it (up to
// control_timeout_s after it came), as the filter itself predicts a gap in the
// odometry; its covariance grown by the most the robot could have moved
// otherwise, taken as a 2-sigma bound (sd += max_speed * gap / 2 in x and y,
// max_turn_rate * gap / 2 in theta).
slam::PoseGaussian resume_pose(const MapCheckpoint& checkpoint, double gap_s, double max_speed_mps,
                               double max_turn_rate_radps, double control_timeout_s);

}  // namespace pixyslam::slam
