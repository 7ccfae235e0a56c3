#pragma once

#include <cstdint>

#include "odometry.h"
#include "pixyslam/encoder/wheel_odometry.h"

namespace pixyslam::encoder_node {

// Core -> message conversions of the encoder bridge, in one place. Core times
// are seconds since `epoch_ns` (a whole second of the host clock, so doubles
// keep sub-microsecond resolution).

// epoch_ns + t_s rounded to the nanosecond (0 if that would be negative).
std::uint64_t to_stamp_ns(double t_s, std::uint64_t epoch_ns);

// One accumulator period as a message: stamped at the period's START (the
// filter holds (v, w) from the stamp until the next message), frame
// "base_link". The caller's Writer fills seq and robot_id.
msg::Odometry to_odometry_msg(const encoder::OdometryOutput& output, std::uint32_t encoder_samples,
                              std::uint64_t epoch_ns);

}  // namespace pixyslam::encoder_node
