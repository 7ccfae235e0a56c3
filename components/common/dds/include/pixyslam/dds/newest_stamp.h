#pragma once

#include <cstdint>

namespace pixyslam::dds {

// For a reader that shows the newest state of a stream (a map, a solution): a
// sample stamped before the newest one taken is stale (a late joiner's copy
// from a writer's history) and dropped, but only within `window_ns`. A sample
// further behind is taken as the time going back (a restarted run, a clock
// step, or a stamp far ahead taken before it: any participant can send
// 2^64 - 1), so that one such stamp cannot stop the stream for good.
class NewestStamp {
 public:
  static constexpr std::uint64_t kDefaultWindowNs = 10'000'000'000;  // as the estimator's max_stamp_jump_s

  explicit NewestStamp(std::uint64_t window_ns = kDefaultWindowNs) : window_ns_(window_ns) {}

  // True if the sample is to be taken; it is then the newest.
  bool take(std::uint64_t stamp_ns) {
    if (taken_ > 0 && stamp_ns < newest_ns_) {
      if (newest_ns_ - stamp_ns <= window_ns_) {
        ++stale_;
        return false;
      }
      ++time_resets_;
    }
    newest_ns_ = stamp_ns;
    ++taken_;
    return true;
  }

  std::uint64_t taken() const { return taken_; }
  std::uint64_t stale() const { return stale_; }              // dropped
  std::uint64_t time_resets() const { return time_resets_; }  // taken although far behind
  std::uint64_t newest_ns() const { return newest_ns_; }

 private:
  std::uint64_t window_ns_;
  std::uint64_t newest_ns_ = 0;
  std::uint64_t taken_ = 0;
  std::uint64_t stale_ = 0;
  std::uint64_t time_resets_ = 0;
};

}  // namespace pixyslam::dds
