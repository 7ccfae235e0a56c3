#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pixyslam/dds/participant.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/robot_sim/robot_sim_config.h"

namespace pixyslam::robot_sim {

// How the simulator process runs (`run:` of config/robot_sim.yaml).
struct RunOptions {
  double duration_s = 90.0;          // hardware time simulated; 0 = until stopped
  double power_on_delay_s = 2.0;     // pseudo-terminals up, hardware silent (bridges open them)
  std::string arduino_link = "/tmp/pixyslam/arduino";  // symlinks to the pty slaves
  std::string pixy_link = "/tmp/pixyslam/pixy";
  double ground_truth_rate_hz = 10.0;
  double tick_s = 0.002;             // wall-clock step of the emulation loop
  double rate = 1.0;                 // hardware seconds per wall second (was speed_factor)
  // A fault for tests: both serial devices vanish at unplug_at_s (the ptys and
  // their links go, as a USB cable pulled out) and come back unplug_for_s later
  // at the same links while the robot drives on; bytes meanwhile are lost.
  double unplug_at_s = 0.0;          // 0: never
  double unplug_for_s = 3.0;
  // The synthetic camera (a build with the camera backend): every Pixy frame
  // period is also rendered as an image of the poles (render_camera_image) and
  // written as a YUV4MPEG2 stream into a FIFO at this path, for the pixy
  // bridge's camera backend. Empty: off.
  std::string camera_video;
};

// The keys of `run:` (ranges, units, help); validate() adds the rules between
// them (two different links; the camera video only with the camera backend).
const parameters::Table<RunOptions>& run_parameters();
void validate(const RunOptions& options);

struct RobotSimProcessConfig {
  RobotSimConfig sim;
  RunOptions run;
  dds::DdsOptions dds;
};

// Reads `world:`, `hardware:`, `run:` and `dds:` of the simulator's file and the
// camera / wheel settings of the bridges' files. Throws config::ConfigError.
RobotSimProcessConfig read_robot_sim_process_config(const std::string& sim_yaml,
                                                    const std::string& pixy_yaml,
                                                    const std::string& encoder_yaml);

// `--set world.KEY=V`, `hardware.KEY=V`, `run.KEY=V`, `dds.KEY=V` (then the
// DDS settings resolved); std::invalid_argument naming a bad one.
void apply_overrides(RobotSimProcessConfig& config, const std::vector<std::string>& assignments);

// Every parameter --set reaches, for --help.
std::string help_text();
// The simulator's own settings as YAML (world layout, hardware, run, dds), for --verbose.
std::string to_yaml(const RobotSimProcessConfig& c);

// The simulator process: runs the HardwareEmulator in real time, writes the
// Arduino's lines and the Pixy's UART bytes into two pseudo-terminals (the
// bridges open their symlinks as serial devices) and publishes GroundTruth
// (true pose, true landmarks) stamped on the host clock. run() returns when
// the duration is over or a stop is requested (StopSignal).
class RobotSimNode {
 public:
  explicit RobotSimNode(const RobotSimProcessConfig& config);
  ~RobotSimNode();
  // Returns the hardware time reached.
  double run();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pixyslam::robot_sim
