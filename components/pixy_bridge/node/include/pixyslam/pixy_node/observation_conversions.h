#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "landmark_observation.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_geometry.h"

namespace pixyslam::pixy_node {

// Core -> message conversions of the pixy bridge, in one place.

// Most detections one LandmarkObservation carries (the IDL bound).
inline constexpr std::size_t kMaxDetectionsPerMessage = 64;

msg::PixyBlock to_block_msg(const pixy::PixyBlock& block);
msg::LandmarkDetection to_detection_msg(const pixy::Detection& detection);

// One camera frame and its detections (pixy::to_detections of that frame), frame
// "camera": camera_frame = the frame's index, blocks_in_frame = its blocks,
// blocks_rejected = blocks that gave no detection. Detections beyond
// kMaxDetectionsPerMessage are left out. The caller's Writer fills seq and robot_id.
msg::LandmarkObservation to_observation_msg(const pixy::PixyFrame& frame,
                                            const std::vector<pixy::Detection>& detections,
                                            std::uint64_t stamp_ns);

}  // namespace pixyslam::pixy_node
