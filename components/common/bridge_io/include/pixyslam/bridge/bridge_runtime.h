#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/diagnostics/diagnostics_publisher.h"

namespace pixyslam::bridge {

// What runs a bridge node besides its parser: the DDS participant `process`
// with its one writer of `Message`, the DeviceReader thread over a ByteSource
// (reads stamped by `clock`, default dds::now_ns), the node's status lines in
// the log every status_period_s and (prefixed "final ") at stop(), and the
// start/stop life cycle.
//
// Locking: the node owns `mutex` and holds it to read its own state; the
// runtime holds it around every handler call, so handlers, publish() and the
// counters run under it. The node declares its runtime after every member its
// handlers use (the reader thread ends before those go) and calls stop() in
// its destructor (the status lines of a half-destroyed node cannot be read).
template <class Message>
class BridgeRuntime {
 public:
  // What the node does; each is called on the reader thread with `mutex` held.
  struct Handlers {
    std::function<void()> on_open;  // optional: after every successful open
    std::function<void(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns)> on_bytes;
    std::function<void(std::uint64_t now_ns)> on_poll;
    std::function<std::vector<std::string>()> status_lines;  // the node's counters as log lines
    // Optional: the node's counters for the diagnostics topic (the device's are
    // added, and an ERROR while the device is not open).
    std::function<std::vector<diagnostics::Counter>()> diagnostics;
  };

  // `log` empty: stderr_log(process).
  BridgeRuntime(const std::string& process, const dds::DdsOptions& dds_options,
                const BridgeProcessOptions& options, std::unique_ptr<ByteSource> source, LogFunction log,
                ClockFunction clock, std::mutex& mutex)
      : process_(process),
        mutex_(mutex),
        status_period_s_(options.status_period_s),
        log_(log ? std::move(log) : stderr_log(process)),
        participant_(dds_options, process),
        writer_(participant_),
        reader_(std::move(source), device_reader_options(options), log_,
                clock ? std::move(clock) : ClockFunction(&dds::now_ns)) {}
  BridgeRuntime(const BridgeRuntime&) = delete;
  BridgeRuntime& operator=(const BridgeRuntime&) = delete;

  // Logs `start_line` and starts the reader thread with `handlers`; no-op once started.
  void start(const std::string& start_line, Handlers handlers) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (started_) return;
      started_ = true;
      handlers_ = std::move(handlers);
      schedule_status();
    }
    log_(start_line);
    DeviceReader::Handlers locked;
    if (handlers_.on_open) {
      locked.on_open = [this] {
        std::lock_guard<std::mutex> lock(mutex_);
        handlers_.on_open();
      };
    }
    locked.on_bytes = [this](const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns) {
      std::lock_guard<std::mutex> lock(mutex_);
      handlers_.on_bytes(data, size, receive_ns);
    };
    locked.on_poll = [this](std::uint64_t now_ns) {
      std::lock_guard<std::mutex> lock(mutex_);
      handlers_.on_poll(now_ns);
      if (status_period_s_ > 0.0 && std::chrono::steady_clock::now() >= next_status_) {
        for (const std::string& line : handlers_.status_lines()) log_(line);
        schedule_status();
      }
    };
    reader_.start(std::move(locked));
    diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
        participant_, process_, participant_.options().diagnostics_period_s, [this] { return snapshot(); });
  }

  // Joins the reader thread (within ~50 ms) and logs the final status lines; idempotent.
  void stop() {
    reader_.stop();
    if (diagnostics_) diagnostics_->stop();
    std::lock_guard<std::mutex> lock(mutex_);
    if (!started_ || stopped_) return;
    stopped_ = true;
    for (const std::string& line : handlers_.status_lines()) log_("final " + line);
  }

  // Publishes `message` and counts the outcome; call with `mutex` held.
  void publish(Message& message) {
    if (writer_.publish(message)) {
      ++published_;
    } else {
      ++publish_failures_;
    }
  }
  // Messages written and writes DDS refused; read with `mutex` held.
  std::uint64_t published() const { return published_; }
  std::uint64_t publish_failures() const { return publish_failures_; }

  // Waits until `count` readers matched the writer; false on timeout.
  bool wait_for_readers(int count, std::chrono::milliseconds timeout) const {
    return writer_.wait_for_readers(count, timeout);
  }
  void log(const std::string& line) const { log_(line); }
  const std::string& device_name() const { return reader_.device_name(); }
  DeviceCounters device_counters() const { return reader_.counters(); }
  std::string device_status_line() const { return reader_.status_line(); }

 private:
  diagnostics::Snapshot snapshot() {
    diagnostics::Snapshot s;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (handlers_.diagnostics) s.counters = handlers_.diagnostics();
      s.counters.push_back({"published", published_, false});
      s.counters.push_back({"publish_failures", publish_failures_, true});
    }
    const DeviceCounters d = reader_.counters();
    s.counters.push_back({"device_opens", d.opens, false});
    s.counters.push_back({"device_open_failures", d.open_failures, false});
    s.counters.push_back({"device_hangups", d.hangups, true});
    s.counters.push_back({"device_read_errors", d.read_errors, true});
    s.counters.push_back({"device_bytes", d.bytes, false});
    if (d.opens <= d.hangups + d.read_errors) {
      s.error = "device '" + reader_.device_name() + "' is not open (" + std::to_string(d.open_failures) +
                " failed attempts so far)";
    }
    return s;
  }

  void schedule_status() {
    next_status_ = std::chrono::steady_clock::now() +
                   std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                       std::chrono::duration<double>(status_period_s_));
  }

  const std::string process_;
  std::mutex& mutex_;
  const double status_period_s_;
  const LogFunction log_;
  Handlers handlers_;  // set by start(), under mutex_, before the reader thread starts
  std::chrono::steady_clock::time_point next_status_;
  std::uint64_t published_ = 0;
  std::uint64_t publish_failures_ = 0;
  bool started_ = false;
  bool stopped_ = false;

  dds::Participant participant_;
  dds::Writer<Message> writer_;
  DeviceReader reader_;  // its thread uses the members above
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;  // reads all of the above
};

}  // namespace pixyslam::bridge
