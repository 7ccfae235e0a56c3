#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <variant>
#include <vector>

#include "landmark_observation.h"
#include "odometry.h"
#include "pixyslam/slam/sensor_queue.h"

namespace pixyslam::slam_node {

// The DDS side of a consumer of the sensor topics that needs them in stamp
// order on one thread (the estimator's filter, the map optimiser): DDS
// callbacks only push(); the consumer's thread calls wait_ready() in a loop and
// gets the inputs the SensorQueue releases, oldest first, on seconds since the
// first stamp received (the epoch; a replay shifted by a constant computes the
// same). Thread-safe.
class SensorInbox {
 public:
  SensorInbox(const slam::SensorQueueOptions& queue, bool use_detection_sigmas);

  void push(const msg::Odometry& m);
  void push(const msg::LandmarkObservation& m);
  // Makes the next wait_ready() return at once with everything still held.
  void stop();

  struct Ready {
    std::vector<slam::SensorInput> inputs;  // in stamp order
    bool stopping = false;                  // stop() was called: this is the last batch
  };
  // Waits for new input, for a held sample's release time, for stop() or at
  // most 0.1 s, then returns what may be consumed now.
  Ready wait_ready();

  // 0 until the first message arrived.
  std::uint64_t epoch_ns() const;
  slam::SensorQueueCounters queue_counters() const;

 private:
  using Message = std::variant<msg::Odometry, msg::LandmarkObservation>;
  void enqueue(Message&& m);
  double now_s() const;  // wall clock on the epoch's time base (queue_mutex_ held)

  const bool use_detection_sigmas_;
  std::mutex inbox_mutex_;
  std::condition_variable inbox_cv_;
  std::deque<Message> inbox_;
  bool stopping_ = false;

  mutable std::mutex queue_mutex_;
  slam::SensorQueue queue_;
  bool has_epoch_ = false;
  std::uint64_t epoch_ns_ = 0;
};

}  // namespace pixyslam::slam_node
