#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "pixyslam/bridge/byte_source.h"

namespace pixyslam::bridge {

// A log line sink (one line, no trailing newline). Called from any thread.
using LogFunction = std::function<void(const std::string& line)>;
// The host clock in ns that stamps received bytes (dds::now_ns in the bridges;
// tests drive their own).
using ClockFunction = std::function<std::uint64_t()>;

// Writes "<process>: <line>\n" to stderr (one fprintf per line, so lines of
// several threads do not interleave).
LogFunction stderr_log(const std::string& process);

struct DeviceReaderOptions {
  std::chrono::milliseconds reopen_period{1000};  // between open attempts after a failure or hang-up
  std::chrono::milliseconds poll_period{50};      // read timeout: on_poll runs at least this often
  std::chrono::seconds repeat_error_log{60};      // a persisting open failure is logged again after this
  // An open device that sends no byte for this long (host clock) is named in the
  // log and counted (DeviceCounters::silences), once per silent stretch, since
  // a cable pulled from a UART, a wrong device or baud rate, or a sender that
  // stopped shows no hang-up. 0: never.
  std::chrono::milliseconds silence_warn{0};
  // Most bytes handed over per on_bytes call: one read takes all a tty holds
  // (Linux buffers 4096 bytes per tty), so what a busy host left unread comes
  // in one chunk, and the pixy bridge can spread its frames back in time.
  std::size_t buffer_bytes = 4096;
};

// Running totals of a DeviceReader.
struct DeviceCounters {
  std::uint64_t opens = 0;          // successful opens (the first and every reopen)
  std::uint64_t open_failures = 0;  // failed open attempts
  std::uint64_t hangups = 0;        // the device went away while open
  std::uint64_t read_errors = 0;    // reads that threw (the device is closed and reopened)
  std::uint64_t handler_errors = 0;  // exceptions thrown by a handler (logged, then ignored)
  std::uint64_t reads = 0;          // reads that returned data
  std::uint64_t bytes = 0;          // bytes read
  std::uint64_t silences = 0;       // times an open device sent nothing for silence_warn
  bool silent = false;              // it is silent now (until its next byte)
};

// Owns the thread that reads a bridge's device: keeps the ByteSource open,
// hands every chunk read to on_bytes with the host time it was read at, and
// calls on_poll at least every poll_period (also while the device is missing),
// so the node can flush by time and log its status. When the device cannot be
// opened, hangs up or fails a read, the reader logs it (naming the device) and
// tries to open it again every reopen_period, forever: it never gives up and
// never throws out of its thread. A handler that throws is logged and counted.
// Handlers run on the reader thread only, one at a time. start() and stop()
// are not thread-safe against each other; counters() is thread-safe.
class DeviceReader {
 public:
  struct Handlers {
    std::function<void()> on_open;  // after every successful open
    std::function<void(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns)> on_bytes;
    std::function<void(std::uint64_t now_ns)> on_poll;
    // Optional: the clock time by which on_poll must run next (0: no deadline),
    // e.g. when a frame the node holds times out. The read then waits only
    // until then (at least 1 ms), not the whole poll_period.
    std::function<std::uint64_t()> poll_deadline_ns;
  };

  DeviceReader(std::unique_ptr<ByteSource> source, const DeviceReaderOptions& options, LogFunction log,
               ClockFunction clock);
  ~DeviceReader();
  DeviceReader(const DeviceReader&) = delete;
  DeviceReader& operator=(const DeviceReader&) = delete;

  // Starts the thread (no-op if it runs).
  void start(Handlers handlers);
  // Stops and joins the thread (within about one poll_period) and closes the device.
  void stop();

  DeviceCounters counters() const;
  const std::string& device_name() const { return device_name_; }
  // The counters as a log line: "status: device '<name>': opens N, open failures N, ...".
  std::string status_line() const;

 private:
  void loop();
  // The read's timeout: poll_period, or less when the node has an earlier deadline.
  std::chrono::milliseconds read_timeout();
  // Waits `period` (or until stop), calling on_poll every poll_period.
  void wait(std::chrono::milliseconds period);
  bool stopping() const { return stop_.load(); }
  // After a read without bytes: logs and counts a silence of silence_warn (once per stretch).
  void note_silence(std::uint64_t now_ns, std::uint64_t& last_bytes_ns);
  template <class Call>
  void run_handler(const char* name, const Call& call);

  std::unique_ptr<ByteSource> source_;
  const std::string device_name_;
  DeviceReaderOptions options_;
  LogFunction log_;
  ClockFunction clock_;
  Handlers handlers_;

  std::atomic<bool> stop_{false};
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;
  std::thread thread_;

  mutable std::mutex counters_mutex_;
  DeviceCounters counters_;
};

}  // namespace pixyslam::bridge
