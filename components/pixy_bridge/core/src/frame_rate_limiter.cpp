#include "pixyslam/pixy/frame_rate_limiter.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pixyslam::pixy {
namespace {

constexpr std::uint64_t kWindowNs = 1000000000ull;  // rates are measured over 1 s of frame time

std::uint64_t to_ns(double seconds) { return static_cast<std::uint64_t>(std::llround(seconds * 1e9)); }

}  // namespace

const parameters::Table<FrameRateOptions>& frame_rate_parameters() {
  using O = FrameRateOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("frame_rate_hz", 0.1, 1000.0, "Hz", "the camera's frame rate: the most frames without blocks per second",
                 [](O& o) -> double& { return o.frame_rate_hz; }),
      P::real<O>("max_frame_rate_hz", 0.1, 10000.0, "Hz", "the most frames per second (default 1.2 * frame_rate_hz)",
                 [](O& o) -> double& { return o.max_frame_rate_hz; }),
      P::real<O>("frame_rate_tolerance_s", 0.0, 10.0, "s", "how early (bunched up) a frame may come and still pass",
                 [](O& o) -> double& { return o.tolerance_s; }),
  };
  return table;
}

void validate(const FrameRateOptions& o) {
  parameters::check_ranges(o, frame_rate_parameters(), "pixy");
  if (!(o.max_frame_rate_hz >= o.frame_rate_hz)) {
    throw parameters::RuleError("pixy", "max_frame_rate_hz",
                                "value " + parameters::number_text(o.max_frame_rate_hz) + " is below frame_rate_hz (" +
                                    parameters::number_text(o.frame_rate_hz) +
                                    "): frames without blocks may come at the camera's rate");
  }
  if (!(o.warn_period_s >= 0.1 && o.warn_period_s <= 3600.0)) {
    throw std::invalid_argument("warn_period_s = " + parameters::number_text(o.warn_period_s) +
                                ": must be in [0.1, 3600] s");
  }
}

std::string FrameRateWarning::text() const {
  char line[400];
  std::snprintf(line, sizeof line,
                "frame rate over the limit: %.0f frames/s offered (%.0f without blocks) over %g s; limits "
                "%g Hz for frames without blocks (pixy.frame_rate_hz), %g Hz for all frames "
                "(pixy.max_frame_rate_hz); %llu frames dropped since the last warning (%llu without blocks)",
                frames_per_s, empty_frames_per_s, window_s, frame_rate_hz, max_frame_rate_hz,
                static_cast<unsigned long long>(dropped), static_cast<unsigned long long>(empty_dropped));
  return line;
}

FrameRateLimiter::FrameRateLimiter(const FrameRateOptions& options) : options_(options) {
  validate(options_);
  tolerance_ns_ = to_ns(options_.tolerance_s);
  empty_.interval_ns = to_ns(1.0 / options_.frame_rate_hz);
  all_.interval_ns = to_ns(1.0 / options_.max_frame_rate_hz);
}

bool FrameRateLimiter::admit(std::uint64_t t, bool empty) {
  ++counters_.frames;
  if (empty) ++counters_.empty_frames;
  if (!started_ || t < last_ns_) {
    if (started_) ++counters_.clock_steps_back;
    started_ = true;
    empty_.next_ns = t;
    all_.next_ns = t;
    window_start_ns_ = t;
  }
  last_ns_ = t;
  roll_window(t);
  ++window_frames_;
  if (empty) ++window_empty_frames_;

  if (all_.conforms(t, tolerance_ns_) && (!empty || empty_.conforms(t, tolerance_ns_))) {
    all_.take(t);
    if (empty) empty_.take(t);
    ++counters_.published;
    return true;
  }
  ++counters_.rate_limited;
  ++window_dropped_;
  ++dropped_since_warning_;
  if (empty) {
    ++counters_.empty_rate_limited;
    ++empty_dropped_since_warning_;
  }
  return false;
}

void FrameRateLimiter::roll_window(std::uint64_t t) {
  if (!started_ || t < window_start_ns_ + kWindowNs) return;
  if (window_dropped_ > 0) {
    FrameRateWarning w;
    w.window_s = 1e-9 * static_cast<double>(kWindowNs);
    w.frames_per_s = static_cast<double>(window_frames_) / w.window_s;
    w.empty_frames_per_s = static_cast<double>(window_empty_frames_) / w.window_s;
    w.frame_rate_hz = options_.frame_rate_hz;
    w.max_frame_rate_hz = options_.max_frame_rate_hz;
    pending_ = w;
  }
  window_start_ns_ = t;
  window_frames_ = 0;
  window_empty_frames_ = 0;
  window_dropped_ = 0;
}

std::optional<FrameRateWarning> FrameRateLimiter::take_warning(std::uint64_t now_ns) {
  roll_window(now_ns);
  if (!pending_) return std::nullopt;
  // A clock that stepped back (now before the last warning) does not hold warnings back.
  if (warned_ && now_ns >= last_warning_ns_ && now_ns - last_warning_ns_ < to_ns(options_.warn_period_s)) {
    return std::nullopt;
  }
  FrameRateWarning w = *pending_;
  w.dropped = dropped_since_warning_;
  w.empty_dropped = empty_dropped_since_warning_;
  pending_.reset();
  dropped_since_warning_ = 0;
  empty_dropped_since_warning_ = 0;
  warned_ = true;
  last_warning_ns_ = now_ns;
  ++counters_.warnings;
  return w;
}

}  // namespace pixyslam::pixy
