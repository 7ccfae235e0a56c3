#include "pixyslam/slam_node/sensor_inbox.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>

#include "pixyslam/dds/endpoints.h"
#include "pixyslam/slam_node/map_state_conversions.h"

namespace pixyslam::slam_node {

SensorInbox::SensorInbox(const slam::SensorQueueOptions& queue, bool use_detection_sigmas)
    : use_detection_sigmas_(use_detection_sigmas),
      max_pending_(queue.max_held),
      gate_(2, queue.max_stamp_jump_s),
      queue_(queue) {}

void SensorInbox::push(const msg::Odometry& m) { enqueue(m); }
void SensorInbox::push(const msg::LandmarkObservation& m) { enqueue(m); }

void SensorInbox::enqueue(Message&& m) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    // The consumer is behind by max_pending_ samples: a flood.
    if (inbox_.size() >= max_pending_) {
      ++overflow_;
      return;
    }
    inbox_.push_back(std::move(m));
  }
  inbox_cv_.notify_one();
}

void SensorInbox::stop() {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    stopping_ = true;
  }
  inbox_cv_.notify_all();
}

std::uint64_t SensorInbox::epoch_ns() const {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  return epoch_ns_;
}

slam::SensorQueueCounters SensorInbox::queue_counters() const {
  slam::SensorQueueCounters c;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    c = queue_.counters();
    c.ahead += gate_.dropped();
    c.rebases = gate_.rebases();
  }
  std::lock_guard<std::mutex> lock(inbox_mutex_);
  c.overflow += overflow_;
  return c;
}

namespace {
std::uint64_t steady_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
}
}  // namespace

double SensorInbox::now_s() const {
  return static_cast<double>(static_cast<std::int64_t>(dds::now_ns() - epoch_ns_)) * 1e-9;
}

SensorInbox::Ready SensorInbox::wait_ready() {
  std::deque<Message> batch;
  Ready out;
  {
    std::unique_lock<std::mutex> lock(inbox_mutex_);
    // Wake for new input, for a held sample's release time, or periodically.
    double wait_s = 0.1;
    {
      std::lock_guard<std::mutex> queue_lock(queue_mutex_);
      if (has_epoch_ && queue_.size() > 0) wait_s = std::clamp(queue_.next_release_s() - now_s(), 0.0, 0.1);
    }
    inbox_cv_.wait_for(lock, std::chrono::duration<double>(wait_s), [this] { return !inbox_.empty() || stopping_; });
    batch.swap(inbox_);
    out.stopping = stopping_;
  }
  std::lock_guard<std::mutex> queue_lock(queue_mutex_);
  const auto stamp_of = [](const Message& m) {
    return std::visit([](const auto& x) { return x.header().stamp_ns(); }, m);
  };
  std::vector<Message> passed;
  for (Message& m : batch) {
    const std::uint64_t stamp = stamp_of(m);
    const std::size_t stream = m.index();
    std::vector<Message> now = gate_.offer(std::move(m), stream, stamp, steady_ns());
    if (gate_.take_rebased()) {
      // What the queue holds, and what this batch passed before, is kept only
      // when it is at the new time (the queue's behind samples were late at the
      // old one and are dropped with it).
      passed.erase(std::remove_if(passed.begin(), passed.end(),
                                  [&](const Message& p) { return !gate_.current(stamp_of(p)); }),
                   passed.end());
      queue_.restart();
      has_epoch_ = false;  // the next sample passed on sets it: times near 0 again
      out.rebased = true;
      out.rebased_to_ns = gate_.reference_ns();
    }
    for (Message& p : now) passed.push_back(std::move(p));
  }
  if (out.stopping) {
    for (Message& p : gate_.flush()) passed.push_back(std::move(p));
  }
  for (const Message& m : passed) {
    if (!has_epoch_) {
      epoch_ns_ = stamp_of(m);
      has_epoch_ = true;
    }
    const double arrival_s = now_s();
    if (const auto* odometry = std::get_if<msg::Odometry>(&m)) {
      queue_.push(to_odometry_input(*odometry, epoch_ns_), arrival_s);
    } else {
      queue_.push(to_observation_input(std::get<msg::LandmarkObservation>(m), epoch_ns_, use_detection_sigmas_),
                  arrival_s);
    }
  }
  if (has_epoch_) out.inputs = out.stopping ? queue_.pop_all() : queue_.pop_ready(now_s());
  return out;
}

void step_each(const std::vector<slam::SensorInput>& inputs,
               const std::function<void(const slam::SensorInput&)>& step, const char* process, std::mutex& mutex,
               std::uint64_t& errors) {
  for (const slam::SensorInput& input : inputs) {
    try {
      step(input);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      if (errors++ % 100 == 0) {
        std::fprintf(stderr, "%s: input stamped %.3f s dropped: %s (%llu so far)\n", process, slam::input_time(input),
                     e.what(), static_cast<unsigned long long>(errors));
      }
    }
  }
}

}  // namespace pixyslam::slam_node
