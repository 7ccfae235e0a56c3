#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/diagnostics/health.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::diagnostics {

// What a process reports: its counters and, when it cannot do its job, why.
struct Snapshot {
  std::vector<Counter> counters;
  std::string error;
};

// Publishes msg::Diagnostics on pixyslam/diagnostics every `period_s` (and a
// last report from stop()) from a thread of its own: header (robot_id, seq,
// frame_id = process), process, pid, uptime, level and status (HealthTracker)
// and the counters `snapshot` returns. `snapshot` runs on that thread and must
// be thread-safe against the node. period_s <= 0: nothing is published.
class DiagnosticsPublisher {
 public:
  DiagnosticsPublisher(dds::Participant& participant, std::string process, double period_s,
                       std::function<Snapshot()> snapshot);
  ~DiagnosticsPublisher();
  DiagnosticsPublisher(const DiagnosticsPublisher&) = delete;
  DiagnosticsPublisher& operator=(const DiagnosticsPublisher&) = delete;

  // Publishes a last report and joins the thread; idempotent. Call it before
  // the objects `snapshot` reads go away.
  void stop();
  std::uint64_t published() const { return writer_.published(); }

 private:
  void publish();

  std::string process_;
  std::function<Snapshot()> snapshot_;
  dds::Writer<msg::Diagnostics> writer_;
  HealthTracker tracker_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stopping_ = false;
  bool stopped_ = false;
  std::thread thread_;
};

}  // namespace pixyslam::diagnostics
