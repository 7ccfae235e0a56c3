#include "pixyslam/pixy_node/pixy_node.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <utility>

#include "pixyslam/pixy/frame_stamp.h"
#include "pixyslam/pixy_node/observation_conversions.h"

namespace pixyslam::pixy_node {
namespace {

// The options, once the camera model and the frame rates passed pixy::validate()
// (before any DDS entity exists).
const PixyNodeOptions& validated(const PixyNodeOptions& options) {
  pixy::validate(options.pixy.camera);
  pixy::validate(options.pixy.rate);
  return options;
}

}  // namespace

PixyNode::PixyNode(const PixyNodeOptions& options, bridge::LogFunction log)
    : PixyNode(options, std::make_unique<bridge::SerialByteSource>(options.process.serial_device, options.process.baud),
               std::move(log)) {}

PixyNode::PixyNode(const PixyNodeOptions& options, std::unique_ptr<bridge::ByteSource> source,
                   bridge::LogFunction log, bridge::ClockFunction clock)
    : options_(validated(options)),
      rate_limiter_(options_.pixy.rate),
      frame_clock_(options_.pixy.rate.frame_rate_hz),
      runtime_("pixy_bridge", options.dds, options.process, std::move(source), std::move(log), std::move(clock),
               mutex_) {}

PixyNode::~PixyNode() { stop(); }

void PixyNode::start() {
  runtime_.start("reading '" + runtime_.device_name() + "', publishing one observation per camera frame on '" +
                     std::string(dds::kLandmarkObservationTopic) + "' (" +
                     std::to_string(options_.pixy.signatures.size()) + " landmark signatures)",
                 {{},
                  [this](const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns) {
                    on_bytes(data, size, receive_ns);
                  },
                  [this](std::uint64_t now_ns) { on_poll(now_ns); },
                  [this] { return status_lines_locked(); },
                  [this] { return diagnostic_counters_locked(); },
                  [this] { return open_frame_deadline_ns(); }});
}

std::vector<diagnostics::Counter> PixyNode::diagnostic_counters_locked() const {
  const pixy::PixyParserCounters& p = parser_.counters();
  const pixy::DetectionCounters& k = detection_counters_;
  const pixy::FrameRateCounters& r = rate_limiter_.counters();
  return {{"bytes_in", p.bytes_in, false},
          {"bytes_skipped", p.bytes_skipped, true},
          {"frames", p.frames, false},
          // Frames over pixy.frame_rate_hz (without blocks) or pixy.max_frame_rate_hz: dropped.
          {"frames_rate_limited", r.rate_limited, true},
          {"empty_frames_rate_limited", r.empty_rate_limited, false},
          {"blocks_ok", p.blocks_ok, false},
          {"checksum_errors", p.checksum_errors, true},
          {"blocks_over_frame_limit", p.blocks_over_frame_limit, true},
          {"resyncs", p.resyncs, true},
          {"detections", k.detections, false},
          {"unknown_signature", k.unknown_signature, true},
          // Partly visible poles (image edges) fail these checks all the time: not a warning.
          {"bad_aspect", k.bad_aspect, false},
          {"outside_image", k.outside_image, false},
          {"zero_height", k.zero_height, false},
          {"duplicate_landmark", k.duplicate_landmark, false},
          {"detections_dropped", detections_dropped_, true}};
}

void PixyNode::stop() { runtime_.stop(); }

bool PixyNode::wait_for_subscribers(int count, std::chrono::milliseconds timeout) const {
  return runtime_.wait_for_readers(count, timeout);
}

PixyNodeCounters PixyNode::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  PixyNodeCounters c;
  c.device = runtime_.device_counters();
  c.parser = parser_.counters();
  c.detections = detection_counters_;
  c.rate = rate_limiter_.counters();
  c.published = runtime_.published();
  c.publish_failures = runtime_.publish_failures();
  c.frames_timed_out = frames_timed_out_;
  c.detections_dropped = detections_dropped_;
  return c;
}

std::vector<std::string> PixyNode::status_lines() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_lines_locked();
}

std::vector<std::string> PixyNode::status_lines_locked() const {
  const pixy::PixyParserCounters& p = parser_.counters();
  const pixy::DetectionCounters& k = detection_counters_;
  const pixy::FrameRateCounters& r = rate_limiter_.counters();
  std::ostringstream stream, detections;
  stream << "status: frames " << p.frames << " (ended by the pause after them " << frames_timed_out_ << ", over the frame rate limit "
         << r.rate_limited << ", of which without blocks " << r.empty_rate_limited << "), blocks " << p.blocks_ok
         << " (colour code " << p.colour_code_blocks_ok << ", outside a frame " << p.blocks_outside_frame
         << ", over the per-frame limit " << p.blocks_over_frame_limit << "), checksum errors " << p.checksum_errors << ", signature 0 " << p.zero_signature_blocks
         << ", resyncs " << p.resyncs << ", bytes skipped " << p.bytes_skipped;
  detections << "status: detections " << k.detections << " of " << k.blocks << " blocks; rejected: unknown signature "
             << k.unknown_signature << ", zero height " << k.zero_height << ", outside image " << k.outside_image
             << ", bad aspect " << k.bad_aspect << ", duplicate " << k.duplicate_landmark
             << "; observations published " << runtime_.published() << ", failed " << runtime_.publish_failures()
             << ", detections dropped " << detections_dropped_;
  return {runtime_.device_status_line(), stream.str(), detections.str()};
}

