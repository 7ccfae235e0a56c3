#include "pixyslam/diagnostics/diagnostics_publisher.h"

#include <unistd.h>

namespace pixyslam::diagnostics {

DiagnosticsPublisher::DiagnosticsPublisher(dds::Participant& participant, std::string process, double period_s,
                                           std::function<Snapshot()> snapshot)
    : process_(std::move(process)),
      snapshot_(std::move(snapshot)),
      writer_(participant),
      start_(std::chrono::steady_clock::now()) {
  if (period_s <= 0.0) {
    stopped_ = true;
    return;
  }
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(period_s));
  thread_ = std::thread([this, period] {
    std::unique_lock<std::mutex> lock(mutex_);
    auto next = std::chrono::steady_clock::now() + period;
    while (!cv_.wait_until(lock, next, [this] { return stopping_; })) {
      lock.unlock();
      publish();
      lock.lock();
      next += period;
    }
  });
}

DiagnosticsPublisher::~DiagnosticsPublisher() { stop(); }

void DiagnosticsPublisher::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return;
    stopped_ = stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  publish();
}

void DiagnosticsPublisher::publish() {
  const Snapshot s = snapshot_();
  const Health health = tracker_.update(s.counters, s.error);
  msg::Diagnostics m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id(process_);
  m.process(process_);
  m.pid(static_cast<std::uint32_t>(::getpid()));
  m.level(static_cast<std::uint8_t>(health.level));
  m.status(health.status);
  m.uptime_s(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  const std::size_t n = std::min<std::size_t>(s.counters.size(), 128);  // the IDL bound
  m.counters().reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    msg::DiagnosticCounter c;
    c.name(s.counters[i].name);
    c.value(s.counters[i].value);
    m.counters().push_back(c);
  }
  writer_.publish(m);
}

}  // namespace pixyslam::diagnostics
