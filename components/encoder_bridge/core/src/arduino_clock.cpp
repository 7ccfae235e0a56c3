#include "pixyslam/encoder/arduino_clock.h"

#include <cmath>
#include <stdexcept>

#include "pixyslam/encoder/wheel_odometry.h"

namespace pixyslam::encoder {

ArduinoClock::ArduinoClock(double window_s) {
  if (!(window_s > 0.0 && window_s <= 3600.0)) {
    throw std::invalid_argument("ArduinoClock: window_s must be in (0, 3600]");
  }
  window_us_ = std::llround(window_s * 1e6);
}

void ArduinoClock::restart() {
  ++counters_.restarts;
  has_last_ = false;
  window_.clear();
}

std::int64_t ArduinoClock::to_host_ns(std::uint32_t arduino_time_us, std::int64_t host_receive_ns) {
  ++counters_.samples;
  if (has_last_) {
    // Modulo 2^32: right across the micros() wrap; a step back reads as ~2^32.
    const std::uint32_t step_us = encoder::time_delta_us(arduino_time_us, last_us_);
    if (static_cast<std::int64_t>(step_us) > window_us_) {
      ++counters_.jumps;
      window_.clear();
      unwrapped_us_ = arduino_time_us;
    } else {
      unwrapped_us_ += step_us;
    }
  } else {
    unwrapped_us_ = arduino_time_us;
    has_last_ = true;
  }
  last_us_ = arduino_time_us;

  const std::int64_t bound = host_receive_ns - unwrapped_us_ * 1000;
  while (!window_.empty() && window_.back().offset_ns >= bound) window_.pop_back();
  window_.push_back({unwrapped_us_, bound});
  while (window_.front().arduino_us < unwrapped_us_ - window_us_) window_.pop_front();

  offset_ns_ = window_.front().offset_ns;
  const std::int64_t host_ns = unwrapped_us_ * 1000 + offset_ns_;
  last_excess_delay_ns_ = host_receive_ns - host_ns;
  return host_ns;
}

}  // namespace pixyslam::encoder
