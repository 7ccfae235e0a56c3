#pragma once

#include <cstdint>
#include <deque>

namespace pixyslam::encoder {

// Maps the Arduino's micros() stamps onto the host clock (ns, the dds::now_ns()
// domain). Each sample bounds the clock offset from above:
//   c_i = host_receive_ns_i - arduino_ns_i = offset + delay_i,  delay_i >= 0
// (line time, USB, scheduling), so the least-delayed sample gives the tightest
// bound: offset = min of c_i over the samples of the last `window_s` of Arduino
// time, and a sample's host time is arduino_ns_i + offset: its receive time
// minus the part of its delay above the smallest delay in the window. Jitter
// is removed; the fixed minimum transport delay (a few ms) is not.
//
// The Arduino clock is unwrapped with modulo-2^32 differences, so the ~71.6 min
// wrap of micros() is seamless. The estimate starts over (history dropped) on
// restart() (an RST line, the device reopened) and when the Arduino time steps
// back or forward by more than the window (an Arduino reset whose RST line was
// lost, or a corrupted stamp: one sample is affected). The window slides over
// Arduino time, so a too-small old minimum leaves it after `window_s`.
//
// Limits: a rate difference between the clocks (a ceramic resonator: up to
// ~0.5 %) biases the mapping by at most rate difference x window (5 ms at
// 1 s); after a forward step of the host clock the old minimum persists for up
// to one window, a backward step is followed at once. Pure (times passed in);
// thread-compatible.
class ArduinoClock {
 public:
  struct Counters {
    std::uint64_t samples = 0;
    std::uint64_t restarts = 0;  // restart() calls
    std::uint64_t jumps = 0;     // Arduino time stepped back or by more than the window
  };

  // window_s > 0.
  explicit ArduinoClock(double window_s);

  // The host time (ns) of a sample stamped `arduino_time_us`, read at host time
  // `host_receive_ns`. Never later than host_receive_ns.
  std::int64_t to_host_ns(std::uint32_t arduino_time_us, std::int64_t host_receive_ns);
  // Forgets the history: the next sample starts a new estimate.
  void restart();

  // The current offset estimate (ns): host time minus Arduino time, the latter
  // unwrapped from the first sample since the last (re)start. And by how much
  // the last sample's receive time was later than its mapped time (its delay
  // above the window's minimum).
  std::int64_t offset_ns() const { return offset_ns_; }
  std::int64_t last_excess_delay_ns() const { return last_excess_delay_ns_; }
  const Counters& counters() const { return counters_; }

 private:
  struct Bound {
    std::int64_t arduino_us;  // unwrapped: first value as sent, then + modulo-2^32 steps
    std::int64_t offset_ns;   // c_i
  };

  std::int64_t window_us_;
  bool has_last_ = false;
  std::uint32_t last_us_ = 0;
  std::int64_t unwrapped_us_ = 0;
  std::deque<Bound> window_;  // increasing arduino_us and increasing offset_ns: front is the minimum
  std::int64_t offset_ns_ = 0;
  std::int64_t last_excess_delay_ns_ = 0;
  Counters counters_;
};

}  // namespace pixyslam::encoder