void PixyNode::on_bytes(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns) {
  // A frame ends with its last block, but is known to be complete only when
  // the next frame starts. "Progress" (blocks + frame starts parsed) tells
  // whether the frame being delivered got anything from this chunk; if it did,
  // the frame starts after it in the chunk tell how long before the read it
  // ended (pixy::FrameClock), so all of a chunk's frames are parsed before any
  // is stamped.
  const auto progress = [this] { return parser_.counters().blocks_ok + parser_.counters().frame_syncs; };
  std::uint64_t mark = progress();
  bool opened_here = false;  // the frame being delivered was opened in this chunk
  chunk_frames_.clear();
  parser_.feed(data, size, [&](pixy::PixyFrame&& frame) {
    const std::uint64_t now = progress();  // includes the sync that opened the next frame
    chunk_frames_.push_back({std::move(frame), opened_here || now - 1 > mark, parser_.counters().frame_syncs});
    mark = now;
    opened_here = true;
  });
  // Frames that ended in this chunk ended after the previous read (none is
  // spread back before the first read). Read within a period of the previous
  // read, their ends are known within that read interval; otherwise, if two or
  // more frames had bytes in the chunk (the open one included), they came
  // bunched up and pixy::FrameClock places them.
  const std::uint64_t earliest_ns = previous_read_ns_ == 0 ? receive_ns : previous_read_ns_;
  const bool prompt = receive_ns - earliest_ns < frame_clock_.period_ns();
  const bool bunched = !prompt && std::any_of(chunk_frames_.begin(), chunk_frames_.end(),
                                              [](const ChunkFrame& f) { return f.ended_in_chunk; });
  const std::uint64_t starts = parser_.counters().frame_syncs;
  for (const ChunkFrame& f : chunk_frames_) {
    if (!f.ended_in_chunk) {
      publish(f.frame, complete_open_frame(f.frame.index));
    } else if (!bunched) {
      publish(f.frame, frame_clock_.measured(f.frame.index, earliest_ns));
    } else {
      const std::uint64_t starts_after = starts - f.starts_seen + 1;
      publish(f.frame, frame_clock_.bunched(f.frame.index, receive_ns, earliest_ns, starts_after));
    }
  }
  if (!chunk_frames_.empty() || progress() > mark) {  // the open frame advanced
    open_frame_read_ns_ = receive_ns;
    open_frame_bunched_ = bunched;
    frame_end_ns_ = bunched  // it came with the others: placed like them
                        ? frame_clock_.bunched(chunk_frames_.back().frame.index + 1, receive_ns, earliest_ns, 0)
                        : receive_ns;
  }
  previous_read_ns_ = receive_ns;
  log_rate_warning(receive_ns);
}

std::uint64_t PixyNode::frame_timeout_ns() const {
  return static_cast<std::uint64_t>(std::llround(options_.frame_timeout_s * 1e9));
}

std::uint64_t PixyNode::open_frame_deadline_ns() const {
  return parser_.frame_open() ? open_frame_read_ns_ + frame_timeout_ns() + 1 : 0;
}

void PixyNode::on_poll(std::uint64_t now_ns) {
  if (parser_.frame_open() && now_ns > open_frame_read_ns_ + frame_timeout_ns()) {
    if (std::optional<pixy::PixyFrame> frame = parser_.flush()) {
      ++frames_timed_out_;
      publish(*frame, complete_open_frame(frame->index));
    }
  }
  log_rate_warning(now_ns);
}

std::uint64_t PixyNode::complete_open_frame(std::uint64_t index) {
  return open_frame_bunched_ ? frame_clock_.estimated(frame_end_ns_) : frame_clock_.measured(index, frame_end_ns_);
}

void PixyNode::log_rate_warning(std::uint64_t now_ns) {
  if (const std::optional<pixy::FrameRateWarning> w = rate_limiter_.take_warning(now_ns)) {
    runtime_.log("WARN: " + w->text());
  }
}

void PixyNode::publish(const pixy::PixyFrame& frame, std::uint64_t end_ns) {
  // First, before any work: a flood of frames must cost no more than parsing.
  if (!rate_limiter_.admit(end_ns, frame.blocks.empty())) return;
  const std::vector<pixy::Detection> detections =
      pixy::to_detections(frame, options_.pixy.signatures, options_.pixy.camera, detection_counters_);
  if (detections.size() > kMaxDetectionsPerMessage) {
    detections_dropped_ += detections.size() - kMaxDetectionsPerMessage;
  }
  const auto latency_ns = static_cast<std::uint64_t>(std::llround(options_.camera_latency_s * 1e9));
  msg::LandmarkObservation m = to_observation_msg(frame, detections, end_ns > latency_ns ? end_ns - latency_ns : 0);
  runtime_.publish(m);
}

}  // namespace pixyslam::pixy_node
