#pragma once
// Sample messages with every field set from one index, for tests that send,
// encode or record them.
#include <cstdint>

#include "odometry.h"

namespace pixyslam::test {

inline msg::Odometry sample_odometry(int i) {
  msg::Odometry m;
  m.header().stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(i) * 100'000'000ull);
  m.header().frame_id("base_link");
  m.v_mps(0.01 * i);
  m.w_radps(-0.002 * i);
  m.period_s(0.1);
  m.distance_m(0.001 * i);
  m.rotation_rad(-0.0002 * i);
  m.encoder_samples(static_cast<std::uint32_t>(i % 7));
  return m;
}

}  // namespace pixyslam::test
