// Tests of the robot-hardware emulator through the bridges' real decoders:
// Arduino lines -> ArduinoLineParser -> WheelOdometry -> OdometryAccumulator
// give back the path's (v, w) within the configured noise and, without noise,
// a dead-reckoned pose close to the truth; Pixy bytes -> PixyBlockParser ->
// to_detections give back the true range and bearing within the pixel
// quantisation, with the right ids; the field of view; determinism; counter
// and clock wrap-around; the options and the shipped config.

#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/wheel_odometry.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/robot_sim/hardware_emulator.h"
#include "pixyslam/robot_sim/robot_sim_config.h"
#include "pixyslam/slam/motion_model.h"

namespace pixyslam::robot_sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Rig {
  sim::WorldOptions world;
  encoder::EncoderOptions encoder;
  pixy::CameraModel camera;
  pixy::SignatureMap signatures;
  HardwareOptions hardware;

  HardwareEmulator make() const { return HardwareEmulator(world, encoder, camera, signatures, hardware); }
};

// The paper-like world (20 poles, ids 1..20), the shipped wheels and camera.
// Ids 1..5 carry single tags (normal blocks), 6..19 two-tag colour codes, and
// pole 20 no signature at all (invisible).
Rig paper_setup() {
  Rig s;
  s.camera.landmark_height_m = 0.08;
  for (int id = 1; id <= 5; ++id) s.signatures.add(static_cast<std::uint16_t>(id), id);
  int id = 6;
  for (int a = 1; a <= 7 && id <= 19; ++a) {
    for (int b = 1; b <= 7 && id <= 19; ++b) {
      if (a != b) s.signatures.add(static_cast<std::uint16_t>(8 * a + b), id++);
    }
  }
  return s;
}

Rig noiseless(Rig s) {
  s.hardware.v_sigma_mps = s.hardware.w_sigma_radps = 0.0;
  s.hardware.range_sigma_m = s.hardware.bearing_sigma_rad = 0.0;
  return s;
}

// The encoder bridge's chain, stamping each line with the emulator time of the
// advance_to() call that produced it.
struct EncoderChain {
  explicit EncoderChain(const encoder::EncoderOptions& o) : odometry(o), accumulator(o.publish_rate_hz) {}

  void feed(double host_time_s, const std::string& bytes) {
    for (const encoder::ArduinoMessage& m : parser.feed(bytes)) {
      if (const auto* r = std::get_if<encoder::EncoderReset>(&m)) {
        resets.push_back(*r);
        odometry.reset(*r);
        continue;
      }
      const auto& s = std::get<encoder::EncoderSample>(m);
      samples.push_back(s);
      const encoder::WheelUpdate u = odometry.update(s);
      if (u.status == encoder::WheelStatus::kStep) steps.push_back(u.step);
      accumulator.add(host_time_s, u, [this](const encoder::OdometryOutput& o) { outputs.push_back(o); });
    }
  }

  encoder::ArduinoLineParser parser;
  encoder::WheelOdometry odometry;
  encoder::OdometryAccumulator accumulator;
  std::vector<encoder::EncoderReset> resets;
  std::vector<encoder::EncoderSample> samples;
  std::vector<encoder::WheelStep> steps;
  std::vector<encoder::OdometryOutput> outputs;
};

// Runs the emulator to `duration_s` one Arduino sample per call.
EncoderChain run_encoder(HardwareEmulator& emu, const Rig& s, double duration_s,
                         std::vector<eval::TimedPose>* truth = nullptr) {
  EncoderChain chain(s.encoder);
  const auto n = static_cast<std::uint64_t>(std::llround(duration_s * s.hardware.arduino_rate_hz));
  for (std::uint64_t k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / s.hardware.arduino_rate_hz;
    HardwareOutput out = emu.advance_to(t);
    chain.feed(t, out.arduino_bytes);
    if (truth) truth->insert(truth->end(), out.truth.begin(), out.truth.end());
  }
  return chain;
}

