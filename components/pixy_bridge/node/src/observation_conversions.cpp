#include "pixyslam/pixy_node/observation_conversions.h"

#include <algorithm>

namespace pixyslam::pixy_node {

msg::PixyBlock to_block_msg(const pixy::PixyBlock& b) {
  msg::PixyBlock m;
  m.signature(b.signature);
  m.x_px(b.x);
  m.y_px(b.y);
  m.width_px(b.width);
  m.height_px(b.height);
  m.angle_deg(b.angle_deg);
  return m;
}

msg::LandmarkDetection to_detection_msg(const pixy::Detection& d) {
  msg::LandmarkDetection m;
  m.landmark_id(d.landmark_id);
  m.range_m(d.range_m);
  m.bearing_rad(d.bearing_rad);
  m.range_sigma_m(d.range_sigma_m);
  m.bearing_sigma_rad(d.bearing_sigma_rad);
  m.block(to_block_msg(d.block));
  return m;
}

msg::LandmarkObservation to_observation_msg(const pixy::PixyFrame& frame,
                                            const std::vector<pixy::Detection>& detections,
                                            std::uint64_t stamp_ns) {
  msg::LandmarkObservation m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("camera");
  m.camera_frame(static_cast<std::uint32_t>(frame.index));
  m.blocks_in_frame(static_cast<std::uint32_t>(frame.blocks.size()));
  m.blocks_rejected(static_cast<std::uint32_t>(frame.blocks.size() - std::min(frame.blocks.size(), detections.size())));
  const std::size_t n = std::min(detections.size(), kMaxDetectionsPerMessage);
  m.detections().reserve(n);
  for (std::size_t i = 0; i < n; ++i) m.detections().push_back(to_detection_msg(detections[i]));
  return m;
}

}  // namespace pixyslam::pixy_node
