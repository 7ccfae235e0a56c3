#include "pixyslam/slam/sensor_queue.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pixyslam::slam {

namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

double stamp(const OdometryInput& o) { return o.sample.t_s; }
double stamp(const ObservationInput& o) { return o.frame.t_s; }

// Inserts keeping the deque sorted by stamp (stable: equal stamps keep arrival
// order); true if it went before an element already there.
template <class T>
bool insert_sorted(std::deque<T>& queue, const T& item) {
  auto it = std::upper_bound(queue.begin(), queue.end(), stamp(item),
                             [](double t, const T& other) { return t < stamp(other); });
  const bool reordered = it != queue.end();
  queue.insert(it, item);
  return reordered;
}

}  // namespace

SensorQueue::SensorQueue(const SensorQueueOptions& options) : options_(options) {}

void SensorQueue::restart() {
  const SensorQueueCounters kept = counters_;
  *this = SensorQueue(options_);
  counters_ = kept;
}

bool SensorQueue::admit() {
  if (size() >= options_.max_held) {
    ++counters_.overflow;
    return false;
  }
  return true;
}

bool SensorQueue::push(const OdometryInput& odometry, double arrival_s) {
  if (!admit()) return false;
  ++counters_.odometry_in;
  odometry_arrival_s_ = std::max(odometry_arrival_s_, arrival_s);
  // A period from the wire that is not finite or longer than a stamp may jump
  // (max_stamp_jump_s; the encoder bridge's longest is 10 s) would make the stream
  // known far ahead and release frames before the odometry that covers them.
  const double period = std::isfinite(odometry.period_s)
                            ? std::clamp(odometry.period_s, 0.0, options_.max_stamp_jump_s)
                            : 0.0;
  const double end = stamp(odometry) + period;
  note_arrival(end, arrival_s, options_.odometry_max_delay_s);
  odometry_known_until_s_ = has_odometry_ ? std::max(odometry_known_until_s_, end) : end;
  has_odometry_ = true;
  if (is_late(stamp(odometry))) ++counters_.late;
  if (insert_sorted(odometry_, odometry)) ++counters_.reordered;
  return true;
}

bool SensorQueue::push(const ObservationInput& observation, double arrival_s) {
  const double t = stamp(observation);
  if (!admit()) return false;
  ++counters_.observations_in;
  observation_arrival_s_ = std::max(observation_arrival_s_, arrival_s);
  note_arrival(t, arrival_s, options_.observation_max_delay_s);
  observation_known_until_s_ = has_observation_ ? std::max(observation_known_until_s_, t) : t;
  has_observation_ = true;
  if (is_late(t)) ++counters_.late;
  if (insert_sorted(observations_, observation)) ++counters_.reordered;
  return true;
}

namespace {

// How far a stream is known: its stamps, and while it keeps arriving nothing
// more; once silent for `max_delay_s` (stamps and arrivals), up to now - max delay;
// never seen: up to now - max delay, except during a recovery wait.
double horizon(bool has, double known_until_s, double arrival_s, double max_delay_s, double now_s,
               bool recovering) {
  const double waited = now_s - max_delay_s;
  // Not seen yet: during a recovery wait it may be the other backlog still on its way (two bridges
  // that held their messages at start, node.wait_readers), so it holds everything back.
  if (!has) return recovering ? -kNever : waited;
  if (arrival_s >= waited || recovering) return known_until_s;
  return std::max(known_until_s, waited);
}

}  // namespace

void SensorQueue::note_arrival(double stamp_end_s, double arrival_s, double max_delay_s) {
  if (arrival_s - stamp_end_s > max_delay_s) {
    recovery_until_s_ = std::max(recovery_until_s_, arrival_s + options_.recovery_wait_s);
  }
}

double SensorQueue::odometry_horizon_s(double now_s) const {
  return horizon(has_odometry_, odometry_known_until_s_, odometry_arrival_s_, options_.odometry_max_delay_s, now_s,
                 now_s < recovery_until_s_);
}

double SensorQueue::observation_horizon_s(double now_s) const {
  return horizon(has_observation_, observation_known_until_s_, observation_arrival_s_,
                 options_.observation_max_delay_s, now_s, now_s < recovery_until_s_);
}

std::vector<SensorInput> SensorQueue::pop_ready(double now_s) {
  std::vector<SensorInput> out;
  const double odometry_horizon = odometry_horizon_s(now_s);
  const double observation_horizon = observation_horizon_s(now_s);
  while (!odometry_.empty() || !observations_.empty()) {
    const bool take_odometry =
        !odometry_.empty() &&
        (observations_.empty() || stamp(odometry_.front()) <= stamp(observations_.front()));
    const double t = take_odometry ? stamp(odometry_.front()) : stamp(observations_.front());
    // Odometry at t is safe once no camera frame older than t can come, and a
    // frame at t once the odometry covering t is in.
    const bool ready = take_odometry ? t <= observation_horizon : t <= odometry_horizon;
    if (!ready && !is_late(t)) break;
    if (take_odometry) {
      out.emplace_back(odometry_.front());
      odometry_.pop_front();
    } else {
      out.emplace_back(observations_.front());
      observations_.pop_front();
    }
    released_until_s_ = has_released_ ? std::max(released_until_s_, t) : t;
    has_released_ = true;
    ++counters_.released;
  }
  return out;
}

std::vector<SensorInput> SensorQueue::pop_all() {
  return pop_ready(kNever);
}

double SensorQueue::next_release_s() const {
  double t = kNever;
  // Held back by the other stream: until it has been silent for its max delay.
  if (!odometry_.empty()) {
    t = std::min(t, std::max(std::max(stamp(odometry_.front()), observation_arrival_s_) +
                                 options_.observation_max_delay_s,
                             recovery_until_s_));
  }
  if (!observations_.empty()) {
    t = std::min(t, std::max(std::max(stamp(observations_.front()), odometry_arrival_s_) +
                                 options_.odometry_max_delay_s,
                             recovery_until_s_));
  }
  return t;
}

}  // namespace pixyslam::slam
