#include "pixyslam/robot_sim/robot_sim_node.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/serial/pseudo_terminal.h"
#ifdef PIXYSLAM_HAS_CAMERA
#include <csignal>

#include "pixyslam/robot_sim/camera_video_fifo.h"
#include "pixyslam/sim/synthetic_camera.h"
#endif

namespace pixyslam::robot_sim {

const parameters::Table<RunOptions>& run_parameters() {
  using O = RunOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("duration_s", 0.0, 1e6, "s", "hardware time simulated (0: until stopped)",
                 [](O& o) -> double& { return o.duration_s; }),
      P::real<O>("power_on_delay_s", 0.0, 60.0, "s", "pseudo-terminals up, hardware silent (the bridges open them)",
                 [](O& o) -> double& { return o.power_on_delay_s; }),
      P::text<O>("arduino_link", "symlink to the Arduino's pseudo-terminal", [](O& o) -> std::string& { return o.arduino_link; }),
      P::text<O>("pixy_link", "symlink to the Pixy's pseudo-terminal", [](O& o) -> std::string& { return o.pixy_link; }),
      P::real<O>("ground_truth_rate_hz", 0.1, 1000.0, "Hz", "GroundTruth messages per second",
                 [](O& o) -> double& { return o.ground_truth_rate_hz; }),
      P::real<O>("tick_s", 0.0005, 0.1, "s", "wall-clock step of the emulation loop", [](O& o) -> double& { return o.tick_s; }),
      P::renamed(P::real<O>("rate", 0.1, 10.0, "", "hardware seconds per wall second (a speed factor, as --rate)",
                            [](O& o) -> double& { return o.rate; }),
                 "speed_factor"),
      P::real<O>("unplug_at_s", 0.0, 1e6, "s", "fault test: both serial devices vanish at this time (0: never)",
                 [](O& o) -> double& { return o.unplug_at_s; }),
      P::real<O>("unplug_for_s", 0.01, 3600.0, "s", "... and come back this much later",
                 [](O& o) -> double& { return o.unplug_for_s; }),
      P::text<O>("camera_video", "also write the synthetic camera's frames (YUV4MPEG2) into this FIFO (empty: off)",
                 [](O& o) -> std::string& { return o.camera_video; }),
  };
  return table;
}

void validate(const RunOptions& o) {
  parameters::check_ranges(o, run_parameters(), "run");
  if (o.arduino_link.empty() || o.arduino_link == o.pixy_link) {
    throw parameters::RuleError("run", "arduino_link", "must be a path different from pixy_link");
  }
#ifndef PIXYSLAM_HAS_CAMERA
  if (!o.camera_video.empty()) {
    throw parameters::RuleError("run", "camera_video",
                                "this robot_sim was built without the camera backend (PIXYSLAM_BUILD_CAMERA)");
  }
#endif
}

RobotSimProcessConfig read_robot_sim_process_config(const std::string& sim_yaml,
                                                    const std::string& pixy_yaml,
                                                    const std::string& encoder_yaml) {
  RobotSimProcessConfig c;
  config::YamlReader root = config::YamlReader::from_file(sim_yaml);
  c.sim = read_robot_sim_config(root, pixy_yaml, encoder_yaml);
  config::YamlReader run = root.child("run");
  config::read_parameters(run, run_parameters(), c.run);
  config::check_rules(run, [&] { validate(c.run); });
  run.finish();
  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    c.dds = dds::read_dds_options(dds, config::folder_of(sim_yaml));
  }
  root.finish();
  return c;
}

void apply_overrides(RobotSimProcessConfig& c, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  for (const std::string& a : parameters::take_section(rest, "world")) {
    parameters::apply_override(c.sim.world, sim::world_layout_parameters(), "world", a);
  }
  sim::validate(c.sim.world);
  for (const std::string& a : parameters::take_section(rest, "hardware")) {
    parameters::apply_override(c.sim.hardware, hardware_parameters(), "hardware", a);
  }
  validate(c.sim.hardware);
  for (const std::string& a : parameters::take_section(rest, "run")) {
    parameters::apply_override(c.run, run_parameters(), "run", a);
  }
  validate(c.run);
  dds::resolve_settings(c.dds, rest);  // dds.KEY=V; anything else is an error there
}

std::string to_yaml(const RobotSimProcessConfig& c) {
  return parameters::to_yaml(c.sim.world, sim::world_layout_parameters(), "world") +
         parameters::to_yaml(c.sim.hardware, hardware_parameters(), "hardware") +
         parameters::to_yaml(c.run, run_parameters(), "run") + dds::to_yaml(c.dds);
}

