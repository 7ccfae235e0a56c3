#pragma once

#include <string>
#include <vector>

#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/encoder/encoder_options.h"

namespace pixyslam::encoder_node {

// Everything the encoder_bridge process is configured with
// (config/encoder_bridge.yaml).
struct EncoderNodeOptions {
  encoder::EncoderOptions encoder;  // `encoder_bridge:` (wheels, rate)
  // `node:` the serial link (the Arduino's USB serial device), reopen_period_s, status_period_s, ...
  bridge::BridgeProcessOptions process{"/dev/ttyACM0", 115200};
  double clock_window_s = 1.0;           // `node.clock_window_s`: Arduino clock mapping window (ArduinoClock)
  dds::DdsOptions dds;                   // `dds:`
};

// Reads `encoder_bridge:` (required), `node:` and `dds:` (optional) from the top
// level of a file and calls root.finish(). `config_dir` resolves a relative
// dds.profiles_file. Throws config::ConfigError naming the file and key path.
EncoderNodeOptions read_encoder_node_options(config::YamlReader& root, const std::string& config_dir);
EncoderNodeOptions read_encoder_node_options_file(const std::string& path);

// The `node:` keys (serial_device, baud, reopen_period_s, status_period_s, clock_window_s).
const parameters::Table<EncoderNodeOptions>& node_parameters();
void validate_node(const EncoderNodeOptions& options);

// `--set encoder_bridge.KEY=V` and `node.KEY=V` applied and checked, taken out
// of `assignments` (the dds. ones stay for dds::resolve_settings).
void apply_overrides(EncoderNodeOptions& options, std::vector<std::string>& assignments);

// Every parameter --set reaches, for --help.
std::string help_text();

// The effective configuration, in the layout read_encoder_node_options() reads.
std::string to_yaml(const EncoderNodeOptions& options);

}  // namespace pixyslam::encoder_node