// Mean of the path's command over [t0, t1), integrated in 0.1 ms steps.
sim::PathCommand mean_command(const sim::LoopPath& path, double t0, double t1) {
  const int n = static_cast<int>(std::llround((t1 - t0) / 1e-4));
  sim::PathCommand m;
  for (int i = 0; i < n; ++i) {
    const sim::PathCommand c = path.command_at(t0 + (i + 0.5) * (t1 - t0) / n);
    m.v_mps += c.v_mps / n;
    m.w_radps += c.w_radps / n;
  }
  return m;
}

struct Stats {
  double mean = 0.0;
  double sd = 0.0;
};

Stats stats(const std::vector<double>& x) {
  Stats s;
  for (const double v : x) s.mean += v / static_cast<double>(x.size());
  for (const double v : x) s.sd += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(s.sd / static_cast<double>(x.size() - 1));
  return s;
}

struct PixyRun {
  std::vector<PixyFrameRecord> frames;  // every frame period
  std::vector<std::uint8_t> bytes;
};

PixyRun run_pixy(HardwareEmulator& emu, double duration_s, double step_s) {
  PixyRun r;
  for (double t = 0.0; t <= duration_s + 1e-9; t += step_s) {
    HardwareOutput out = emu.advance_to(t);
    r.bytes.insert(r.bytes.end(), out.pixy_bytes.begin(), out.pixy_bytes.end());
    r.frames.insert(r.frames.end(), out.frames.begin(), out.frames.end());
  }
  return r;
}

std::vector<pixy::PixyFrame> parse_frames(const std::vector<std::uint8_t>& bytes, pixy::PixyParserCounters* counters) {
  pixy::PixyBlockParser parser;
  std::vector<pixy::PixyFrame> frames = parser.feed(bytes);
  if (auto last = parser.flush()) frames.push_back(std::move(*last));
  if (counters) *counters = parser.counters();
  return frames;
}

// ---------------------------------------------------------------------------
// Arduino

TEST(HardwareEmulator, ArduinoSendsResetThenSamplesFromSeqZero) {
  Rig s = paper_setup();
  s.hardware.arduino_start_time_us = 1234;
  HardwareEmulator emu = s.make();
  EXPECT_TRUE(emu.advance_to(-1.0).arduino_bytes.empty());
  const HardwareOutput out = emu.advance_to(0.1);
  encoder::ArduinoLineParser parser;
  const std::vector<encoder::ArduinoMessage> msgs = parser.feed(out.arduino_bytes);
  EXPECT_EQ(parser.counters().rejected_lines(), 0u);
  EXPECT_EQ(parser.counters().bytes_skipped, 0u);
  ASSERT_EQ(msgs.size(), 7u);  // RST + ENC at 0, 20, ..., 100 ms
  const auto& reset = std::get<encoder::EncoderReset>(msgs[0]);
  EXPECT_EQ(reset.firmware_version, "sim-1");
  EXPECT_EQ(reset.ticks_per_revolution, 1320u);
  for (std::size_t i = 1; i < msgs.size(); ++i) {
    const auto& e = std::get<encoder::EncoderSample>(msgs[i]);
    EXPECT_EQ(e.seq, i - 1);
    EXPECT_EQ(e.arduino_time_us, 1234u + 20000u * (i - 1));
    EXPECT_EQ(e, out.encoder_samples[i - 1].sample);
  }
  EXPECT_EQ(std::get<encoder::EncoderSample>(msgs[1]).left_ticks, 0);
  ASSERT_EQ(out.truth.size(), 6u);
  EXPECT_DOUBLE_EQ(out.truth[5].t_s, 0.1);
  EXPECT_NEAR(out.truth[5].x_m, 0.02, 1e-12);  // 0.2 m/s straight ahead
  EXPECT_EQ(emu.counters().arduino_lines, 7u);
  // Nothing new for a time not after the last one.
  EXPECT_TRUE(emu.advance_to(0.1).arduino_bytes.empty());
  EXPECT_DOUBLE_EQ(emu.time_s(), 0.1);
}

