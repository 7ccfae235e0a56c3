#include "pixyslam/encoder_node/encoder_node_options.h"

#include <cstdio>
#include <optional>

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
    for (const std::string key : {"serial_device", "baud"}) {
      if (a.rfind("encoder_bridge." + key + "=", 0) == 0) {
        throw std::invalid_argument("'" + a + "': encoder_bridge." + key + " moved to node." + key);
      }
    }
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
  // Until 2026-11-29 the serial link was in encoder_bridge:. An installed file
  // the user edited (a conffile: wheel calibration goes there) keeps it after
  // an upgrade, so the old keys are still taken, with a warning naming the new.
  std::optional<std::string> old_device;
  std::optional<long> old_baud;
  if (bridge.has("serial_device")) old_device = bridge.text("serial_device");
  if (bridge.has("baud")) old_baud = static_cast<long>(bridge.integer("baud", 1, 4000000));
  for (const char* key : {"serial_device", "baud"}) {
    if (!bridge.has(key)) continue;
    if (root.has("node") && root.child("node").has(key)) {
      bridge.fail(key, std::string("given twice: here and as node.") + key + ", where it belongs now");
    }
    std::fprintf(stderr, "encoder_bridge: %s: key '%s' is deprecated: it moved to node.%s (as in pixy_bridge.yaml); "
                 "taken as that\n", bridge.origin().c_str(), bridge.key_path(key).c_str(), key);
  }
  o.encoder = encoder::read_encoder_options(bridge);
  if (old_device) o.process.serial_device = *old_device;
  if (old_baud) o.process.baud = *old_baud;
  if (root.has("node")) {
    config::YamlReader node = root.child("node");
    config::read_parameters(node, node_parameters(), o);
    node.finish();
    config::check_rules(node, [&] { validate_node(o); });
  } else {
    config::check_rules(bridge, [&] { validate_node(o); });  // an old encoder_bridge.baud
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
