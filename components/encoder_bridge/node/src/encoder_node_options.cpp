#include "pixyslam/encoder_node/encoder_node_options.h"

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::encoder_node {

const parameters::Table<EncoderNodeOptions>& node_parameters() {
  using O = EncoderNodeOptions;
  static const parameters::Table<O> table = [] {
    const auto process = [](O& o) -> bridge::BridgeProcessOptions& { return o.process; };
    parameters::Table<O> t = bridge::serial_link_parameters<O>(process, "the Arduino's serial device");
    for (parameters::Parameter<O>& p : bridge::process_parameters<O>(process)) t.push_back(std::move(p));
    t.push_back(parameters::real<O>("clock_window_s", 0.05, 60.0, "s", "window of the Arduino clock mapping (ArduinoClock)",
                                    [](O& o) -> double& { return o.clock_window_s; }));
    return t;
  }();
  return table;
}

void validate_node(const EncoderNodeOptions& o) {
  parameters::check_ranges(o, node_parameters(), "node");
  bridge::validate_serial_link(o.process, "node");
}

void apply_overrides(EncoderNodeOptions& o, std::vector<std::string>& assignments) {
  for (const std::string& a : parameters::take_section(assignments, "encoder_bridge")) {
    parameters::apply_override(o.encoder, encoder::encoder_parameters(), "encoder_bridge", a);
  }
  encoder::validate(o.encoder);
  for (const std::string& a : parameters::take_section(assignments, "node")) {
    parameters::apply_override(o, node_parameters(), "node", a);
  }
  validate_node(o);
}

std::string help_text() {
  return "encoder parameters (encoder_bridge:):\n" + parameters::help_text(encoder::encoder_parameters(), "encoder_bridge") +
         "the process (node:):\n" + parameters::help_text(node_parameters(), "node") +
         "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

EncoderNodeOptions read_encoder_node_options(config::YamlReader& root, const std::string& config_dir) {
  EncoderNodeOptions o;
  config::YamlReader bridge = root.child("encoder_bridge");
  for (const char* moved : {"serial_device", "baud"}) {
    if (bridge.has(moved)) bridge.fail(moved, std::string("moved to node.") + moved + " (as in pixy_bridge.yaml)");
  }
  o.encoder = encoder::read_encoder_options(bridge);
  if (root.has("node")) {
    config::YamlReader node = root.child("node");
    config::read_parameters(node, node_parameters(), o);
    node.finish();
    config::check_rules(node, [&] { validate_node(o); });
  }
  o.dds = dds::read_dds_section(root, config_dir);
  root.finish();
  return o;
}

EncoderNodeOptions read_encoder_node_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_encoder_node_options(root, config::folder_of(path));
}

std::string to_yaml(const EncoderNodeOptions& o) {
  return encoder::to_yaml(o.encoder) + parameters::to_yaml(o, node_parameters(), "node") + dds::to_yaml(o.dds);
}

}  // namespace pixyslam::encoder_node
