#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/encoder_options.h"

namespace pixyslam::encoder {

// Modular differences of the Arduino's wrapping quantities: the counter and
// clock values are taken modulo 2^32, so `now - before` is right across a wrap
// as long as the true difference fits (|ticks| < 2^31, time < 2^32 us).
// tick_delta(INT32_MIN + 2, INT32_MAX - 2) == 5; time_delta_us(10, 0xfffffff6u) == 20.
std::int32_t tick_delta(std::int32_t now, std::int32_t before);
std::uint32_t time_delta_us(std::uint32_t now, std::uint32_t before);

// Differential-drive motion between two encoder samples, forward positive:
//   left_m  = left_sign  * dticks_l * 2 pi r / ticks_per_revolution, right_m likewise,
//   distance_m = (left_m + right_m) / 2,  rotation_rad = (right_m - left_m) / wheel_base_m,
//   v_mps = distance_m / dt_s,  w_radps = rotation_rad / dt_s  (w > 0: counter-clockwise).
// dt_s is measured by the Arduino's clock.
struct WheelStep {
  std::uint32_t seq = 0;  // of the sample that ends the step
  double dt_s = 0.0;
  double left_m = 0.0;
  double right_m = 0.0;
  double distance_m = 0.0;
  double rotation_rad = 0.0;
  double v_mps = 0.0;
  double w_radps = 0.0;
};

enum class WheelStatus {
  kStep,       // `step` holds the motion since the previous baseline
  kBaseline,   // the sample starts a new baseline, no motion known up to it: the first
               // sample, the first after a reset, or a restart (see WheelCounters)
  kDuplicate,  // same seq as the previous sample: ignored
  kRejected,   // implausible wheel speed: ignored, the baseline is kept
};

struct WheelUpdate {
  WheelStatus status = WheelStatus::kBaseline;
  WheelStep step;  // meaningful for kStep only
};

// Running totals since construction.
struct WheelCounters {
  std::uint64_t samples = 0;             // update() calls
  std::uint64_t steps = 0;               // kStep results
  std::uint64_t resets = 0;              // reset() calls (RST lines)
  std::uint64_t ticks_per_revolution_mismatches = 0;  // RST reporting another value than the options
  std::uint64_t duplicates = 0;
  std::uint64_t sequence_gaps = 0;       // times seq jumped by more than 1
  std::uint64_t lost_samples = 0;        // seq numbers skipped in those jumps
  std::uint64_t sequence_backwards = 0;  // seq went back without an RST line (restart)
  std::uint64_t time_gaps = 0;           // Arduino interval 0 or above max_sample_gap_s (restart)
  std::uint64_t implausible = 0;         // steps over max_wheel_speed_mps (kRejected, or the
                                         // restart that ends a run of rejections)
  std::uint64_t rejection_restarts = 0;  // restarts after kMaxConsecutiveRejections in a row
};

// Turns successive EncoderSamples into wheel motion (WheelStep) with the
// geometry of EncoderOptions. Tick and time deltas are taken modulo 2^32
// (wrap-aware). A reset() (RST line) drops the baseline, so no motion is taken
// across it. A sequence gap (lost lines) is counted and the step still spans
// it, from the Arduino time stamps. A step in which either wheel would have
// moved faster than max_wheel_speed_mps is rejected and the baseline kept, so
// the next sample spans both intervals; after kMaxConsecutiveRejections in a
// row the latest sample becomes the baseline. seq going backwards or an
// Arduino interval of 0 or above max_sample_gap_s also restarts from the
// latest sample. Thread-compatible.
class WheelOdometry {
 public:
  static constexpr int kMaxConsecutiveRejections = 3;

  // Throws std::invalid_argument if the options do not validate().
  explicit WheelOdometry(const EncoderOptions& options);

  WheelUpdate update(const EncoderSample& sample);
  // The Arduino restarted: the next sample is a new baseline.
  void reset(const EncoderReset& reset);

  double metres_per_tick() const { return metres_per_tick_; }
  const WheelCounters& counters() const { return counters_; }

 private:
  WheelUpdate restart(const EncoderSample& sample);

