#pragma once

#include <cstdint>
#include <deque>
#include <variant>
#include <vector>

#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// Odometry as it arrives from the encoder bridge: (v, w) held over
// [sample.t_s, sample.t_s + period_s).
struct OdometryInput {
  OdometrySample sample;
  double period_s = 0.0;
  std::uint64_t seq = 0;  // message sequence number, carried through for the output
};

struct ObservationInput {
  ObservationFrame frame;
  std::uint64_t seq = 0;
};

using SensorInput = std::variant<OdometryInput, ObservationInput>;

// How long a live stream may lag behind the wall clock before the queue stops
// waiting for it. Odometry is stamped at the start of its period and sent at
// its end, so it lags by about one period; camera frames by their transport only.
struct SensorQueueOptions {
  double odometry_max_delay_s = 0.3;
  double observation_max_delay_s = 0.05;
};

struct SensorQueueCounters {
  std::uint64_t odometry_in = 0;
  std::uint64_t observations_in = 0;
  std::uint64_t released = 0;
  std::uint64_t reordered = 0;  // arrived after a younger sample of its stream; sorted in
  std::uint64_t late = 0;       // older than what was already released: released at once,
                                // the filter applies it at its current time
};

// Merges the odometry and camera streams into one time-ordered sequence for
// the filter (cartographer's OrderedMultiQueue, for two live streams). A sample
// stamped t is released once neither stream can still deliver something older:
// the odometry stream is known up to (last stamp + period), the camera stream
// up to its last stamp, and a stream silent for longer than its max delay no
// longer holds the other back. At equal stamps odometry goes first (a frame at
// t uses the control that starts at t). Times are seconds on the stamps' clock;
// `now_s` is the wall clock on the same clock, passed in. Thread-compatible.
class SensorQueue {
 public:
  explicit SensorQueue(const SensorQueueOptions& options);

  void push(const OdometryInput& odometry);
  void push(const ObservationInput& observation);

  // Samples that may go to the filter now, oldest first.
  std::vector<SensorInput> pop_ready(double now_s);
  // Everything still held, oldest first (end of run).
  std::vector<SensorInput> pop_all();

  // Wall time at which a held sample becomes releasable without new input
  // (infinity if nothing is held).
  double next_release_s() const;
  std::size_t size() const { return odometry_.size() + observations_.size(); }
  const SensorQueueCounters& counters() const { return counters_; }

 private:
  double odometry_horizon_s(double now_s) const;
  double observation_horizon_s(double now_s) const;
  bool is_late(double t_s) const { return has_released_ && t_s < released_until_s_; }

  SensorQueueOptions options_;
  std::deque<OdometryInput> odometry_;         // sorted by stamp
  std::deque<ObservationInput> observations_;  // sorted by stamp
  bool has_odometry_ = false;
  double odometry_known_until_s_ = 0.0;
  bool has_observation_ = false;
  double observation_known_until_s_ = 0.0;
  bool has_released_ = false;
  double released_until_s_ = 0.0;
  SensorQueueCounters counters_;
};

}  // namespace pixyslam::slam