std::string help_text() {
  return "world (world:; the path and poles, and also path:, poles:, initial_pose: lists as in slam_sim.yaml):\n" +
         parameters::help_text(sim::world_layout_parameters(), "world") +
         "hardware (hardware:):\n" + parameters::help_text(hardware_parameters(), "hardware") +
         "the process (run:):\n" + parameters::help_text(run_parameters(), "run") +
         "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

struct RobotSimNode::Impl {
  explicit Impl(const RobotSimProcessConfig& c)
      : config(c),
        emulator(make_hardware_emulator(c.sim)),
        participant(c.dds, "robot_sim"),
        truth_writer(participant) {
    for (const std::string& link : {c.run.arduino_link, c.run.pixy_link}) {
      const auto folder = std::filesystem::path(link).parent_path();
      if (!folder.empty()) std::filesystem::create_directories(folder);
    }
    plug_in();
    for (const sim::Pole& pole : emulator.poles()) {
      if (!emulator.signature_of(pole.id)) continue;  // invisible: not part of the map
      msg::TrueLandmark l;
      l.landmark_id(pole.id);
      l.x_m(pole.x_m);
      l.y_m(pole.y_m);
      landmarks.push_back(l);
    }
#ifdef PIXYSLAM_HAS_CAMERA
    if (!c.run.camera_video.empty()) {
      std::signal(SIGPIPE, SIG_IGN);  // a reader that leaves is an EPIPE, handled
      const pixy::CameraModel& model = c.sim.pixy.camera;
      camera_options.camera = model;
      camera_options.pole_width_m = c.sim.hardware.pole_width_m;
      for (const sim::Pole& pole : emulator.poles()) {
        const std::optional<std::uint16_t> sig = emulator.signature_of(pole.id);
        if (!sig || *sig < 8 || *sig >= 64) continue;  // two-tag colour codes are drawn
        camera_poles.push_back({pole.id, pole.x_m, pole.y_m, *sig / 8, *sig % 8});
      }
      video = std::make_unique<CameraVideoFifo>(c.run.camera_video, model.image_width_px, model.image_height_px,
                                                static_cast<int>(std::lround(c.sim.hardware.pixy_rate_hz)));
    }
#endif
  }

#ifdef PIXYSLAM_HAS_CAMERA
  void render_frames(const HardwareOutput& out) {
    if (!video) return;
    for (const PixyFrameRecord& f : out.frames) {
      const cv::Mat image = sim::render_camera_image(slam::Pose2(f.pose.x_m, f.pose.y_m, f.pose.theta_rad),
                                                        camera_poles, camera_options, detector, camera_rng);
      video->write_frame(image);
    }
  }
  sim::SyntheticCameraOptions camera_options;
  camera::DetectorOptions detector = camera::default_detector_options();
  std::vector<sim::SyntheticPole> camera_poles;
  std::mt19937_64 camera_rng{7};
  std::unique_ptr<CameraVideoFifo> video;
#endif

  void plug_in() {
    arduino = std::make_unique<serial::PseudoTerminal>(config.run.arduino_link);
    pixy = std::make_unique<serial::PseudoTerminal>(config.run.pixy_link);
  }

  // Bytes to a device, or lost while it is unplugged.
  template <class Bytes>
  void write(std::unique_ptr<serial::PseudoTerminal>& device, const Bytes& bytes) {
    if (bytes.empty()) return;
    if (device) {
      device->write_all(bytes);
    } else {
      unplugged_bytes += bytes.size();
    }
  }

  void publish_truth(const eval::TimedPose& pose) {
    msg::GroundTruth m;
    m.header().stamp_ns(power_on_ns + static_cast<std::uint64_t>(std::llround(pose.t_s * 1e9)));
    m.header().frame_id("map");
    m.pose().x_m(pose.x_m);
    m.pose().y_m(pose.y_m);
    m.pose().theta_rad(pose.theta_rad);
    const sim::PathCommand command = emulator.path().command_at(pose.t_s);
    m.v_mps(command.v_mps);
    m.w_radps(command.w_radps);
    m.landmarks(landmarks);
    truth_writer.publish(m);
  }

  RobotSimProcessConfig config;
  HardwareEmulator emulator;
  dds::Participant participant;
  dds::Writer<msg::GroundTruth> truth_writer;
  std::unique_ptr<serial::PseudoTerminal> arduino;
  std::unique_ptr<serial::PseudoTerminal> pixy;
  std::vector<msg::TrueLandmark> landmarks;
  std::uint64_t power_on_ns = 0;
  std::uint64_t unplugged_bytes = 0;
  std::uint64_t dropped_bytes = 0;  // by the ptys' drop policy, over every pty the run had
};

RobotSimNode::RobotSimNode(const RobotSimProcessConfig& config) : impl_(std::make_unique<Impl>(config)) {}

RobotSimNode::~RobotSimNode() = default;

double RobotSimNode::run() {
  Impl& s = *impl_;
  const RunOptions& run = s.config.run;
  std::fprintf(stderr, "robot_sim: Arduino on %s (%s), Pixy on %s (%s); %zu visible poles; power on in %.1f s\n",
               s.arduino->device_path().c_str(), s.arduino->slave_path().c_str(),
               s.pixy->device_path().c_str(), s.pixy->slave_path().c_str(), s.landmarks.size(),
               run.power_on_delay_s);
  if (app::StopSignal::wait_for(std::chrono::milliseconds(static_cast<long>(run.power_on_delay_s * 1000)))) {
    return 0.0;
  }
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  s.power_on_ns = dds::now_ns();
  const double truth_period = 1.0 / run.ground_truth_rate_hz;
  double next_truth_s = 0.0;
  double t = 0.0;
  double next_status_s = 10.0;
  const auto tick = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(run.tick_s));
  auto wake = start;
  while (!app::StopSignal::requested()) {
    t = std::chrono::duration<double>(Clock::now() - start).count() * run.rate;
    if (run.duration_s > 0.0 && t > run.duration_s) t = run.duration_s;
    const HardwareOutput out = s.emulator.advance_to(t);
    if (run.unplug_at_s > 0.0 && s.arduino && t >= run.unplug_at_s && t < run.unplug_at_s + run.unplug_for_s) {
      s.dropped_bytes += s.arduino->counters().dropped_bytes + s.pixy->counters().dropped_bytes;
      s.arduino.reset();
      s.pixy.reset();
      std::fprintf(stderr, "robot_sim: t %.1f s: serial devices unplugged for %.1f s\n", t, run.unplug_for_s);
    } else if (!s.arduino && t >= run.unplug_at_s + run.unplug_for_s) {
      s.plug_in();
      std::fprintf(stderr, "robot_sim: t %.1f s: serial devices plugged back in (%s, %s); %llu bytes lost\n", t,
                   s.arduino->slave_path().c_str(), s.pixy->slave_path().c_str(),
                   static_cast<unsigned long long>(s.unplugged_bytes));
    }
    s.write(s.arduino, out.arduino_bytes);
    s.write(s.pixy, out.pixy_bytes);
#ifdef PIXYSLAM_HAS_CAMERA
    s.render_frames(out);
#endif
    for (const eval::TimedPose& pose : out.truth) {
      if (pose.t_s + 1e-9 < next_truth_s) continue;
      s.publish_truth(pose);
      next_truth_s += truth_period;
    }
    if (t >= next_status_s) {
      const HardwareCounters& c = s.emulator.counters();
      std::fprintf(stderr, "robot_sim: t %.0f s, %llu Arduino lines, %llu Pixy frames sent, %llu blocks\n", t,
                   static_cast<unsigned long long>(c.arduino_lines),
                   static_cast<unsigned long long>(c.pixy_frames_sent),
                   static_cast<unsigned long long>(c.blocks_sent));
      next_status_s += 10.0;
    }
    if (run.duration_s > 0.0 && t >= run.duration_s) break;
    wake += tick;
    std::this_thread::sleep_until(wake);
  }
  // Give readers a moment to take the last ground truth.
  s.truth_writer.wait_for_acknowledgments(std::chrono::milliseconds(500));
  const HardwareCounters& c = s.emulator.counters();
  std::fprintf(stderr,
               "robot_sim: done at t %.1f s: %llu Arduino lines, %llu Pixy frames (%llu sent), %llu blocks "
               "(%llu clipped); poles behind %llu, out of range %llu, outside image %llu, too small %llu; "
               "%llu ground truth messages; serial bytes dropped %llu, lost while unplugged %llu\n",
               t, static_cast<unsigned long long>(c.arduino_lines), static_cast<unsigned long long>(c.pixy_frames),
               static_cast<unsigned long long>(c.pixy_frames_sent), static_cast<unsigned long long>(c.blocks_sent),
               static_cast<unsigned long long>(c.blocks_clipped), static_cast<unsigned long long>(c.behind_camera),
               static_cast<unsigned long long>(c.out_of_range), static_cast<unsigned long long>(c.outside_image),
               static_cast<unsigned long long>(c.too_small),
               static_cast<unsigned long long>(s.truth_writer.published()),
               static_cast<unsigned long long>(s.dropped_bytes +
                                               (s.arduino ? s.arduino->counters().dropped_bytes : 0) +
                                               (s.pixy ? s.pixy->counters().dropped_bytes : 0)),
               static_cast<unsigned long long>(s.unplugged_bytes));
#ifdef PIXYSLAM_HAS_CAMERA
  if (s.video) {
    const CameraVideoFifo::Counters& v = s.video->counters();
    std::fprintf(stderr, "robot_sim: camera video %s: %llu frames written, dropped %llu (no reader), %llu (pipe full)\n",
                 s.video->path().c_str(), static_cast<unsigned long long>(v.frames_written),
                 static_cast<unsigned long long>(v.dropped_no_reader), static_cast<unsigned long long>(v.dropped_pipe_full));
  }
#endif
  return t;
}

}  // namespace pixyslam::robot_sim
