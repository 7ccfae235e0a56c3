#pragma once

// The simulated world's sensor streams (apps/simulation/sim_world) as the bridges publish
// them, for feeding the estimator over DDS: used by test_estimator_node and by
// benchmarks/bench_latency. The caller chooses the stamps.

#include <cstdint>

#include "landmark_observation.h"
#include "odometry.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::test_support {

// One odometry period of `period_s` starting at `stamp_ns`, frame "base_link".
inline msg::Odometry odometry_msg(const slam::OdometrySample& s, double period_s, std::uint64_t stamp_ns) {
  msg::Odometry m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("base_link");
  m.v_mps(s.v_mps);
  m.w_radps(s.w_radps);
  m.period_s(period_s);
  m.encoder_samples(s.measured ? 5 : 0);  // 5 Arduino samples per 10 Hz period, as the bridge reports
  return m;
}

// One camera frame stamped `stamp_ns`, frame "camera"; every detection with
// range sigma 0.07 m and bearing sigma 0.027 rad.
inline msg::LandmarkObservation observation_msg(const slam::ObservationFrame& f, std::uint64_t stamp_ns) {
  msg::LandmarkObservation m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("camera");
  for (const slam::RangeBearing& rb : f.detections) {
    msg::LandmarkDetection d;
    d.landmark_id(rb.landmark_id);
    d.range_m(rb.range_m);
    d.bearing_rad(rb.bearing_rad);
    d.range_sigma_m(0.07);
    d.bearing_sigma_rad(0.027);
    m.detections().push_back(d);
  }
  return m;
}

}  // namespace pixyslam::test_support
