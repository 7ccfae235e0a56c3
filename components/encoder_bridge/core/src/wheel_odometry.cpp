#include "pixyslam/encoder/wheel_odometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pixyslam::encoder {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

std::int32_t tick_delta(std::int32_t now, std::int32_t before) {
  const std::uint32_t d = static_cast<std::uint32_t>(now) - static_cast<std::uint32_t>(before);
  // Two's complement reading of the 32-bit difference, without implementation-defined casts.
  return d <= 0x7fffffffu ? static_cast<std::int32_t>(d) : -static_cast<std::int32_t>(~d) - 1;
}

std::uint32_t time_delta_us(std::uint32_t now, std::uint32_t before) { return now - before; }

// ---------------------------------------------------------------------------
// WheelOdometry

WheelOdometry::WheelOdometry(const EncoderOptions& options) : options_(options) {
  validate(options_);
  metres_per_tick_ = 2.0 * kPi * options_.wheel_radius_m / options_.ticks_per_revolution;
}

void WheelOdometry::reset(const EncoderReset& reset) {
  ++counters_.resets;
  if (reset.ticks_per_revolution != 0 &&
      reset.ticks_per_revolution != static_cast<std::uint32_t>(options_.ticks_per_revolution)) {
    ++counters_.ticks_per_revolution_mismatches;
  }
  has_baseline_ = false;
  consecutive_rejections_ = 0;
}

WheelUpdate WheelOdometry::restart(const EncoderSample& sample) {
  has_baseline_ = true;
  baseline_ = sample;
  last_seq_ = sample.seq;
  consecutive_rejections_ = 0;
  return WheelUpdate{WheelStatus::kBaseline, {}};
}

WheelUpdate WheelOdometry::update(const EncoderSample& sample) {
  ++counters_.samples;
  if (!has_baseline_) return restart(sample);

  const std::uint32_t dseq = sample.seq - last_seq_;
  if (dseq == 0) {
    ++counters_.duplicates;
    return WheelUpdate{WheelStatus::kDuplicate, {}};
  }
  if (dseq >= 0x80000000u) {  // backwards: the Arduino restarted and its RST line was lost
    ++counters_.sequence_backwards;
    return restart(sample);
  }
  if (dseq > 1) {
    ++counters_.sequence_gaps;
    counters_.lost_samples += dseq - 1;
  }
  last_seq_ = sample.seq;

  const std::uint32_t dt_us = time_delta_us(sample.arduino_time_us, baseline_.arduino_time_us);
  const double dt_s = static_cast<double>(dt_us) * 1e-6;
  if (dt_us == 0 || dt_s > options_.max_sample_gap_s) {
    ++counters_.time_gaps;
    return restart(sample);
  }

  WheelStep step;
  step.seq = sample.seq;
  step.dt_s = dt_s;
  step.left_m = options_.left_sign * metres_per_tick_ *
                static_cast<double>(tick_delta(sample.left_ticks, baseline_.left_ticks));
  step.right_m = options_.right_sign * metres_per_tick_ *
                 static_cast<double>(tick_delta(sample.right_ticks, baseline_.right_ticks));
  const double limit_m = options_.max_wheel_speed_mps * dt_s;
  if (std::abs(step.left_m) > limit_m || std::abs(step.right_m) > limit_m) {
    ++counters_.implausible;
    if (++consecutive_rejections_ >= kMaxConsecutiveRejections) {
      ++counters_.rejection_restarts;
      return restart(sample);
    }
    return WheelUpdate{WheelStatus::kRejected, {}};
  }
  consecutive_rejections_ = 0;
  baseline_ = sample;

  step.distance_m = 0.5 * (step.left_m + step.right_m);
  step.rotation_rad = (step.right_m - step.left_m) / options_.wheel_base_m;
  step.v_mps = step.distance_m / dt_s;
  step.w_radps = step.rotation_rad / dt_s;
  ++counters_.steps;
  return WheelUpdate{WheelStatus::kStep, step};
}

// ---------------------------------------------------------------------------
// OdometryAccumulator

OdometryAccumulator::OdometryAccumulator(double publish_rate_hz) {
  if (!std::isfinite(publish_rate_hz) || publish_rate_hz <= 0.0) {
    throw std::invalid_argument("publish_rate_hz must be finite and > 0");
  }
  period_s_ = 1.0 / publish_rate_hz;
}

