#pragma once

#include <cstdint>
#include <deque>
#include <limits>
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

// The time an input refers to.
inline double input_time(const SensorInput& input) {
  if (const auto* o = std::get_if<OdometryInput>(&input)) return o->sample.t_s;
  return std::get<ObservationInput>(input).frame.t_s;
}

// How long a live stream may lag behind the wall clock before the queue stops
// waiting for it. Odometry is stamped at the start of its period and sent at
// its end, so it lags by about one period; camera frames by their transport only.
struct SensorQueueOptions {
  double odometry_max_delay_s = 0.3;
  double observation_max_delay_s = 0.05;
  // After an outage (a sample arriving later than its stream's max delay after
  // its stamp), a silent stream still holds the other back this long: the
  // streams' backlogs come back at different times (reliable DDS resends on
  // its heartbeat), and are merged in stamp order if both arrive within it.
  // A stream not seen yet holds the other back during this wait too (bridges
  // that held their first messages until every reader matched release their
  // backlogs at slightly different times).
  double recovery_wait_s = 1.0;
};

struct SensorQueueCounters {
  std::uint64_t odometry_in = 0;
  std::uint64_t observations_in = 0;
  std::uint64_t released = 0;
  std::uint64_t reordered = 0;  // arrived after a younger sample of its stream; sorted in
  std::uint64_t late = 0;       // older than what was already released: released at once (the
                                // filter applies a frame at its stamp, FastSlam2::frames_late)
};

// Merges the odometry and camera streams into one time-ordered sequence for
// the filter (cartographer's OrderedMultiQueue, for two live streams). A sample
// stamped t is released once neither stream can still deliver something older:
// the odometry stream is known up to (last stamp + period), the camera stream
// up to its last stamp. A stream holds the other back while it keeps arriving
// (its last arrival within its max delay), however far its stamps lag, so a
// backlog delivered after a network outage is merged in stamp order; a stream
// silent for longer than its max delay, in stamps and in arrivals, no longer
// holds the other back, except during the recovery wait after an outage. At equal stamps odometry goes first (a frame at t uses
// the control that starts at t). Times are seconds on the stamps' clock; `now_s`
// and `arrival_s` are the wall clock on the same clock, passed in (an unknown
// arrival, -infinity, counts as long ago). Thread-compatible.
class SensorQueue {
 public:
  explicit SensorQueue(const SensorQueueOptions& options);

  void push(const OdometryInput& odometry, double arrival_s = -std::numeric_limits<double>::infinity());
  void push(const ObservationInput& observation, double arrival_s = -std::numeric_limits<double>::infinity());

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
  void note_arrival(double stamp_end_s, double arrival_s, double max_delay_s);
  bool is_late(double t_s) const { return has_released_ && t_s < released_until_s_; }

  SensorQueueOptions options_;
  std::deque<OdometryInput> odometry_;         // sorted by stamp
  std::deque<ObservationInput> observations_;  // sorted by stamp
  bool has_odometry_ = false;
  double odometry_known_until_s_ = 0.0;
  double odometry_arrival_s_ = -std::numeric_limits<double>::infinity();
  bool has_observation_ = false;
  double observation_known_until_s_ = 0.0;
  double observation_arrival_s_ = -std::numeric_limits<double>::infinity();
  double recovery_until_s_ = -std::numeric_limits<double>::infinity();
  bool has_released_ = false;
  double released_until_s_ = 0.0;
  SensorQueueCounters counters_;
};

}  // namespace pixyslam::slam
