#pragma once

#include <string>

#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/pixy/pixy_options.h"
#include "pixyslam/robot_sim/hardware_emulator.h"
#include "pixyslam/robot_sim/hardware_options.h"
#include "pixyslam/sim/sim_world.h"

namespace pixyslam::robot_sim {

// Everything the hardware emulator needs. The camera, the signatures and the
// wheel geometry come from the bridges' own files, so the emulated hardware and
// the bridges that parse it share one truth.
struct RobotSimConfig {
  sim::WorldOptions world;        // path and poles (the emulator ignores its sensor keys)
  HardwareOptions hardware;
  encoder::EncoderOptions encoder;
  pixy::PixyOptions pixy;
};

// Reads `world:` (sim::read_world_options) and `hardware:`
// (read_hardware_options) from sim_yaml, which may hold no other top-level
// key but the process's `run:` and `dds:` (not read here); the `pixy:`
// mapping of pixy_yaml (pixy::read_pixy_options) and the `encoder_bridge:` mapping of encoder_yaml (encoder::read_encoder_options).
// Other top-level keys of the two bridge files belong to the bridges and are
// not checked here. Throws config::ConfigError naming the file and key path.
RobotSimConfig load_robot_sim_config(const std::string& sim_yaml, const std::string& pixy_yaml,
                                     const std::string& encoder_yaml);
// The same with the simulator's file already open: reads `world:` and
// `hardware:` of `sim_root` and leaves its finish() to the caller (who reads
// further sections of the same file).
RobotSimConfig read_robot_sim_config(config::YamlReader& sim_root, const std::string& pixy_yaml,
                                     const std::string& encoder_yaml);

HardwareEmulator make_hardware_emulator(const RobotSimConfig& config);

}  // namespace pixyslam::robot_sim
