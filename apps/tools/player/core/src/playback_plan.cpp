#include "pixyslam/player/playback_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace pixyslam::player {

namespace {
std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }
}  // namespace

void validate(const PlaybackOptions& options) {
  if (!(options.rate > 0.0) || !std::isfinite(options.rate)) {
    throw std::invalid_argument("--rate must be a finite number > 0, got " + std::to_string(options.rate));
  }
  // Bounded so that the ns arithmetic below cannot overflow (~31 years).
  constexpr double kMaxSeconds = 1e9;
  if (!(options.start_offset_s >= 0.0) || options.start_offset_s > kMaxSeconds) {
    throw std::invalid_argument("--start must be a number of seconds >= 0, got " +
                                std::to_string(options.start_offset_s));
  }
  if (!(options.duration_s >= 0.0) || options.duration_s > kMaxSeconds) {
    throw std::invalid_argument("--duration must be a number of seconds >= 0, got " +
                                std::to_string(options.duration_s));
  }
}

PlaybackPass plan_pass(const std::vector<std::uint64_t>& log_times_ns, const std::vector<bool>& selected,
                       std::uint64_t log_start_ns, const PlaybackOptions& options) {
  validate(options);
  if (selected.size() != log_times_ns.size()) throw std::invalid_argument("plan_pass: selection size mismatch");
  PlaybackPass pass;
  pass.origin_log_ns = log_start_ns + static_cast<std::uint64_t>(seconds_to_ns(options.start_offset_s));
  const std::uint64_t log_end_ns = log_times_ns.empty() ? log_start_ns : log_times_ns.back();
  if (pass.origin_log_ns > log_end_ns) {
    throw std::invalid_argument("--start " + std::to_string(options.start_offset_s) +
                                " s lies past the end of the log (" +
                                std::to_string(static_cast<double>(log_end_ns - log_start_ns) * 1e-9) + " s)");
  }
  const std::uint64_t window_end_ns =
      options.duration_s > 0.0
          ? std::min(log_end_ns, pass.origin_log_ns + static_cast<std::uint64_t>(seconds_to_ns(options.duration_s)))
          : log_end_ns;
  auto scaled = [&](std::uint64_t log_ns) {
    return static_cast<std::int64_t>(std::llround(static_cast<double>(log_ns - pass.origin_log_ns) / options.rate));
  };
  for (std::size_t i = 0; i < log_times_ns.size(); ++i) {
    const std::uint64_t t = log_times_ns[i];
    if (i > 0 && t < log_times_ns[i - 1]) throw std::invalid_argument("plan_pass: log times must not decrease");
    if (!selected[i] || t < pass.origin_log_ns || t > window_end_ns) continue;
    pass.messages.push_back({i, scaled(t)});
  }
  pass.span_ns = scaled(window_end_ns);
  return pass;
}

std::int64_t restamp_offset_ns(std::uint64_t origin_log_ns, std::uint64_t now_ns) {
  return static_cast<std::int64_t>(now_ns - origin_log_ns);  // two's complement: negative if now is earlier
}

std::uint64_t shift_stamp(std::uint64_t stamp_ns, std::int64_t offset_ns) {
  if (offset_ns >= 0) {
    const auto up = static_cast<std::uint64_t>(offset_ns);
    if (stamp_ns > std::numeric_limits<std::uint64_t>::max() - up) {
      throw std::out_of_range("restamp: stamp " + std::to_string(stamp_ns) + " + offset overflows");
    }
    return stamp_ns + up;
  }
  const std::uint64_t down = static_cast<std::uint64_t>(-(offset_ns + 1)) + 1;
  if (stamp_ns < down) {
    throw std::out_of_range("restamp: stamp " + std::to_string(stamp_ns) + " - " + std::to_string(down) +
                            " ns would be negative");
  }
  return stamp_ns - down;
}

}  // namespace pixyslam::player
