#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "pixyslam/parameters/parameters.h"

namespace pixyslam::pixy {

// How fast the pixy bridge publishes camera frames (`pixy:` keys of
// config/pixy_bridge.yaml). The Pixy (CMUcam5) processes 50 frames per second;
// a line that delivers more is not a camera: a flood of sync words ("aa55 aa55"
// is one frame without blocks per 2 bytes) or a replayed or looping stream.
struct FrameRateOptions {
  // The camera's nominal frame rate: frames without blocks are never published
  // faster than this.
  double frame_rate_hz = 50.0;
  // No frame at all is published faster than this; a little above the camera's
  // rate, so a real camera's frames all pass.
  double max_frame_rate_hz = 60.0;
  // How far ahead of a limit's schedule a frame may arrive and still pass:
  // frames that a busy host read late arrive bunched up. A burst of at most
  // 1 + tolerance_s * rate frames passes at once. With 0.1 s, a bridge that a
  // loaded host (CI, four tests on two cores) left unscheduled for a few
  // tenths of a second dropped 31 of a 50 Hz camera's frames (the estimator's
  // ATE went from ~0.04 to 0.19 m); a flood is held to the same rates.
  double tolerance_s = 0.5;
  // A warning at most this often while frames are dropped.
  double warn_period_s = 5.0;
};

// The `pixy:` keys of the frame rates (warn_period_s is not a key).
const parameters::Table<FrameRateOptions>& frame_rate_parameters();

// Throws std::invalid_argument naming the first field out of its range:
// frame_rate_hz in [0.1, 1000], max_frame_rate_hz in [frame_rate_hz, 10000],
// tolerance_s in [0, 10], warn_period_s in [0.1, 3600].
void validate(const FrameRateOptions& options);

// Running totals of a FrameRateLimiter.
struct FrameRateCounters {
  std::uint64_t frames = 0;              // frames offered to admit()
  std::uint64_t empty_frames = 0;        // of which without blocks
  std::uint64_t published = 0;           // admitted
  std::uint64_t rate_limited = 0;        // dropped: over a limit
  std::uint64_t empty_rate_limited = 0;  // of which without blocks
  std::uint64_t clock_steps_back = 0;    // frame times that went backwards (the schedule restarted)
  std::uint64_t warnings = 0;            // warnings handed out by take_warning()
};

// What take_warning() reports: the offered rates of the last measuring window
// (1 s of frame time) that dropped frames, the limits, and the drops since the
// previous warning.
struct FrameRateWarning {
  double window_s = 1.0;
  double frames_per_s = 0.0;        // frames offered in that window / window_s
  double empty_frames_per_s = 0.0;  // of which without blocks
  std::uint64_t dropped = 0;        // frames dropped since the previous warning
  std::uint64_t empty_dropped = 0;  // of which without blocks
  double frame_rate_hz = 0.0;       // the limits
  double max_frame_rate_hz = 0.0;

  // One log line, e.g. "frame rate over the limit: 3512 frames/s offered (3512
  // without blocks), limits 50 Hz for frames without blocks (pixy.frame_rate_hz)
  // and 60 Hz for all frames (pixy.max_frame_rate_hz); 17500 frames dropped
  // since the last warning (17500 without blocks)".
  std::string text() const;
};

// Decides, frame by frame, whether the bridge publishes a camera frame, from
// the frame's time (the host clock in ns that stamps it; no clock is read
// here). Two limits, each a GCRA / token bucket over frame times:
//   * frames without blocks: at most frame_rate_hz,
//   * all frames: at most max_frame_rate_hz;
// a frame without blocks must pass both and uses up room in both. Over any
// stretch of D seconds of frame time, at most rate * D + 1 + tolerance_s * rate
// frames pass a limit. A frame over a limit is dropped and counted; frames at
// or under the limits (a 50 Hz camera, with jitter up to tolerance_s) all pass.
// A frame time earlier than the previous one (the host clock stepped back)
// restarts both schedules there and is counted. Thread-compatible.
class FrameRateLimiter {
 public:
  // Throws std::invalid_argument for options validate() refuses.
  explicit FrameRateLimiter(const FrameRateOptions& options = {});

  // True if the frame at `time_ns` (without blocks when `empty`) is to be
  // published; false if it is dropped (and counted).
  bool admit(std::uint64_t time_ns, bool empty);

  // A warning when a measuring window that dropped frames has ended by
  // `now_ns` (same clock as the frame times), at most one per warn_period_s;
  // empty otherwise. Call it after admit() and now and then while no frames come.
  std::optional<FrameRateWarning> take_warning(std::uint64_t now_ns);

  const FrameRateCounters& counters() const { return counters_; }
  const FrameRateOptions& options() const { return options_; }

 private:
  // A limit: the theoretical arrival time of the next frame (GCRA).
  struct Schedule {
    std::uint64_t interval_ns = 0;
    std::uint64_t next_ns = 0;
    bool conforms(std::uint64_t t, std::uint64_t tolerance_ns) const { return next_ns <= t + tolerance_ns; }
    void take(std::uint64_t t) { next_ns = (next_ns > t ? next_ns : t) + interval_ns; }
  };
  // Closes the measuring window if `t` is past its end.
  void roll_window(std::uint64_t t);

  FrameRateOptions options_;
  std::uint64_t tolerance_ns_ = 0;
  Schedule empty_;
  Schedule all_;
  bool started_ = false;
  std::uint64_t last_ns_ = 0;
  FrameRateCounters counters_;

  // Measuring windows (1 s of frame time) and the warning state.
  std::uint64_t window_start_ns_ = 0;
  std::uint64_t window_frames_ = 0;
  std::uint64_t window_empty_frames_ = 0;
  std::uint64_t window_dropped_ = 0;
  std::optional<FrameRateWarning> pending_;  // the last closed window that dropped frames
  std::uint64_t dropped_since_warning_ = 0;
  std::uint64_t empty_dropped_since_warning_ = 0;
  bool warned_ = false;
  std::uint64_t last_warning_ns_ = 0;
};

}  // namespace pixyslam::pixy
