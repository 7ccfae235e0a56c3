#include "pixyslam/encoder/odometry_stream.h"

#include <algorithm>
#include <cmath>

namespace pixyslam::encoder {

OdometryStream::OdometryStream(const EncoderOptions& options, double clock_window_s)
    : stall_ns_(static_cast<std::uint64_t>(std::llround(options.max_sample_gap_s * 1e9))),
      odometry_(options),
      accumulator_(options.publish_rate_hz),
      clock_(clock_window_s) {}

double OdometryStream::to_seconds(std::int64_t host_ns) const {
  return static_cast<double>(host_ns - static_cast<std::int64_t>(epoch_ns_)) * 1e-9;
}

void OdometryStream::add_sample(const EncoderSample& sample, std::uint64_t receive_ns, const Emit& emit) {
  const std::int64_t host_ns = clock_.to_host_ns(sample.arduino_time_us, static_cast<std::int64_t>(receive_ns));
  if (!has_epoch_) {
    const std::int64_t positive = std::max<std::int64_t>(host_ns, 0);
    epoch_ns_ = static_cast<std::uint64_t>(positive - positive % 1000000000);
    has_epoch_ = true;
  }
  const double t_s = to_seconds(host_ns);
  const WheelUpdate update = odometry_.update(sample);
  // A repeated line is no news: it neither counts as a sample of a period nor
  // holds off the stall timer (an Arduino that repeats one line has stalled).
  if (update.status == WheelStatus::kDuplicate) return;
  sample_times_.push_back(t_s);
  last_sample_ns_ = receive_ns;
  accumulator_.add(t_s, update, [&](const OdometryOutput& o) { output(o, emit); });
  last_time_s_ = std::max(last_time_s_, t_s);
}

void OdometryStream::reset(const EncoderReset& reset) {
  odometry_.reset(reset);
  clock_.restart();
}

void OdometryStream::poll(std::uint64_t now_ns, const Emit& emit) {
  if (!has_epoch_ || now_ns <= last_sample_ns_ + stall_ns_) return;
  const double gap_s = to_seconds(static_cast<std::int64_t>(now_ns - stall_ns_));
  if (gap_s >= last_time_s_ + accumulator_.period_s()) {
    accumulator_.mark_gap(gap_s, [&](const OdometryOutput& o) { output(o, emit); });
    last_time_s_ = gap_s;
  }
}

void OdometryStream::output(const OdometryOutput& o, const Emit& emit) {
  // Samples stamped before the period's end that no earlier output counted.
  const double end_s = o.t_s + o.duration_s;
  std::uint32_t samples = 0;
  while (!sample_times_.empty() && sample_times_.front() < end_s) {
    ++samples;
    sample_times_.pop_front();
  }
  if (samples == 0) ++empty_periods_;
  emit({o, samples, epoch_ns_});
}

}  // namespace pixyslam::encoder
