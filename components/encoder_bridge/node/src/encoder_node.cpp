#include "pixyslam/encoder_node/encoder_node.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <variant>

#include "pixyslam/encoder_node/odometry_conversions.h"

namespace pixyslam::encoder_node {

EncoderNode::EncoderNode(const EncoderNodeOptions& options, bridge::LogFunction log)
    : EncoderNode(options,
                  std::make_unique<bridge::SerialByteSource>(options.process.serial_device, options.process.baud),
                  std::move(log)) {}

EncoderNode::EncoderNode(const EncoderNodeOptions& options, std::unique_ptr<bridge::ByteSource> source,
                         bridge::LogFunction log, bridge::ClockFunction clock)
    : options_(options),
      stream_(options.encoder, options.clock_window_s),
      runtime_("encoder_bridge", options.dds, options.process, std::move(source), std::move(log),
               std::move(clock), mutex_) {}

EncoderNode::~EncoderNode() { stop(); }

void EncoderNode::start() {
  runtime_.start("reading '" + runtime_.device_name() + "', publishing odometry at " +
                     bridge::yaml_number(options_.encoder.publish_rate_hz) + " Hz on '" +
                     std::string(dds::kOdometryTopic) + "'",
                 {[this] { on_open(); },
                  [this](const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns) {
                    on_bytes(data, size, receive_ns);
                  },
                  [this](std::uint64_t now_ns) { on_poll(now_ns); },
                  [this] { return status_lines_locked(); },
                  [this] { return diagnostic_counters_locked(); },
                  {}});  // no poll deadline: its periods are checked every poll
}

std::vector<diagnostics::Counter> EncoderNode::diagnostic_counters_locked() const {
  const encoder::ArduinoParserCounters& p = parser_.counters();
  const encoder::WheelCounters& w = stream_.wheel_counters();
  return {{"bytes_in", p.bytes_in, false},
          {"bytes_skipped", p.bytes_skipped, true},
          {"samples", p.samples, false},
          {"arduino_resets", p.resets, false},
          {"lines_rejected", p.rejected_lines(), true},
          {"bad_checksum", p.bad_checksum, true},
          {"wheel_steps", w.steps, false},
          {"samples_lost", w.lost_samples, true},
          {"sequence_backwards", w.sequence_backwards, true},
          {"time_gaps", w.time_gaps, true},
          {"implausible_steps", w.implausible, true},
          {"empty_periods", stream_.empty_periods(), true},
          {"late_steps_dropped", stream_.accumulator_counters().steps_after_gap, true}};
}

void EncoderNode::stop() { runtime_.stop(); }

bool EncoderNode::wait_for_subscribers(int count, std::chrono::milliseconds timeout) const {
  return runtime_.wait_for_readers(count, timeout);
}

EncoderNodeCounters EncoderNode::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  EncoderNodeCounters c;
  c.device = runtime_.device_counters();
  c.parser = parser_.counters();
  c.wheel = stream_.wheel_counters();
  c.accumulator = stream_.accumulator_counters();
  c.clock = stream_.clock().counters();
  c.published = runtime_.published();
  c.publish_failures = runtime_.publish_failures();
  c.empty_periods = stream_.empty_periods();
  return c;
}

std::vector<std::string> EncoderNode::status_lines() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_lines_locked();
}

std::vector<std::string> EncoderNode::status_lines_locked() const {
  const encoder::ArduinoParserCounters& p = parser_.counters();
  const encoder::WheelCounters& w = stream_.wheel_counters();
  const encoder::ArduinoClock::Counters& k = stream_.clock().counters();
  std::ostringstream lines, motion;
  lines << "status: lines: samples " << p.samples << ", resets " << p.resets << ", rejected "
        << p.rejected_lines() << " (framing " << p.bad_framing << ", checksum " << p.bad_checksum
        << ", unknown type " << p.unknown_type << ", field count " << p.wrong_field_count << ", bad field "
        << p.bad_field << ", overlong " << p.overlong_lines << ", unterminated " << p.unterminated_lines
        << "), bytes skipped " << p.bytes_skipped;
  motion << "status: wheel steps " << w.steps << ", duplicates " << w.duplicates << ", seq gaps "
         << w.sequence_gaps << " (lost " << w.lost_samples << "), seq backwards " << w.sequence_backwards
         << ", time gaps " << w.time_gaps << ", implausible " << w.implausible << ", ticks/rev mismatches "
         << w.ticks_per_revolution_mismatches << "; clock restarts " << k.restarts << ", jumps " << k.jumps
         << ", last excess delay " << static_cast<double>(stream_.clock().last_excess_delay_ns()) * 1e-6
         << " ms; odometry published " << runtime_.published() << ", failed " << runtime_.publish_failures()
         << ", empty periods " << stream_.empty_periods() << " (late steps dropped "
         << stream_.accumulator_counters().steps_after_gap << ")";
  return {runtime_.device_status_line(), lines.str(), motion.str()};
}

void EncoderNode::on_open() { stream_.restart_clock(); }

void EncoderNode::on_bytes(const std::uint8_t* data, std::size_t size, std::uint64_t receive_ns) {
  parser_.feed(data, size, [&](const encoder::ArduinoMessage& message) {
    if (const auto* sample = std::get_if<encoder::EncoderSample>(&message)) {
      stream_.add_sample(*sample, receive_ns, [this](const encoder::StreamOutput& o) { publish(o); });
    } else {
      on_reset(std::get<encoder::EncoderReset>(message));
    }
  });
}

void EncoderNode::on_reset(const encoder::EncoderReset& reset) {
  stream_.reset(reset);
  std::string line = "Arduino (re)started: firmware '" + reset.firmware_version + "', ticks_per_revolution " +
                     std::to_string(reset.ticks_per_revolution);
  if (reset.ticks_per_revolution != 0 &&
      reset.ticks_per_revolution != static_cast<std::uint32_t>(options_.encoder.ticks_per_revolution)) {
    line += " differs from the configured " + std::to_string(options_.encoder.ticks_per_revolution) +
            " (the configuration is used)";
  }
  runtime_.log(line);
}

void EncoderNode::on_poll(std::uint64_t now_ns) {
  stream_.poll(now_ns, [this](const encoder::StreamOutput& o) { publish(o); });
}

void EncoderNode::publish(const encoder::StreamOutput& output) {
  msg::Odometry m = to_odometry_msg(output.odometry, output.samples, output.epoch_ns);
  runtime_.publish(m);
}

}  // namespace pixyslam::encoder_node