TEST(HardwareEmulator, RecoveredVelocitiesHaveThePapersNoise) {
  // Given the default noise (3 cm/s, 2 deg/s per 10 Hz sample), when the
  // encoder bridge's chain decodes 300 s of lines, then its 10 Hz (v, w) differ
  // from the path's mean command by that much.
  const Rig s = paper_setup();
  HardwareEmulator emu = s.make();
  const EncoderChain chain = run_encoder(emu, s, 300.0);
  EXPECT_EQ(chain.parser.counters().rejected_lines(), 0u);
  EXPECT_EQ(chain.odometry.counters().implausible, 0u);
  ASSERT_GE(chain.outputs.size(), 2990u);
  std::vector<double> ev, ew;
  for (const encoder::OdometryOutput& o : chain.outputs) {
    EXPECT_NEAR(o.covered_s, o.duration_s, 1e-9);
    const sim::PathCommand c = mean_command(emu.path(), o.t_s, o.t_s + o.duration_s);
    ev.push_back(o.v_mps - c.v_mps);
    ew.push_back(o.w_radps - c.w_radps);
  }
  const Stats sv = stats(ev);
  const Stats sw = stats(ew);
  std::cout << "[ info ] 10 Hz odometry error over " << ev.size() << " samples: v mean " << sv.mean << " sd "
            << sv.sd << " m/s (paper 0.03), w mean " << sw.mean << " sd " << sw.sd << " rad/s = "
            << sw.sd * 180.0 / kPi << " deg/s (paper 2)\n";
  EXPECT_NEAR(sv.mean, 0.0, 0.0025);
  EXPECT_NEAR(sw.mean, 0.0, 0.003);
  EXPECT_NEAR(sv.sd, 0.03, 0.03 * 0.06);
  EXPECT_NEAR(sw.sd, 0.0349, 0.0349 * 0.08);
}

TEST(HardwareEmulator, NoiselessDeadReckoningFollowsTheTruth) {
  // Given no noise, the decoded (v, w) match the command within one tick, and
  // integrating them (zero-order hold, as the filter does) stays on the true
  // path over a whole lap with its four corners.
  const Rig s = noiseless(paper_setup());
  HardwareEmulator emu = s.make();
  const double lap = emu.path().lap_time_s();
  std::vector<eval::TimedPose> truth;
  const EncoderChain chain = run_encoder(emu, s, lap + 1.0, &truth);
  std::map<long, eval::TimedPose> truth_at;  // by Arduino sample index
  for (const eval::TimedPose& p : truth) truth_at[std::lround(p.t_s * 50.0)] = p;

  const double tick_m = 2.0 * kPi * s.encoder.wheel_radius_m / s.encoder.ticks_per_revolution;
  slam::Pose2 pose = slam::Pose2::Zero();
  double max_position_error = 0.0;
  double max_heading_error = 0.0;
  for (const encoder::OdometryOutput& o : chain.outputs) {
    const sim::PathCommand c = mean_command(emu.path(), o.t_s, o.t_s + o.duration_s);
    EXPECT_NEAR(o.v_mps, c.v_mps, tick_m / o.duration_s + 1e-9) << o.t_s;
    EXPECT_NEAR(o.w_radps, c.w_radps, 2.0 * tick_m / s.encoder.wheel_base_m / o.duration_s + 1e-9) << o.t_s;
    pose = slam::move(pose, o.v_mps, o.w_radps, o.duration_s);
    const eval::TimedPose& t = truth_at.at(std::lround((o.t_s + o.duration_s) * 50.0));
    max_position_error = std::max(max_position_error, std::hypot(pose.x() - t.x_m, pose.y() - t.y_m));
    max_heading_error = std::max(max_heading_error, std::abs(slam::wrap_angle(pose.z() - t.theta_rad)));
  }
  std::cout << "[ info ] noiseless dead reckoning over " << lap << " s: max position error " << max_position_error
            << " m, max heading error " << max_heading_error << " rad\n";
  EXPECT_GT(chain.outputs.size(), 800u);
  EXPECT_LT(max_position_error, 0.005);
  EXPECT_LT(max_heading_error, 0.003);
  // The truth is the path's geometry, exact up to rounding: (4, 0, 0) after the
  // first side (20 s), then a quarter circle of radius 0.5 m about (4, 0.5);
  // just before the lap closes, the last quarter circle about (0, 0.5).
  const double r = s.world.corner_radius_m;
  const double w = s.world.speed_mps / r;
  const auto expect_pose = [&](long k, double x, double y, double theta) {
    const eval::TimedPose& p = truth_at.at(k);
    EXPECT_NEAR(p.x_m, x, 1e-9) << p.t_s;
    EXPECT_NEAR(p.y_m, y, 1e-9) << p.t_s;
    EXPECT_NEAR(p.theta_rad, theta, 1e-9) << p.t_s;
  };
  expect_pose(1000, 4.0, 0.0, 0.0);
  expect_pose(1100, 4.0 + r * std::sin(2.0 * w), r - r * std::cos(2.0 * w), 2.0 * w);
  const long last = static_cast<long>(std::floor(lap * 50.0));
  const double left = w * (lap - static_cast<double>(last) / 50.0);  // heading still to turn
  expect_pose(last, -r * std::sin(left), r - r * std::cos(left), -left);
}

