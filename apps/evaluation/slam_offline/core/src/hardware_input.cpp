#include "pixyslam/offline/hardware_input.h"

#include <cstdio>
#include <variant>

#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/wheel_odometry.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_geometry.h"

namespace pixyslam::offline {

RunInput hardware_input(const robot_sim::RobotSimConfig& config, double duration_s, double step_s) {
  robot_sim::HardwareEmulator emulator = robot_sim::make_hardware_emulator(config);
  encoder::ArduinoLineParser line_parser;
  encoder::WheelOdometry wheels(config.encoder);
  encoder::OdometryAccumulator accumulator(config.encoder.publish_rate_hz);
  pixy::PixyBlockParser block_parser;
  pixy::DetectionCounters detection_counters;

  RunInput in;
  in.initial_pose = slam::Pose2::Zero();
  in.start_time_s = 0.0;
  for (const eval::LandmarkPoint& l : emulator.landmarks()) {
    if (emulator.signature_of(l.id)) in.landmarks.push_back(l);
  }
  for (double t = 0.0; t <= duration_s + 1e-9; t += step_s) {
    const robot_sim::HardwareOutput out = emulator.advance_to(t);
    in.truth.insert(in.truth.end(), out.truth.begin(), out.truth.end());
    line_parser.feed(out.arduino_bytes.data(), out.arduino_bytes.size(), [&](const encoder::ArduinoMessage& m) {
      if (const auto* reset = std::get_if<encoder::EncoderReset>(&m)) {
        wheels.reset(*reset);
        return;
      }
      const encoder::WheelUpdate update = wheels.update(std::get<encoder::EncoderSample>(m));
      for (const encoder::OdometryOutput& o : accumulator.add(t, update)) {
        in.odometry.push_back({o.t_s, o.v_mps, o.w_radps});
      }
    });
    auto on_frame = [&](pixy::PixyFrame&& frame) {
      slam::ObservationFrame f;
      f.t_s = t;
      for (const pixy::Detection& d :
           pixy::to_detections(frame, config.pixy.signatures, config.pixy.camera, detection_counters)) {
        f.detections.push_back({d.landmark_id, d.range_m, d.bearing_rad, d.range_sigma_m, d.bearing_sigma_rad});
      }
      if (!f.detections.empty()) in.frames.push_back(std::move(f));
    };
    block_parser.feed(out.pixy_bytes.data(), out.pixy_bytes.size(), on_frame);
    // The live bridge closes a frame when the line goes idle; here every step
    // ends with the emulator's output complete.
    if (!out.pixy_bytes.empty()) {
      if (auto frame = block_parser.flush()) on_frame(std::move(*frame));
    }
  }
  std::printf("pixy bridge parsers      %llu frames, %llu blocks: %llu detections, %llu rejected by aspect\n",
              static_cast<unsigned long long>(block_parser.counters().frames),
              static_cast<unsigned long long>(detection_counters.blocks),
              static_cast<unsigned long long>(detection_counters.detections),
              static_cast<unsigned long long>(detection_counters.bad_aspect));
  return in;
}

}  // namespace pixyslam::offline
