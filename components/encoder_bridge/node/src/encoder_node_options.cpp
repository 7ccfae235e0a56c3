#include "pixyslam/encoder_node/encoder_node_options.h"

#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::encoder_node {

EncoderNodeOptions read_encoder_node_options(config::YamlReader& root, const std::string& config_dir) {
  EncoderNodeOptions o;
  config::YamlReader bridge = root.child("encoder_bridge");
  o.encoder = encoder::read_encoder_options(bridge);
  if (root.has("node")) {
    config::YamlReader node = root.child("node");
    o.process = bridge::read_bridge_process_options(node);
    o.clock_window_s = node.number("clock_window_s", 0.05, 60.0, o.clock_window_s);
    node.finish();
  }
  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, config_dir);
  }
  root.finish();
  return o;
}

EncoderNodeOptions read_encoder_node_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_encoder_node_options(root, config::folder_of(path));
}

std::string to_yaml(const EncoderNodeOptions& o) {
  return encoder::to_yaml(o.encoder) + "node:\n" + bridge::to_yaml_lines(o.process) +
         "  clock_window_s: " + bridge::yaml_number(o.clock_window_s) + "\n" + dds::to_yaml(o.dds);
}

}  // namespace pixyslam::encoder_node
