#include "pixyslam/pixy/frame_stamp.h"

#include <algorithm>
#include <cmath>

namespace pixyslam::pixy {

std::uint64_t bunched_frame_end_ns(std::uint64_t read_ns, std::uint64_t earliest_ns, std::uint64_t starts_after,
                                   std::uint64_t period_ns) {
  if (earliest_ns >= read_ns) return read_ns;
  const std::uint64_t span_ns = read_ns - earliest_ns;
  // starts_after * period_ns >= span_ns, without overflow.
  if (period_ns > 0 && starts_after >= (span_ns + period_ns - 1) / period_ns) return earliest_ns;
  return read_ns - starts_after * period_ns;
}

FramePeriodEstimate::FramePeriodEstimate(double frame_rate_hz)
    : min_period_ns_(static_cast<std::uint64_t>(std::llround(1e9 / frame_rate_hz))), period_ns_(min_period_ns_) {}

void FramePeriodEstimate::add_interval_ns(std::uint64_t interval_ns) {
  constexpr std::uint64_t kLongestNs = 1000000000ull;
  if (interval_ns > kLongestNs) return;
  intervals_[count_ % kIntervals] = interval_ns;
  ++count_;
  const std::size_t n = std::min(count_, kIntervals);
  if (n < kMinIntervals) return;
  std::array<std::uint64_t, kIntervals> sorted = intervals_;
  std::nth_element(sorted.begin(), sorted.begin() + n / 4, sorted.begin() + n);
  period_ns_ = std::max(min_period_ns_, sorted[n / 4]);
}

FrameClock::FrameClock(double frame_rate_hz) : period_(frame_rate_hz) {}

std::uint64_t FrameClock::measured(std::uint64_t index, std::uint64_t end_ns) {
  if (last_measured_ && index == anchor_index_ + 1 && end_ns > anchor_ns_) {
    period_.add_interval_ns(end_ns - anchor_ns_);
  }
  last_measured_ = true;
  has_anchor_ = true;
  anchor_index_ = index;
  anchor_ns_ = end_ns;
  return end_ns;
}

std::uint64_t FrameClock::bunched(std::uint64_t index, std::uint64_t read_ns, std::uint64_t earliest_ns,
                                  std::uint64_t starts_after) {
  last_measured_ = false;
  const std::uint64_t p = period_.period_ns();
  const std::uint64_t back = bunched_frame_end_ns(read_ns, earliest_ns, starts_after, p);
  if (!has_anchor_ || index <= anchor_index_ || index - anchor_index_ > (back - std::min(back, anchor_ns_)) / p + 1) {
    return back;  // no anchor, or more than a period (plus one frame) beyond it: no forward bound to trust
  }
  const std::uint64_t forward = anchor_ns_ + (index - anchor_index_) * p;
  if (forward > back || back - forward >= p) return back;
  return std::max(forward, earliest_ns);
}

std::uint64_t FrameClock::estimated(std::uint64_t end_ns) {
  last_measured_ = false;
  return end_ns;
}

}  // namespace pixyslam::pixy