void OdometryAccumulator::add(double host_time_s, const WheelUpdate& update,
                              const OutputCallback& on_output) {
  if (!std::isfinite(host_time_s)) {
    ++counters_.invalid_host_times;
    return;
  }
  switch (update.status) {
    case WheelStatus::kStep: {
      ++counters_.steps;
      if (!started_) {
        // The first step covers its own Arduino interval, ending at its stamp.
        started_ = true;
        t0_ = cursor_ = host_time_s - update.step.dt_s;
      }
      double kept = 1.0;  // the step's share after the last mark_gap() time
      if (host_time_s - update.step.dt_s < gap_until_) {
        if (host_time_s <= gap_until_) {
          ++counters_.steps_after_gap;
          break;
        }
        kept = (host_time_s - gap_until_) / update.step.dt_s;
      }
      advance(host_time_s, true, kept * update.step.distance_m, kept * update.step.rotation_rad, on_output);
      break;
    }
    case WheelStatus::kBaseline:
      close_uncovered(host_time_s, on_output, false);
      break;
    case WheelStatus::kDuplicate:
    case WheelStatus::kRejected:
      break;
  }
}

std::vector<OdometryOutput> OdometryAccumulator::add(double host_time_s, const WheelUpdate& update) {
  std::vector<OdometryOutput> out;
  add(host_time_s, update, [&out](const OdometryOutput& o) { out.push_back(o); });
  return out;
}

void OdometryAccumulator::mark_gap(double host_time_s, const OutputCallback& on_output) {
  if (!std::isfinite(host_time_s)) {
    ++counters_.invalid_host_times;
    return;
  }
  close_uncovered(host_time_s, on_output, true);
  gap_until_ = std::max(gap_until_, host_time_s);
}

void OdometryAccumulator::close_uncovered(double host_time_s, const OutputCallback& on_output, bool stalled) {
  ++counters_.gaps;
  if (!started_) {
    started_ = true;
    t0_ = cursor_ = host_time_s;
  }
  advance(host_time_s, false, 0.0, 0.0, on_output, stalled);
}

std::vector<OdometryOutput> OdometryAccumulator::mark_gap(double host_time_s) {
  std::vector<OdometryOutput> out;
  mark_gap(host_time_s, [&out](const OdometryOutput& o) { out.push_back(o); });
  return out;
}

void OdometryAccumulator::emit(const OutputCallback& on_output, bool stalled) {
  if (stalled && covered_s_ > 0.0 && covered_s_ < period_s_) {
    // The stream stalled inside this period: the rest of it is unknown, not
    // standing still. Its mean velocity is that of the part measured.
    const double scale = period_s_ / covered_s_;
    distance_m_ *= scale;
    rotation_rad_ *= scale;
    ++counters_.stalled_periods_extrapolated;
  }
  OdometryOutput o;
  o.t_s = period_start();
  o.duration_s = period_s_;
  o.distance_m = distance_m_;
  o.rotation_rad = rotation_rad_;
  o.v_mps = distance_m_ / period_s_;
  o.w_radps = rotation_rad_ / period_s_;
  o.covered_s = std::min(covered_s_, period_s_);
  ++index_;
  distance_m_ = rotation_rad_ = covered_s_ = 0.0;
  ++counters_.outputs;
  on_output(o);
}

void OdometryAccumulator::advance(double end, bool covered, double distance_m, double rotation_rad,
                                  const OutputCallback& on_output, bool stalled) {
  if (end < cursor_) {
    ++counters_.host_time_backwards;
    end = cursor_;
  }
  if (end - cursor_ > static_cast<double>(kMaxCatchUpPeriods) * period_s_) {
    // Too long a jump to fill period by period: close the open period and start
    // a new grid at `end`; the step's motion goes into the new period.
    ++counters_.grid_restarts;
    emit(on_output, stalled);
    t0_ = cursor_ = end;
    index_ = 0;
    if (covered) {
      distance_m_ += distance_m;
      rotation_rad_ += rotation_rad;
    }
    return;
  }

  const double span = end - cursor_;
  double distance_left = distance_m;
  double rotation_left = rotation_rad;
  while (end >= period_end()) {
    const double boundary = period_end();
    if (covered && span > 0.0) {
      const double fraction = (boundary - cursor_) / span;
      const double d = distance_m * fraction;
      const double r = rotation_rad * fraction;
      distance_m_ += d;
      rotation_rad_ += r;
      distance_left -= d;
      rotation_left -= r;
      covered_s_ += boundary - cursor_;
    }
    cursor_ = boundary;
    emit(on_output, stalled);
  }
  if (covered) {
    // The remainder (not a fraction) keeps the outputs' sum equal to the steps'.
    distance_m_ += distance_left;
    rotation_rad_ += rotation_left;
    covered_s_ += end - cursor_;
  }
  cursor_ = end;
}

}  // namespace pixyslam::encoder
