#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
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
// first stamp passed on (the epoch; a replay shifted by a constant computes the
// same). A stamp that jumps more than max_stamp_jump_s ahead waits for the next
// sample to confirm it (slam::StampGate); the first sample too. Thread-safe.
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
    // The time went back (StampGate: a wrong jump undone): what was held is
    // dropped, the inputs are at the new time, older than those before, on a
    // new epoch (epoch_ns()).
    bool rebased = false;
    std::uint64_t rebased_to_ns = 0;  // the stamp the time went back to
  };
  // Waits for new input, for a held sample's release time, for stop() or at
  // most 0.1 s, then returns what may be consumed now.
  Ready wait_ready();

  // 0 until the first message arrived.
  std::uint64_t epoch_ns() const;
  // The queue's counters, with what the inbox dropped before it (ahead: a stamp
  // jump no sample confirmed; overflow: max_held samples waiting already).
  slam::SensorQueueCounters queue_counters() const;

 private:
  using Message = std::variant<msg::Odometry, msg::LandmarkObservation>;
  void enqueue(Message&& m);
  double now_s() const;  // wall clock on the epoch's time base (queue_mutex_ held)

  const bool use_detection_sigmas_;
  const std::size_t max_pending_;
  mutable std::mutex inbox_mutex_;
  std::condition_variable inbox_cv_;
  std::deque<Message> inbox_;
  bool stopping_ = false;
  std::uint64_t overflow_ = 0;  // dropped by enqueue()

  mutable std::mutex queue_mutex_;
  slam::StampGate<Message> gate_;  // streams by Message index: a jump needs its stream's next sample
  slam::SensorQueue queue_;
  bool has_epoch_ = false;
  std::uint64_t epoch_ns_ = 0;
};

// Runs `step` on every input in order. An input it throws on (an invariant a
// hostile sample broke) is dropped and counted in `errors`, under `mutex`; the
// first and every 100th are logged as "PROCESS: input stamped T s dropped: ...".
void step_each(const std::vector<slam::SensorInput>& inputs,
               const std::function<void(const slam::SensorInput&)>& step, const char* process, std::mutex& mutex,
               std::uint64_t& errors);

}  // namespace pixyslam::slam_node
