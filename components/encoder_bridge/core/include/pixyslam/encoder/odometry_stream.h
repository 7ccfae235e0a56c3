#pragma once

#include <cstdint>
#include <deque>
#include <functional>

#include "pixyslam/encoder/arduino_clock.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/encoder/wheel_odometry.h"

namespace pixyslam::encoder {

// One published period: the accumulator's output, how many Arduino samples
// stamped before its end no earlier period counted (0: "no data"), and the
// host time (ns) of t = 0 s in the output's stamps.
struct StreamOutput {
  OdometryOutput odometry;
  std::uint32_t samples = 0;
  std::uint64_t epoch_ns = 0;
};

// The encoder bridge's whole path from parsed Arduino messages to fixed-rate
// odometry, with every time passed in (host ns, the receive times of the
// bytes): Arduino stamps mapped onto the host clock (ArduinoClock), samples
// turned into wheel motion (WheelOdometry) and resampled to publish_rate_hz
// (OdometryAccumulator). t = 0 s is the first sample's host time rounded down
// to a whole second. While no sample arrives for max_sample_gap_s, poll()
// closes the elapsed periods as "no data" (one period at a time, up to
// max_sample_gap_s ago), so the stream keeps its rate through a stall.
// Thread-compatible.
class OdometryStream {
 public:
  using Emit = std::function<void(const StreamOutput&)>;

  // Throws std::invalid_argument for a window_s or publish rate that is not > 0.
  OdometryStream(const EncoderOptions& options, double clock_window_s);

  // A sample read at host time receive_ns; emits the periods it completes.
  void add_sample(const EncoderSample& sample, std::uint64_t receive_ns, const Emit& emit);
  // An RST line: the wheel state and the clock estimate start over.
  void reset(const EncoderReset& reset);
  // The device was (re)opened: a new clock estimate (an Uno also resets).
  void restart_clock() { clock_.restart(); }
  // Host time now_ns with no sample since the last: closes stalled periods.
  void poll(std::uint64_t now_ns, const Emit& emit);

  const WheelCounters& wheel_counters() const { return odometry_.counters(); }
  const AccumulatorCounters& accumulator_counters() const { return accumulator_.counters(); }
  const ArduinoClock& clock() const { return clock_; }
  std::uint64_t empty_periods() const { return empty_periods_; }

 private:
  double to_seconds(std::int64_t host_ns) const;
  void output(const OdometryOutput& o, const Emit& emit);

  std::uint64_t stall_ns_;
  WheelOdometry odometry_;
  OdometryAccumulator accumulator_;
  ArduinoClock clock_;
  bool has_epoch_ = false;
  std::uint64_t epoch_ns_ = 0;        // host time of t = 0 s
  std::deque<double> sample_times_;   // of samples not yet counted into an output, s
  double last_time_s_ = 0.0;          // latest time passed to the accumulator
  std::uint64_t last_sample_ns_ = 0;  // receive time of the latest sample
  std::uint64_t empty_periods_ = 0;
};

}  // namespace pixyslam::encoder
