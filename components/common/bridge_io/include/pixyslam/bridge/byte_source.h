#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/serial/serial_port.h"

namespace pixyslam::bridge {

// Where a bridge's bytes come from: a serial device that can come and go (an
// Arduino on USB, the Pixy's UART) or a test's scripted twin. open() throws an
// exception whose message names the device when it cannot be opened;
// read_some() waits up to `timeout` and reports data, a timeout or a hang-up as
// serial::SerialPort does (after a hang-up: close(), then open() again later)
// and throws on a read error. Used by one thread at a time.
class ByteSource {
 public:
  virtual ~ByteSource() = default;

  virtual void open() = 0;
  virtual void close() = 0;
  virtual bool is_open() const = 0;
  virtual serial::ReadResult read_some(std::uint8_t* buffer, std::size_t max,
                                       std::chrono::milliseconds timeout) = 0;
  // What to call the source in log lines, e.g. "/dev/ttyACM0".
  virtual std::string name() const = 0;
};

// A serial device in raw 8N1 mode at `baud` (serial::SerialPort).
class SerialByteSource final : public ByteSource {
 public:
  SerialByteSource(std::string path, long baud);

  void open() override;
  void close() override;
  bool is_open() const override;
  serial::ReadResult read_some(std::uint8_t* buffer, std::size_t max,
                               std::chrono::milliseconds timeout) override;
  std::string name() const override;

 private:
  std::string path_;
  long baud_;
  serial::SerialPort port_;
};

// The script a ScriptedByteSource plays: chunks of bytes with the host time at
// which each arrives, idle time, hang-ups, and open attempts that fail. Events
// may be added while a reader plays it. now_ns() is the time of the last event
// played, so clock() can stamp what the source delivers: a node driven by a
// script sees exactly the arrival times the script says, however fast it runs.
// Thread-safe.
class ByteScript {
 public:
  void add_bytes(const std::vector<std::uint8_t>& bytes, std::uint64_t at_ns);
  void add_bytes(std::string_view bytes, std::uint64_t at_ns);
  // Time passes without bytes: one read returns a timeout with now_ns() = until_ns.
  void add_idle(std::uint64_t until_ns);
  // The device hangs up; a later open() reconnects and plays on.
  void add_hangup(std::uint64_t at_ns);
  // The next `count` open() calls fail.
  void fail_next_opens(int count);

  std::uint64_t now_ns() const;
  // Every event was played.
  bool finished() const;
  // Waits until finished(); false on timeout.
  bool wait_finished(std::chrono::milliseconds timeout) const;
  int opens() const;  // successful open() calls
  // A ClockFunction reading now_ns() (keeps the script alive).
  static std::function<std::uint64_t()> clock(const std::shared_ptr<ByteScript>& script);

 private:
  friend class ScriptedByteSource;
  struct Event {
    enum class Kind { kBytes, kIdle, kHangup } kind = Kind::kBytes;
    std::vector<std::uint8_t> bytes;
    std::size_t taken = 0;
    std::uint64_t at_ns = 0;
  };
  void push(Event event);
  bool try_open();
  serial::ReadResult read(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout);

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::deque<Event> events_;
  std::uint64_t now_ns_ = 0;
  int failing_opens_ = 0;
  int opens_ = 0;
};

// The simulated twin of a serial device: plays a shared ByteScript. A read
// with nothing scheduled waits up to its timeout for the script to grow.
class ScriptedByteSource final : public ByteSource {
 public:
  explicit ScriptedByteSource(std::shared_ptr<ByteScript> script, std::string name = "/dev/scripted");

  void open() override;
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  serial::ReadResult read_some(std::uint8_t* buffer, std::size_t max,
                               std::chrono::milliseconds timeout) override;
  std::string name() const override { return name_; }

 private:
  std::shared_ptr<ByteScript> script_;
  std::string name_;
  bool open_ = false;
};

}  // namespace pixyslam::bridge
