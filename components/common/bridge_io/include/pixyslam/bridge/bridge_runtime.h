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
// node.wait_readers: from start() on the device is read as usual (stamps are
// the read times), but the messages are held until that many readers matched
// or node.wait_readers_timeout_s passed, then written in order: every reader
// gets the run from seq 1, and no sensor data is lost meanwhile.
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
    // Optional: DeviceReader::Handlers::poll_deadline_ns.
    std::function<std::uint64_t()> poll_deadline_ns;
  };

  // `log` empty: stderr_log(process).
  BridgeRuntime(const std::string& process, const dds::DdsOptions& dds_options,
                const BridgeProcessOptions& options, std::unique_ptr<ByteSource> source, LogFunction log,
                ClockFunction clock, std::mutex& mutex)
      : process_(process),
        mutex_(mutex),
        status_period_s_(options.status_period_s),
        log_(log ? std::move(log) : stderr_log(process)),
        hold_readers_(options.wait_readers),
        hold_timeout_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(options.wait_readers_timeout_s))),
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
      holding_ = hold_readers_ > 0;
      hold_deadline_ = std::chrono::steady_clock::now() + hold_timeout_;
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
      if (holding_) release_hold();
      if (status_period_s_ > 0.0 && std::chrono::steady_clock::now() >= next_status_) {
        for (const std::string& line : handlers_.status_lines()) log_(line);
        schedule_status();
      }
    };
    if (handlers_.poll_deadline_ns) {
      locked.poll_deadline_ns = [this] {
        std::lock_guard<std::mutex> lock(mutex_);
        return handlers_.poll_deadline_ns();
      };
    }
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
    if (holding_ && !held_.empty()) {
      log_("stopped before node.wait_readers was met: " + std::to_string(held_.size()) + " held messages not sent");
    }
    for (const std::string& line : handlers_.status_lines()) log_("final " + line);
  }

  // Publishes `message` (or holds it, see node.wait_readers) and counts the outcome; call with `mutex` held.
  void publish(Message& message) {
    if (holding_ && !release_hold()) {
      held_.push_back(message);
      return;
    }
    write(message);
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
    // An open device that went silent (node.silence_warn_s): a warning while it increases.
    s.counters.push_back({"device_silences", d.silences, true});
    if (d.opens <= d.hangups + d.read_errors) {
      s.error = "device '" + reader_.device_name() + "' is not open (" + std::to_string(d.open_failures) +
                " failed attempts so far)";
    }
    return s;
  }

  void write(Message& message) {
    if (writer_.publish(message)) {
      ++published_;
    } else {
      ++publish_failures_;
    }
  }

  // Ends the hold when the readers matched, at the time-out, or at kMaxHeld
  // messages, writing the held ones; true once released. With `mutex` held.
  bool release_hold() {
    static constexpr std::size_t kMaxHeld = 10000;
    const int matched = writer_.matched_readers();
    const bool timed_out = std::chrono::steady_clock::now() >= hold_deadline_;
    if (matched < hold_readers_ && !timed_out && held_.size() < kMaxHeld) return false;
    holding_ = false;
    if (matched < hold_readers_) {
      log_(std::to_string(matched) + " of " + std::to_string(hold_readers_) + " readers matched (node.wait_readers) " +
           (timed_out ? "at the time-out" : "with " + std::to_string(kMaxHeld) + " messages held") +
           "; publishing anyway, " + std::to_string(held_.size()) + " held messages first");
    } else if (!held_.empty()) {
      log_(std::to_string(matched) + " readers matched: publishing the " + std::to_string(held_.size()) +
           " messages held meanwhile");
    }
    for (Message& m : held_) write(m);
    held_.clear();
    held_.shrink_to_fit();
    return true;
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
  const int hold_readers_;
  const std::chrono::steady_clock::duration hold_timeout_;
  bool holding_ = false;
  std::chrono::steady_clock::time_point hold_deadline_;
  std::vector<Message> held_;
  bool started_ = false;
  bool stopped_ = false;

  dds::Participant participant_;
  dds::Writer<Message> writer_;
  DeviceReader reader_;  // its thread uses the members above
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;  // reads all of the above
};

}  // namespace pixyslam::bridge