TEST(HardwareEmulator, CountersAndClockWrapAround) {
  // Counters start 3000 ticks before the int32 limit (forward counting up, or
  // mirrored motors counting down), micros() 1 s before the 2^32 wrap: 10 s of
  // straight driving (2 m, ~12900 ticks) crosses both wraps.
  for (const int sign : {1, -1}) {
    Rig s = noiseless(paper_setup());
    s.encoder.left_sign = s.encoder.right_sign = sign;
    s.hardware.start_ticks = sign > 0 ? std::numeric_limits<std::int32_t>::max() - 3000
                                      : std::numeric_limits<std::int32_t>::min() + 3000;
    s.hardware.arduino_start_time_us = 0xffffffffu - 1000000u + 7u;
    HardwareEmulator emu = s.make();
    const EncoderChain chain = run_encoder(emu, s, 10.0);
    ASSERT_EQ(chain.samples.size(), 501u);
    EXPECT_EQ(chain.samples.front().left_ticks, s.hardware.start_ticks);
    EXPECT_EQ(chain.samples.back().left_ticks < 0, sign > 0) << "the counter did not wrap";
    EXPECT_LT(chain.samples.back().arduino_time_us, chain.samples.front().arduino_time_us);
    EXPECT_EQ(chain.samples.back().arduino_time_us, 9000006u);  // (2^32 - 999993 + 10^7) mod 2^32
    const encoder::WheelCounters& wc = chain.odometry.counters();
    EXPECT_EQ(wc.steps, 500u);
    EXPECT_EQ(wc.implausible, 0u);
    EXPECT_EQ(wc.time_gaps, 0u);
    double distance = 0.0;
    for (const encoder::WheelStep& st : chain.steps) {
      distance += st.distance_m;
      EXPECT_NEAR(st.dt_s, 0.02, 1e-12);
    }
    const double tick_m = 2.0 * kPi * s.encoder.wheel_radius_m / s.encoder.ticks_per_revolution;
    EXPECT_NEAR(distance, 2.0, tick_m) << "sign " << sign;
  }
}

// ---------------------------------------------------------------------------
// Pixy

