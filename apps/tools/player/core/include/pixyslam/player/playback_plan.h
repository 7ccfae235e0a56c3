#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pixyslam::player {

// How a log is replayed (pixyslam_play flags).
struct PlaybackOptions {
  double rate = 1.0;            // playback speed factor (2: twice as fast), > 0
  double start_offset_s = 0.0;  // skip this much log time from the log's first message
  double duration_s = 0.0;      // play this much log time; 0: to the end
  bool loop = false;            // start over at the end, until stopped
};

// Throws std::invalid_argument naming the option for a rate <= 0, a negative
// or non-finite offset or duration.
void validate(const PlaybackOptions& options);

// One message of a pass: its index in the log's message list and when to
// publish it, in wall-clock ns after the pass starts.
struct ScheduledMessage {
  std::size_t index = 0;
  std::int64_t due_ns = 0;
};

// One pass over the log. `origin_log_ns` is the log time that maps to the pass
// start (log start + offset); `span_ns` the wall time the pass lasts (its
// window of log time / rate), so a loop's next pass starts after it.
struct PlaybackPass {
  std::vector<ScheduledMessage> messages;
  std::uint64_t origin_log_ns = 0;
  std::int64_t span_ns = 0;
};

// Plans a pass: the messages whose log time lies in [log_start + offset,
// log_start + offset + duration] (all to the end when duration is 0), in log
// order, each due (log_time - origin) / rate after the pass starts: the
// original timing, scaled. `log_times_ns[i]` is the log time of message i
// (non-decreasing); `selected[i]` whether its topic is played; `log_start_ns`
// the first log time of the whole log (all topics). Throws
// std::invalid_argument when the offset lies past the log's end. Pure.
PlaybackPass plan_pass(const std::vector<std::uint64_t>& log_times_ns, const std::vector<bool>& selected,
                       std::uint64_t log_start_ns, const PlaybackOptions& options);

// The restamp offset for a pass that starts now: moves the pass origin's log
// time to `now_ns`, so every replayed stamp lags the clock by what it lagged
// the logger's clock live (an estimator then orders its inputs as it did).
// Pure.
std::int64_t restamp_offset_ns(std::uint64_t origin_log_ns, std::uint64_t now_ns);

// A stamp moved by `offset_ns` (restamping a replay onto the current clock).
// Throws std::out_of_range if the result would not fit an unsigned 64-bit stamp.
std::uint64_t shift_stamp(std::uint64_t stamp_ns, std::int64_t offset_ns);

}  // namespace pixyslam::player
