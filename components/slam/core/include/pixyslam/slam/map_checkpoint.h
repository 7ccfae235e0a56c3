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
};

// The filter's estimate as a checkpoint: its mean pose and covariance
// (symmetrised) at stamp_ns, and its map (the landmarks' weighted mixture over
// the particles, or those of the best particle).
MapCheckpoint checkpoint_of(const FastSlam2& filter, std::uint64_t stamp_ns, bool mixture_landmarks);

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

// The pose to resume from, `gap_s` after the checkpoint: its covariance grown
// by the most the robot could have moved meanwhile, taken as a 2-sigma bound
// (sd += max_speed * gap / 2 in x and y, max_turn_rate * gap / 2 in theta).
slam::PoseGaussian resume_pose(const MapCheckpoint& checkpoint, double gap_s, double max_speed_mps,
                               double max_turn_rate_radps);

}  // namespace pixyslam::slam