TEST(HardwareEmulator, NoiselessBlocksGiveTheTrueRangeAndBearing) {
  Rig s = noiseless(paper_setup());
  HardwareEmulator emu = s.make();
  const PixyRun run = run_pixy(emu, 2.0 * emu.path().lap_time_s(), 0.05);
  pixy::PixyParserCounters pc;
  const std::vector<pixy::PixyFrame> frames = parse_frames(run.bytes, &pc);
  EXPECT_EQ(pc.checksum_errors, 0u);
  EXPECT_EQ(pc.bytes_skipped, 0u);
  std::vector<const PixyFrameRecord*> sent;
  for (const PixyFrameRecord& f : run.frames) {
    if (f.sent) sent.push_back(&f);
  }
  ASSERT_EQ(frames.size(), sent.size());
  ASSERT_GT(frames.size(), 100u);

  const pixy::CameraModel& cam = s.camera;
  const double height_px_m = cam.focal_length_mm * cam.landmark_height_m / cam.sensor_height_mm * cam.image_height_px;
  const double half_px_rad = 0.5 * cam.sensor_width_mm / (cam.focal_length_mm * cam.image_width_px);
  pixy::DetectionCounters dc;
  std::size_t checked = 0, clipped = 0, blocks = 0;
  std::map<int, std::pair<int, int>> by_range;  // 0.5 m bin -> (blocks, detections)
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(frames[i].blocks.size(), sent[i]->sightings.size());
    std::map<int, const PoleSighting*> sighting_of;
    for (std::size_t k = 0; k < frames[i].blocks.size(); ++k) {
      EXPECT_EQ(frames[i].blocks[k], sent[i]->sightings[k].block);
      sighting_of[sent[i]->sightings[k].landmark_id] = &sent[i]->sightings[k];
      ++by_range[static_cast<int>(sent[i]->sightings[k].true_range_m / 0.5)].first;
      ++blocks;
    }
    for (const pixy::Detection& d : pixy::to_detections(frames[i], s.signatures, cam, dc)) {
      // The id decoded from the signature is the pole's.
      ASSERT_EQ(sighting_of.count(d.landmark_id), 1u) << "frame " << i << " id " << d.landmark_id;
      const PoleSighting& p = *sighting_of.at(d.landmark_id);
      ++by_range[static_cast<int>(p.true_range_m / 0.5)].second;
      EXPECT_EQ(p.noisy_range_m, p.true_range_m);
      if (p.clipped) {
        ++clipped;
        continue;
      }
      // Half a pixel of height or column, at most.
      const double h = height_px_m / p.true_range_m;
      EXPECT_NEAR(d.range_m, p.true_range_m, height_px_m / (h - 0.5) - p.true_range_m + 1e-12);
      EXPECT_NEAR(d.bearing_rad, p.true_bearing_rad, half_px_rad + 1e-12);
      ++checked;
    }
  }
  std::cout << "[ info ] " << blocks << " blocks sent, " << dc.detections << " accepted by the bridge ("
            << dc.bad_aspect << " bad aspect, " << clipped << " accepted although clipped); by true range:";
  for (const auto& [bin, n] : by_range) {
    std::cout << " " << bin * 0.5 << "-" << (bin + 1) * 0.5 << " m " << n.second << "/" << n.first;
  }
  std::cout << "\n";
  EXPECT_GT(checked, 300u);
  EXPECT_EQ(dc.unknown_signature, 0u);
  EXPECT_EQ(dc.outside_image, 0u);
  EXPECT_EQ(dc.duplicate_landmark, 0u);
  EXPECT_EQ(dc.detections + dc.bad_aspect, blocks);
  EXPECT_EQ(emu.counters().blocks_sent, blocks);
}

