#include "pixyslam/robot_sim/robot_sim_config.h"

#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::robot_sim {

RobotSimConfig load_robot_sim_config(const std::string& sim_yaml, const std::string& pixy_yaml,
                                     const std::string& encoder_yaml) {
  config::YamlReader root = config::YamlReader::from_file(sim_yaml);
  RobotSimConfig c = read_robot_sim_config(root, pixy_yaml, encoder_yaml);
  // The simulator process's own mappings (robot_sim_node.h) are read there.
  for (const char* process_key : {"run", "dds"}) {
    if (root.has(process_key)) root.child(process_key);
  }
  root.finish();
  return c;
}

RobotSimConfig read_robot_sim_config(config::YamlReader& sim_root, const std::string& pixy_yaml,
                                     const std::string& encoder_yaml) {
  RobotSimConfig c;
  {
    config::YamlReader world = sim_root.child("world");
    c.world = sim::read_world_options(world, sim::world_layout_parameters());
    config::YamlReader hardware = sim_root.child("hardware");
    c.hardware = read_hardware_options(hardware);
  }
  {
    config::YamlReader root = config::YamlReader::from_file(pixy_yaml);
    config::YamlReader pixy = root.child("pixy");
    c.pixy = pixy::read_pixy_options(pixy);
  }
  {
    config::YamlReader root = config::YamlReader::from_file(encoder_yaml);
    config::YamlReader bridge = root.child("encoder_bridge");
    c.encoder = encoder::read_encoder_options(bridge);
  }
  return c;
}

HardwareEmulator make_hardware_emulator(const RobotSimConfig& c) {
  return HardwareEmulator(c.world, c.encoder, c.pixy.camera, c.pixy.signatures, c.hardware);
}

}  // namespace pixyslam::robot_sim
