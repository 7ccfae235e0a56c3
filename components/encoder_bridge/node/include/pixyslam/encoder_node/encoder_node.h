#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "odometry.h"
#include "pixyslam/bridge/bridge_runtime.h"
#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/odometry_stream.h"
#include "pixyslam/encoder_node/encoder_node_options.h"

namespace pixyslam::encoder_node {

struct EncoderNodeCounters {
  bridge::DeviceCounters device;
  encoder::ArduinoParserCounters parser;
  encoder::WheelCounters wheel;
  encoder::AccumulatorCounters accumulator;
  encoder::ArduinoClock::Counters clock;
  std::uint64_t published = 0;         // Odometry messages written
  std::uint64_t publish_failures = 0;  // writes DDS refused
  std::uint64_t empty_periods = 0;     // periods published without any sample (v = w = 0)
};

// The encoder_bridge process: reads the Arduino's line protocol from a byte
// source (the serial device, or a test's twin) on one reader thread,
// parses it (ArduinoLineParser) and turns samples into fixed-rate odometry
// (OdometryStream: wheel motion resampled to publish_rate_hz), publishing one
// msg::Odometry per period on the odometry topic, stamped at the period's
// start on the host clock (dds::now_ns() domain; Arduino times are mapped onto
// it by ArduinoClock), frame "base_link".
//
// Device trouble (missing, unplugged, read errors) is logged naming the device
// and retried every reopen_period_s; it never stops the node. While no sample
// arrives for max_sample_gap_s, the elapsed periods are published as "no data"
// (v = w = 0, encoder_samples = 0) so the stream keeps its rate. Counters go to
// the log every status_period_s and at stop(). Thread-safe.
class EncoderNode {
 public:
  // Reads options.process.serial_device at options.process.baud.
  explicit EncoderNode(const EncoderNodeOptions& options,
                       bridge::LogFunction log = bridge::stderr_log("encoder_bridge"));
  // Reads `source` instead; `clock` (default dds::now_ns) stamps what it reads.
  EncoderNode(const EncoderNodeOptions& options, std::unique_ptr<bridge::ByteSource> source,
              bridge::LogFunction log, bridge::ClockFunction clock = {});
  // Stops the node.
  ~EncoderNode();
  EncoderNode(const EncoderNode&) = delete;
  EncoderNode& operator=(const EncoderNode&) = delete;

  // Starts the reader thread.
  void start();
  // Joins the reader thread (within ~50 ms) and logs the counters; idempotent.
  void stop();

  // Waits until `count` readers matched the odometry writer; false on timeout.
  bool wait_for_subscribers(int count, std::chrono::milliseconds timeout) const;
  EncoderNodeCounters counters() const;
  // The counters as log lines.
  std::vector<std::string> status_lines() const;

 private:
  // The reader thread's handlers, called with mutex_ held (BridgeRuntime).
  void on_open();
  void on_bytes(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns);
  void on_poll(std::uint64_t now_ns);
  void on_reset(const encoder::EncoderReset& reset);
  void publish(const encoder::StreamOutput& output);
  std::vector<diagnostics::Counter> diagnostic_counters_locked() const;
  std::vector<std::string> status_lines_locked() const;

  EncoderNodeOptions options_;

  // Reader-thread state; others read it under mutex_.
  mutable std::mutex mutex_;
  encoder::ArduinoLineParser parser_;
  encoder::OdometryStream stream_;

  bridge::BridgeRuntime<msg::Odometry> runtime_;  // last: its thread uses the members above
};

}  // namespace pixyslam::encoder_node