TEST(HardwareEmulator, OnlyPolesInTheFieldOfViewAppear) {
  // Given a far range limit, when the robot drives a lap, then no pole behind
  // the camera or wholly beside the image is ever reported, a pole without a
  // signature never is, and a block is cut exactly when the pole's image
  // crosses the image edge.
  Rig s = noiseless(paper_setup());
  s.hardware.max_range_m = 50.0;
  s.hardware.min_block_area_px = 0;
  HardwareEmulator emu = s.make();
  const PixyRun run = run_pixy(emu, emu.path().lap_time_s(), 0.1);
  const pixy::CameraModel& c = s.camera;
  const double half_fov = std::atan(0.5 * c.sensor_width_mm / c.focal_length_mm);
  EXPECT_NEAR(2.0 * half_fov * 180.0 / kPi, 69.54, 0.01);  // from S_w = 3.888 mm, f = 2.8 mm
  ASSERT_FALSE(run.frames.empty());
  // At t = 0 the robot is at the origin facing +x: the poles left of x = 0 are behind it.
  std::size_t behind_at_start = 0;
  for (const sim::Pole& p : emu.poles()) {
    if (p.x_m >= 0.0) continue;
    ++behind_at_start;
    for (const PoleSighting& sg : run.frames.front().sightings) EXPECT_NE(sg.landmark_id, p.id);
  }
  EXPECT_GT(behind_at_start, 0u);

  std::size_t sightings = 0, cut = 0;
  for (const PixyFrameRecord& f : run.frames) {
    for (const PoleSighting& sg : f.sightings) {
      ++sightings;
      EXPECT_NE(sg.landmark_id, 20);  // no signature
      const sim::Pole& p = emu.poles().at(static_cast<std::size_t>(sg.landmark_id - 1));
      ASSERT_EQ(p.id, sg.landmark_id);
      const double dx = p.x_m - f.pose.x_m, dy = p.y_m - f.pose.y_m;
      const double forward = std::cos(f.pose.theta_rad) * dx + std::sin(f.pose.theta_rad) * dy;
      EXPECT_GT(forward, 0.0);
      // Angular half width of the pole's image, in tan units as on the sensor.
      const double tan_phi = std::abs(std::tan(sg.true_bearing_rad));
      const double half_width_tan = 0.5 * s.hardware.pole_width_m / sg.true_range_m;
      const double edge_tan = std::tan(half_fov);
      EXPECT_LT(tan_phi - half_width_tan, edge_tan + 1e-9) << "wholly outside the image";
      EXPECT_EQ(sg.clipped, tan_phi + half_width_tan > edge_tan + 1e-12) << sg.landmark_id;
      if (sg.clipped) ++cut;
    }
  }
  EXPECT_GT(sightings, 100u);
  EXPECT_GT(cut, 0u);
  EXPECT_GT(emu.counters().behind_camera, 0u);
  EXPECT_GT(emu.counters().outside_image, 0u);
  EXPECT_EQ(emu.counters().out_of_range, 0u);
}

TEST(HardwareEmulator, NoisyDetectionsHaveThePapersNoise) {
  const Rig s = paper_setup();
  HardwareEmulator emu = s.make();
  const PixyRun run = run_pixy(emu, 300.0, 0.1);
  const std::vector<pixy::PixyFrame> frames = parse_frames(run.bytes, nullptr);
  std::vector<const PixyFrameRecord*> sent;
  for (const PixyFrameRecord& f : run.frames) {
    if (f.sent) sent.push_back(&f);
  }
  ASSERT_EQ(frames.size(), sent.size());
  pixy::DetectionCounters dc;
  std::vector<double> er, eb;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    for (const pixy::Detection& d : pixy::to_detections(frames[i], s.signatures, s.camera, dc)) {
      for (const PoleSighting& p : sent[i]->sightings) {
        if (p.landmark_id != d.landmark_id || p.clipped) continue;
        er.push_back(d.range_m - p.true_range_m);
        eb.push_back(d.bearing_rad - p.true_bearing_rad);
      }
    }
  }
  ASSERT_GT(er.size(), 500u);
  const Stats sr = stats(er);
  const Stats sb = stats(eb);
  std::cout << "[ info ] " << er.size() << " detections: range error mean " << sr.mean << " sd " << sr.sd
            << " m (paper 0.07 + pixel quantisation), bearing error mean " << sb.mean << " sd " << sb.sd
            << " rad (paper 0.027); " << dc.bad_aspect << " of " << dc.blocks << " blocks fail the aspect check\n";
  EXPECT_NEAR(sb.mean, 0.0, 0.003);
  EXPECT_NEAR(sb.sd, 0.027, 0.003);
  EXPECT_NEAR(sr.mean, 0.0, 0.02);
  EXPECT_GT(sr.sd, 0.065);
  EXPECT_LT(sr.sd, 0.12);
}

TEST(HardwareEmulator, ColourCodesAndNormalBlocks) {
  const Rig s = noiseless(paper_setup());
  HardwareEmulator emu = s.make();
  const PixyRun run = run_pixy(emu, 60.0, 0.5);
  bool normal = false, code = false;
  for (const PixyFrameRecord& f : run.frames) {
    for (std::size_t k = 0; k < f.sightings.size(); ++k) {
      const pixy::PixyBlock& b = f.sightings[k].block;
      EXPECT_EQ(b.signature, *emu.signature_of(f.sightings[k].landmark_id));
      EXPECT_EQ(b.colour_code, f.sightings[k].landmark_id >= 6);
      EXPECT_EQ(b.angle_deg, b.colour_code ? 90 : 0);
      EXPECT_EQ(b.y, 100);
      if (k > 0) {
        const pixy::PixyBlock& a = f.sightings[k - 1].block;
        EXPECT_GE(a.width * a.height, b.width * b.height);  // largest first
      }
      (b.colour_code ? code : normal) = true;
    }
  }
  EXPECT_TRUE(normal);
  EXPECT_TRUE(code);
  EXPECT_FALSE(emu.signature_of(20).has_value());
  EXPECT_EQ(emu.landmarks().size(), 20u);
}

