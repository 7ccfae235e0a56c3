#include "pixyslam/slam/sensor_queue.h"

#include <algorithm>
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

void SensorQueue::push(const OdometryInput& odometry) {
  ++counters_.odometry_in;
  const double end = stamp(odometry) + std::max(0.0, odometry.period_s);
  odometry_known_until_s_ = has_odometry_ ? std::max(odometry_known_until_s_, end) : end;
  has_odometry_ = true;
  if (is_late(stamp(odometry))) ++counters_.late;
  if (insert_sorted(odometry_, odometry)) ++counters_.reordered;
}

void SensorQueue::push(const ObservationInput& observation) {
  ++counters_.observations_in;
  const double t = stamp(observation);
  observation_known_until_s_ = has_observation_ ? std::max(observation_known_until_s_, t) : t;
  has_observation_ = true;
  if (is_late(t)) ++counters_.late;
  if (insert_sorted(observations_, observation)) ++counters_.reordered;
}

double SensorQueue::odometry_horizon_s(double now_s) const {
  const double waited = now_s - options_.odometry_max_delay_s;
  return has_odometry_ ? std::max(odometry_known_until_s_, waited) : waited;
}

double SensorQueue::observation_horizon_s(double now_s) const {
  const double waited = now_s - options_.observation_max_delay_s;
  return has_observation_ ? std::max(observation_known_until_s_, waited) : waited;
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
  if (!odometry_.empty()) {
    t = std::min(t, stamp(odometry_.front()) + options_.observation_max_delay_s);
  }
  if (!observations_.empty()) {
    t = std::min(t, stamp(observations_.front()) + options_.odometry_max_delay_s);
  }
  return t;
}

}  // namespace pixyslam::slam
