#include "pixyslam/encoder_node/odometry_conversions.h"

#include <cmath>

namespace pixyslam::encoder_node {

std::uint64_t to_stamp_ns(double t_s, std::uint64_t epoch_ns) {
  const double ns = std::round(t_s * 1e9);
  if (ns < 0.0 && -ns >= static_cast<double>(epoch_ns)) return 0;
  return ns < 0.0 ? epoch_ns - static_cast<std::uint64_t>(-ns) : epoch_ns + static_cast<std::uint64_t>(ns);
}

msg::Odometry to_odometry_msg(const encoder::OdometryOutput& o, std::uint32_t encoder_samples,
                              std::uint64_t epoch_ns) {
  msg::Odometry m;
  m.header().stamp_ns(to_stamp_ns(o.t_s, epoch_ns));
  m.header().frame_id("base_link");
  m.v_mps(o.v_mps);
  m.w_radps(o.w_radps);
  m.period_s(o.duration_s);
  m.distance_m(o.distance_m);
  m.rotation_rad(o.rotation_rad);
  m.encoder_samples(encoder_samples);
  return m;
}

}  // namespace pixyslam::encoder_node
