#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "landmark_observation.h"
#include "pixyslam/bridge/bridge_runtime.h"
#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/pixy/frame_rate_limiter.h"
#include "pixyslam/pixy/frame_stamp.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/pixy_node/pixy_node_options.h"

namespace pixyslam::pixy_node {

struct PixyNodeCounters {
  bridge::DeviceCounters device;
  pixy::PixyParserCounters parser;
  pixy::DetectionCounters detections;
  pixy::FrameRateCounters rate;          // frames over pixy.frame_rate_hz / max_frame_rate_hz, dropped
  std::uint64_t published = 0;           // LandmarkObservation messages written
  std::uint64_t publish_failures = 0;    // writes DDS refused
  std::uint64_t frames_timed_out = 0;    // frames closed by frame_timeout_s (not by the next frame)
  std::uint64_t detections_dropped = 0;  // beyond the message's bound
};

// The pixy_bridge process: reads the Pixy's UART block stream from a byte
// source (the serial device, or a test's twin) on one reader thread, parses it
// into frames (PixyBlockParser), turns each frame's blocks into landmark
// range/bearing detections (to_detections, seed paper Eq. 5/6) and publishes one
// msg::LandmarkObservation per camera frame, also frames without detections,
// frame "camera".
//
// Frame rate: a frame is published only if pixy::FrameRateLimiter admits it at
// its stamp (before camera_latency_s): frames without blocks at most
// pixy.frame_rate_hz, all frames at most pixy.max_frame_rate_hz. The others are
// dropped before any geometry or DDS work, so a flood of sync words or frames
// is read at line rate; they are counted (frames_rate_limited on the
// diagnostics topic, which then says WARN) and a "WARN: frame rate over the
// limit: ..." line naming the offered rate and the limits is logged at most
// every 5 s while it lasts.
//
// Stamp: the host time (dds::now_ns() domain) at which the frame's last block
// was read (for a frame without blocks: its start), minus camera_latency_s;
// frames that came bunched up in one read are placed a camera frame period
// apart, the period measured on frames read one at a time (pixy::FrameClock).
// A frame is complete when the next frame starts, or when no data came for it
// for frame_timeout_s (the camera sends nothing while it sees nothing).
//
// Device trouble is logged naming the device and retried every
// reopen_period_s; it never stops the node. Counters go to the log every
// status_period_s and at stop(). Thread-safe.
class PixyNode {
 public:
  // Reads options.process.serial_device at options.process.baud.
  explicit PixyNode(const PixyNodeOptions& options, bridge::LogFunction log = bridge::stderr_log("pixy_bridge"));
  // Reads `source` instead; `clock` (default dds::now_ns) stamps what it reads.
  PixyNode(const PixyNodeOptions& options, std::unique_ptr<bridge::ByteSource> source, bridge::LogFunction log,
           bridge::ClockFunction clock = {});
  ~PixyNode();
  PixyNode(const PixyNode&) = delete;
  PixyNode& operator=(const PixyNode&) = delete;

  // Starts the reader thread.
  void start();
  // Joins the reader thread (within ~50 ms) and logs the counters; idempotent.
  void stop();

  // Waits until `count` readers matched the observation writer; false on timeout.
  bool wait_for_subscribers(int count, std::chrono::milliseconds timeout) const;
  PixyNodeCounters counters() const;
  // The counters as log lines.
  std::vector<std::string> status_lines() const;

 private:
  // The reader thread's handlers, called with mutex_ held (BridgeRuntime).
  void on_bytes(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns);
  void on_poll(std::uint64_t now_ns);
  std::uint64_t frame_timeout_ns() const;
  // When the open frame times out (0: none open): the device read waits no
  // longer, so a frame no next frame ends goes out frame_timeout_s after its
  // last byte, not at the next 50 ms read timeout.
  std::uint64_t open_frame_deadline_ns() const;
  // The end of the frame that was open before this chunk (frame_end_ns_), now complete.
  std::uint64_t complete_open_frame(std::uint64_t index);
  // Publishes the frame unless the rate limiter drops it.
  void publish(const pixy::PixyFrame& frame, std::uint64_t end_ns);
  void log_rate_warning(std::uint64_t now_ns);
  std::vector<diagnostics::Counter> diagnostic_counters_locked() const;
  std::vector<std::string> status_lines_locked() const;

  PixyNodeOptions options_;

  // Reader-thread state; others read it under mutex_.
  mutable std::mutex mutex_;
  pixy::PixyBlockParser parser_;
  pixy::DetectionCounters detection_counters_;
  pixy::FrameRateLimiter rate_limiter_;
  std::uint64_t open_frame_read_ns_ = 0;  // host time the open frame last advanced (opened or got a block)
  std::uint64_t frame_end_ns_ = 0;        // its end: that time, or where FrameClock placed it
  std::uint64_t previous_read_ns_ = 0;  // host time of the last chunk read
  // The frames one chunk completed, stamped once the whole chunk is parsed.
  struct ChunkFrame {
    pixy::PixyFrame frame;
    bool ended_in_chunk = false;   // its last block (or its start) came in this chunk
    std::uint64_t starts_seen = 0;  // parser frame_syncs when it completed (with the next frame's start)
  };
  std::vector<ChunkFrame> chunk_frames_;
  pixy::FrameClock frame_clock_;     // the frames' end times
  bool open_frame_bunched_ = false;  // the open frame came in a chunk with others (frame_end_ns_ estimated)
  std::uint64_t frames_timed_out_ = 0;
  std::uint64_t detections_dropped_ = 0;

  bridge::BridgeRuntime<msg::LandmarkObservation> runtime_;  // last: its thread uses the members above
};

}  // namespace pixyslam::pixy_node
