#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace pixyslam::pixy {

// When a camera frame ended, on the host clock, from when the bytes that ended
// it were read. The bridge reads the UART in chunks. Read promptly, a chunk
// holds at most the end of one frame and the start of the next; a host that
// left the reader (or the camera's writer, robot_sim) unscheduled for a while
// hands over several frames in one chunk, and stamping them all with the read
// time would tell the estimator the robot saw them all at once, where it stood
// when the chunk was read.
//
// The camera sends a frame every `period_ns`, so a frame followed in its chunk
// by `starts_after` frame starts ended about that many periods before the chunk
// was read; and it ended after `earliest_ns`, the previous read (its bytes were
// not in it). Returns
//   read_ns - starts_after * period_ns, clamped to [earliest_ns, read_ns]:
// read_ns for the frame still open at the chunk's end (starts_after 0), and
// for chunks read promptly (the previous read less than a period ago) within
// one read interval of the read time. A flood (more frames than periods since
// earliest_ns) piles up at earliest_ns, where the rate limiter holds it to the
// camera's rate.
std::uint64_t bunched_frame_end_ns(std::uint64_t read_ns, std::uint64_t earliest_ns, std::uint64_t starts_after,
                                   std::uint64_t period_ns);

// The camera's frame period as its stream shows it. The Pixy computes 50
// frames per second but a bridge or a simulator may deliver fewer (robot_sim:
// 10 Hz), so the period is measured: the lower quartile of the last 32
// intervals between consecutive frames that were each read on their own
// (add_interval_ns), intervals over 1 s left out (the camera was silent). The
// lower quartile, because a frame the camera did not send (nothing seen) makes
// one interval two periods long. Never below 1 / frame_rate_hz (the fastest
// the camera goes); that value until 8 intervals are in. Thread-compatible.
class FramePeriodEstimate {
 public:
  explicit FramePeriodEstimate(double frame_rate_hz);

  void add_interval_ns(std::uint64_t interval_ns);
  std::uint64_t period_ns() const { return period_ns_; }

 private:
  static constexpr std::size_t kIntervals = 32;
  static constexpr std::size_t kMinIntervals = 8;
  std::uint64_t min_period_ns_;
  std::uint64_t period_ns_;
  std::array<std::uint64_t, kIntervals> intervals_{};
  std::size_t count_ = 0;  // intervals added (the ring holds the last kIntervals)
};

// The times at which a camera's frames ended, on the host clock, for a bridge
// that reads the camera's byte stream in chunks. A frame read on its own
// (promptly: the only frame its chunk completed) is a measurement; frames
// bunched up in one chunk are placed between two bounds, with the period P
// measured on the measurements (FramePeriodEstimate):
//   * from the read back (bunched_frame_end_ns): no later than
//     read - starts_after * P, each frame at least P after the one before;
//   * from the last measurement forward: no earlier than
//     anchor + (index - anchor index) * P, for the same reason.
// If the two are less than a period apart, no frame can have gone unsent in
// between, and the forward one is the frame's time (the camera's phase; the
// backward one can be up to a period late, the time between the last frame and
// the read); otherwise the backward one. Never before the previous read.
// Thread-compatible.
class FrameClock {
 public:
  explicit FrameClock(double frame_rate_hz);

  // Frame `index` (PixyFrame::index) ended when the chunk read at `end_ns`
  // delivered its last bytes, alone. Returns end_ns.
  std::uint64_t measured(std::uint64_t index, std::uint64_t end_ns);
  // Frame `index` ended in a chunk read at `read_ns` together with other
  // frames, followed there by `starts_after` frame starts; `earliest_ns`: the
  // previous read. Returns its estimated end.
  std::uint64_t bunched(std::uint64_t index, std::uint64_t read_ns, std::uint64_t earliest_ns,
                        std::uint64_t starts_after);
  // A frame placed by bunched() earlier (the frame a bunched chunk left open,
  // whose end was that chunk's read) ended at `end_ns`: not a measurement.
  // Returns end_ns.
  std::uint64_t estimated(std::uint64_t end_ns);

  std::uint64_t period_ns() const { return period_.period_ns(); }

 private:
  FramePeriodEstimate period_;
  bool last_measured_ = false;  // the previous frame was a measurement
  bool has_anchor_ = false;
  std::uint64_t anchor_index_ = 0;  // the last measurement
  std::uint64_t anchor_ns_ = 0;
};

}  // namespace pixyslam::pixy