TEST(HardwareEmulator, EmptyFramesOnlyWhenAsked) {
  Rig s = paper_setup();
  s.world.poles_per_long_side = s.world.poles_per_short_side = 0;  // nothing to see
  HardwareEmulator quiet = s.make();
  EXPECT_TRUE(quiet.advance_to(2.0).pixy_bytes.empty());
  EXPECT_EQ(quiet.counters().pixy_frames, 21u);
  s.hardware.send_empty_frames = true;
  HardwareEmulator chatty = s.make();
  const HardwareOutput out = chatty.advance_to(2.0);
  EXPECT_EQ(out.pixy_bytes.size(), 2u * 21u);  // a lone frame-start sync per frame
  // The last sync waits for the word after it before it counts as a frame start.
  EXPECT_EQ(parse_frames(out.pixy_bytes, nullptr).size(), 20u);
}

// ---------------------------------------------------------------------------
// Determinism

TEST(HardwareEmulator, SameSeedSameBytesWhateverTheCallTimes) {
  const Rig s = paper_setup();
  HardwareEmulator a = s.make();
  HardwareEmulator b = s.make();
  std::string arduino_a, arduino_b;
  std::vector<std::uint8_t> pixy_a, pixy_b;
  for (int k = 0; k <= 1500; ++k) {
    const HardwareOutput o = a.advance_to(k * 0.02);
    arduino_a += o.arduino_bytes;
    pixy_a.insert(pixy_a.end(), o.pixy_bytes.begin(), o.pixy_bytes.end());
  }
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> step(0.0, 0.35);
  for (double t = 0.0;; t += step(prng)) {
    const HardwareOutput o = b.advance_to(std::min(t, 30.0));
    arduino_b += o.arduino_bytes;
    pixy_b.insert(pixy_b.end(), o.pixy_bytes.begin(), o.pixy_bytes.end());
    if (t >= 30.0) break;
  }
  EXPECT_EQ(arduino_a, arduino_b);
  EXPECT_EQ(pixy_a, pixy_b);
  EXPECT_FALSE(pixy_a.empty());
  EXPECT_EQ(a.pose(), b.pose());

  // Another seed changes both streams; camera settings leave the wheels alone.
  Rig other = s;
  other.hardware.seed = 2;
  HardwareEmulator c = other.make();
  const HardwareOutput oc = c.advance_to(30.0);
  EXPECT_NE(oc.arduino_bytes, arduino_a);
  EXPECT_NE(oc.pixy_bytes, pixy_a);
  Rig camera_only = s;
  camera_only.hardware.bearing_sigma_rad = 0.05;
  camera_only.hardware.pixy_rate_hz = 25.0;
  HardwareEmulator d = camera_only.make();
  EXPECT_EQ(d.advance_to(30.0).arduino_bytes, arduino_a);
}

// ---------------------------------------------------------------------------
// Options

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return "";
}

HardwareOptions read_text(const std::string& yaml) {
  config::YamlReader root = config::YamlReader::from_string(yaml, "test.yaml");
  config::YamlReader hw = root.child("hardware");
  return read_hardware_options(hw);
}

