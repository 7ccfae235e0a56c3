#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
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
  // A sample stamped more than this after the newest one is held until the
  // next sample confirms the new time (StampGate): one stamp from a wrong clock
  // or a hostile sender would move the filter's time past every real sample.
  double max_stamp_jump_s = 10.0;
  // Samples waiting at most (inbox and queue each); more are dropped (a flood).
  std::size_t max_held = 20000;
};

struct SensorQueueCounters {
  std::uint64_t odometry_in = 0;
  std::uint64_t observations_in = 0;
  std::uint64_t released = 0;
  std::uint64_t reordered = 0;  // arrived after a younger sample of its stream; sorted in
  std::uint64_t late = 0;       // older than what was already released: released at once (the
                                // filter applies a frame at its stamp, FastSlam2::frames_late)
  std::uint64_t ahead = 0;      // dropped: a jump past max_stamp_jump_s that no sample confirmed (StampGate)
  std::uint64_t overflow = 0;   // dropped: max_held samples were waiting already
  std::uint64_t rebases = 0;    // the time went back to what the samples said (StampGate)
};

// Passes on samples in arrival order unless a stamp jumps more than
// max_jump_s past the newest one passed on (of any stream): that sample is
// held until the next sample of its own stream confirms the new time (stamped
// within max_jump_s of it, as after a restart or a clock step), and dropped
// (counted) when its stream goes on at the old time or max_hold_s passes: one
// stamp from a wrong clock or a hostile sender does not move the time. The
// first sample of each stream is held the same way until the time is known,
// so that none can set it alone. Two consistent samples of one stream do move
// it; if that was wrong (a hostile sender's pair, a clock stepped back), every
// sample after is more than max_jump_s behind: once only such samples came for
// max_hold_s (at least three), the time goes back to theirs (rebased(): the
// consumer restarts its clock-dependent state), so no pair of samples can stop
// the time for good. Stamps in ns on the stamps' clock, arrivals in ns on any
// steady clock. Thread-compatible.
template <class T>
class StampGate {
 public:
  StampGate(std::size_t streams, double max_jump_s, double max_hold_s = 1.0)
      : max_jump_ns_(max_jump_s * 1e9), max_hold_ns_(max_hold_s * 1e9), held_(streams) {}

  // What may go on now, in arrival order: nothing (held), or this sample and
  // whatever the time it confirms releases.
  std::vector<T> offer(T item, std::size_t stream, std::uint64_t stamp_ns, std::uint64_t arrival_ns) {
    std::vector<T> out;
    for (Held& h : held_) {
      if (h.has && static_cast<double>(arrival_ns) - static_cast<double>(h.arrival_ns) > max_hold_ns_) drop(h);
    }
    Held& mine = held_[stream];
    if (behind(stamp_ns)) {
      if (behind_count_ == 0) {
        behind_since_ns_ = arrival_ns;
        behind_newest_ns_ = stamp_ns;
      }
      ++behind_count_;
      behind_newest_ns_ = std::max(behind_newest_ns_, stamp_ns);
      if (behind_count_ >= kRebaseSamples &&
          static_cast<double>(arrival_ns) - static_cast<double>(behind_since_ns_) >= max_hold_ns_) {
        reference_ns_ = behind_newest_ns_;
        behind_count_ = 0;
        for (Held& h : held_) {
          if (h.has) drop(h);
        }
        ++rebases_;
        rebased_ = true;
      }
    } else if (known(stamp_ns)) {
      behind_count_ = 0;
    }
    if (known(stamp_ns)) {
      reference_ns_ = std::max(reference_ns_, stamp_ns);
      if (mine.has) drop(mine);  // its stream goes on at the old time
      out.push_back(std::move(item));
    } else if (mine.has && std::abs(static_cast<double>(stamp_ns) - static_cast<double>(mine.stamp_ns)) <= max_jump_ns_) {
      reference_ns_ = has_reference_ ? std::max({reference_ns_, mine.stamp_ns, stamp_ns})
                                     : std::max(mine.stamp_ns, stamp_ns);
      has_reference_ = true;
      mine.has = false;
      out.push_back(std::move(mine.item));
      out.push_back(std::move(item));
    } else {
      if (mine.has) drop(mine);
      mine = Held{true, std::move(item), stamp_ns, arrival_ns};
    }
    for (Held& h : held_) {
      if (h.has && known(h.stamp_ns)) {
        h.has = false;
        out.push_back(std::move(h.item));
      }
    }
    return out;
  }
  // At the end: held first samples go on while the time is still unknown;
  // held jumps are dropped.
  std::vector<T> flush() {
    std::vector<T> out;
    for (Held& h : held_) {
      if (!h.has) continue;
      if (has_reference_) {
        drop(h);
      } else {
        h.has = false;
        out.push_back(std::move(h.item));
      }
    }
    return out;
  }
  std::uint64_t dropped() const { return dropped_; }
  std::uint64_t rebases() const { return rebases_; }
  // True once after an offer() that moved the time back (what it returned is at the new time).
  bool take_rebased() { return std::exchange(rebased_, false); }
  // The time (the newest stamp passed on, or the one a rebase went back to).
  std::uint64_t reference_ns() const { return reference_ns_; }
  // Within max_jump_s of the time either way.
  bool current(std::uint64_t stamp_ns) const { return known(stamp_ns) && !behind(stamp_ns); }

 private:
  static constexpr std::uint64_t kRebaseSamples = 3;
  struct Held {
    bool has = false;
    T item{};
    std::uint64_t stamp_ns = 0;
    std::uint64_t arrival_ns = 0;
  };
  bool behind(std::uint64_t stamp_ns) const {
    return has_reference_ && static_cast<double>(reference_ns_) - static_cast<double>(stamp_ns) > max_jump_ns_;
  }
  bool known(std::uint64_t stamp_ns) const {
    return has_reference_ && static_cast<double>(stamp_ns) - static_cast<double>(reference_ns_) <= max_jump_ns_;
  }
  void drop(Held& h) {
    h.has = false;
    ++dropped_;
  }

  double max_jump_ns_;
  double max_hold_ns_;
  std::vector<Held> held_;
  bool has_reference_ = false;
  std::uint64_t reference_ns_ = 0;
  std::uint64_t dropped_ = 0;
  // The run of samples behind the time with none at it between (0: none),
  // since behind_since_ns_ (arrival).
  std::uint64_t behind_count_ = 0;
  std::uint64_t behind_since_ns_ = 0;
  std::uint64_t behind_newest_ns_ = 0;
  std::uint64_t rebases_ = 0;
  bool rebased_ = false;
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

  // False (and counted) when the sample is dropped: max_held samples held.
  bool push(const OdometryInput& odometry, double arrival_s = -std::numeric_limits<double>::infinity());
  bool push(const ObservationInput& observation, double arrival_s = -std::numeric_limits<double>::infinity());

  // Samples that may go to the filter now, oldest first.
  std::vector<SensorInput> pop_ready(double now_s);
  // Everything still held, oldest first (end of run).
  std::vector<SensorInput> pop_all();
  // Drops what is held and forgets the streams' times (the time went back:
  // StampGate::rebased()); the counters go on.
  void restart();

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
  bool admit();

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