  EncoderOptions options_;
  double metres_per_tick_ = 0.0;
  bool has_baseline_ = false;
  EncoderSample baseline_;
  std::uint32_t last_seq_ = 0;
  int consecutive_rejections_ = 0;
  WheelCounters counters_;
};

// Mean velocities over one output period [t_s, t_s + duration_s) of host time:
// v_mps = distance_m / duration_s, w_radps = rotation_rad / duration_s. Time of
// the period not covered by wheel steps (before a baseline, after a reset or
// restart) counts as no motion; covered_s says how much was covered.
struct OdometryOutput {
  double t_s = 0.0;  // START of the period
  double duration_s = 0.0;
  double v_mps = 0.0;
  double w_radps = 0.0;
  double distance_m = 0.0;
  double rotation_rad = 0.0;
  double covered_s = 0.0;
};

struct AccumulatorCounters {
  std::uint64_t outputs = 0;
  std::uint64_t steps = 0;
  std::uint64_t gaps = 0;                  // baselines and mark_gap() calls
  std::uint64_t host_time_backwards = 0;   // time stamps before the previous one (clamped)
  std::uint64_t invalid_host_times = 0;    // NaN or infinite stamps (the call is ignored)
  std::uint64_t grid_restarts = 0;         // jumps longer than kMaxCatchUpPeriods periods
  std::uint64_t steps_after_gap = 0;       // steps wholly before a mark_gap() time: dropped
  std::uint64_t stalled_periods_extrapolated = 0;  // periods a mark_gap() closed part-measured
};

// Resamples wheel steps to a fixed output rate (publish_rate_hz; seed paper:
// 10 Hz). Periods are [t0 + k T, t0 + (k + 1) T), T = 1 / publish_rate_hz, t0 the
// first host time stamp passed in (a first update that is a step: its stamp
// minus its dt_s). Each step covers host time from the previous stamp to its
// own; its distance and rotation are split over the periods it overlaps in
// proportion to the overlap (constant velocity within a step), so the outputs'
// distances sum to the steps' (up to rounding). A period is output when a stamp
// at or after its end arrives. Its time stamp is the START of the interval it
// covers, because the filter applies (v, w) as a zero-order hold from the
// sample's time until the next sample's: the mean over [t, t + T) stamped t,
// held over [t, t + T), reproduces the motion of that interval. The output is
// therefore one period (plus transport) late. Stamps are host times in seconds
// (e.g. when the sample's '\n' was read); a stamp earlier than the previous one
// is clamped to it, a non-finite one ignored. A jump of more than
// kMaxCatchUpPeriods periods closes the open period and restarts the grid at
// the new stamp (the periods in between are not output). Thread-compatible.
class OdometryAccumulator {
 public:
  using OutputCallback = std::function<void(const OdometryOutput&)>;
  static constexpr std::uint64_t kMaxCatchUpPeriods = 1000;

  // Throws std::invalid_argument unless publish_rate_hz is finite and > 0.
  explicit OdometryAccumulator(double publish_rate_hz);

  // kStep: covers (previous stamp, host_time_s] with the step. kBaseline: the
  // same interval is uncovered. kDuplicate and kRejected: nothing (a later step
  // covers the interval). Calls `on_output` for every period completed. A step
  // that began before the last mark_gap() time (the backlog of a stream that
  // stalled: its periods already went out as "no data", and the filter held
  // its last command through them) counts only with its part after that time;
  // one wholly before it is dropped (steps_after_gap), so the motion is not
  // counted twice, once held and once as a burst in the next period.
  void add(double host_time_s, const WheelUpdate& update, const OutputCallback& on_output);
  std::vector<OdometryOutput> add(double host_time_s, const WheelUpdate& update);
  // Declares that no wheel motion is known up to host_time_s (e.g. the serial
  // stream stalled), completing the periods that end by then. The period the
  // stream stalled in carries the mean velocity of its measured part over its
  // whole length (the rest is unknown, not standing still); the periods after
  // it go out with no motion and covered_s 0 ("no data").
  void mark_gap(double host_time_s, const OutputCallback& on_output);
  std::vector<OdometryOutput> mark_gap(double host_time_s);

  double period_s() const { return period_s_; }
  const AccumulatorCounters& counters() const { return counters_; }

 private:
  // Moves the cursor to `end`, spreading (distance, rotation) over the interval
  // when `covered`; a zero-length interval puts them in the open period.
  // `stalled`: a mark_gap(); periods it closes extrapolate their measured part.
  void advance(double end, bool covered, double distance_m, double rotation_rad,
               const OutputCallback& on_output, bool stalled = false);
  double period_start() const { return t0_ + static_cast<double>(index_) * period_s_; }
  double period_end() const { return t0_ + static_cast<double>(index_ + 1) * period_s_; }
  void emit(const OutputCallback& on_output, bool stalled = false);
  // Moves the cursor to host_time_s uncovered (a baseline, or mark_gap()).
  void close_uncovered(double host_time_s, const OutputCallback& on_output, bool stalled);

  double period_s_ = 0.1;
  bool started_ = false;
  double t0_ = 0.0;
  std::uint64_t index_ = 0;  // of the open period
  double cursor_ = 0.0;      // end of the last interval processed
  double distance_m_ = 0.0;  // of the open period so far
  double rotation_rad_ = 0.0;
  double covered_s_ = 0.0;
  double gap_until_ = -std::numeric_limits<double>::infinity();  // the last mark_gap() time
  AccumulatorCounters counters_;
};

}  // namespace pixyslam::encoder