TEST(HardwareOptions, YamlErrorsNameTheKey) {
  EXPECT_NE(error_of([] { read_text("hardware:\n  arduino_rate: 50\n"); }).find("hardware.arduino_rate"),
            std::string::npos);
  const std::string range = error_of([] { read_text("hardware:\n  pixy_rate_hz: 0\n"); });
  EXPECT_NE(range.find("hardware.pixy_rate_hz"), std::string::npos) << range;
  EXPECT_NE(error_of([] { read_text("hardware:\n  min_range_m: 3\n  max_range_m: 2\n"); }).find("max_range_m"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_text("hardware:\n  firmware_version: \"a b\"\n"); }).find("firmware_version"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_text("hardware:\n  start_ticks: 2147483648\n"); }).find("start_ticks"),
            std::string::npos);
  const HardwareOptions o = read_text("hardware:\n  arduino_start_time_us: 4294967295\n  start_ticks: -2147483648\n");
  EXPECT_EQ(o.arduino_start_time_us, 4294967295u);
  EXPECT_EQ(o.start_ticks, std::numeric_limits<std::int32_t>::min());

  HardwareOptions bad;
  bad.arduino_rate_hz = 0.0;
  const std::string what = error_of([&] { validate(bad); });
  EXPECT_NE(what.find("arduino_rate_hz"), std::string::npos) << what;
  bad = HardwareOptions{};
  bad.pole_width_m = -1.0;
  EXPECT_NE(error_of([&] { validate(bad); }).find("pole_width_m"), std::string::npos);
  Rig s = paper_setup();
  s.hardware.physics_step_s = 0.0;
  EXPECT_NE(error_of([&] { s.make(); }).find("physics_step_s"), std::string::npos);
  EXPECT_THROW(paper_setup().make().advance_to(std::nan("")), std::invalid_argument);
}

TEST(HardwareOptions, ToYamlRoundTrips) {
  HardwareOptions o;
  o.seed = 99;
  o.arduino_start_time_us = 4000000000u;
  o.start_ticks = -5;
  o.pole_width_m = 0.038;
  o.send_empty_frames = true;
  EXPECT_EQ(to_yaml(read_text(to_yaml(o))), to_yaml(o));
}

TEST(RobotSimConfig, ShippedFilesLoadAndShareOneTruth) {
  const std::string dir = PIXYSLAM_CONFIG_DIR;
  const RobotSimConfig c =
      load_robot_sim_config(dir + "/robot_sim.yaml", dir + "/pixy_bridge.yaml", dir + "/encoder_bridge.yaml");
  // robot_sim.yaml lists the defaults, but for poles that image at 2.1:1 (80 x 42 mm).
  HardwareOptions expected;
  expected.pole_width_m = 0.042;
  EXPECT_EQ(to_yaml(c.hardware), to_yaml(expected));
  EXPECT_EQ(c.encoder.ticks_per_revolution, 1320);
  EXPECT_DOUBLE_EQ(c.pixy.camera.landmark_height_m, 0.08);
  HardwareEmulator emu = make_hardware_emulator(c);
  // Every pole of the shipped world has a colour code in pixy_bridge.yaml.
  for (const sim::Pole& p : emu.poles()) EXPECT_TRUE(emu.signature_of(p.id).has_value()) << p.id;
  const HardwareOutput out = emu.advance_to(20.0);
  EXPECT_EQ(out.encoder_samples.size(), 1001u);
  EXPECT_FALSE(out.pixy_bytes.empty());
  // A stray top-level key in the emulator's own file is an error.
  const std::string err = error_of([&] {
    load_robot_sim_config(dir + "/pixy_bridge.yaml", dir + "/pixy_bridge.yaml", dir + "/encoder_bridge.yaml");
  });
  EXPECT_NE(err.find("world"), std::string::npos) << err;
  // The emulator makes its own sensor noise (hardware:): a world key of the
  // offline simulator's sensors would do nothing here, so it is refused.
  for (const char* key : {"seed: 3", "camera_rate_hz: 30", "range_sigma_m: 0.1", "duration_s: 60"}) {
    config::YamlReader root = config::YamlReader::from_string(std::string("world:\n  ") + key + "\nhardware: {}\n",
                                                              "sim.yaml");
    const std::string e = error_of(
        [&] { read_robot_sim_config(root, dir + "/pixy_bridge.yaml", dir + "/encoder_bridge.yaml"); });
    EXPECT_NE(e.find(std::string(key).substr(0, std::string(key).find(':'))), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace pixyslam::robot_sim
