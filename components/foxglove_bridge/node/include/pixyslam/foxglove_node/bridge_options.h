#pragma once

#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/dds_options.h"
#include "pixyslam/foxglove/visualiser.h"
#include "pixyslam/foxglove_node/ws_server.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::foxglove_node {

// Everything the foxglove_bridge process is configured with (config/foxglove_bridge.yaml).
struct BridgeOptions {
  WsServerOptions server;              // `foxglove_bridge.address`, `port`, `max_clients`, ...
  std::vector<std::string> topics;     // `foxglove_bridge.topics`: DDS topic patterns (select_topics); empty = all
  bool visuals = true;                 // `foxglove_bridge.visuals`: the pixyslam/viz/* channels
  foxglove::VisualOptions visual;      // `foxglove_bridge.ellipse_sigma`, `path_max_poses`, ...
  dds::DdsOptions dds;                 // `dds:`
};

// The `foxglove_bridge:` keys but topics: range, unit, help.
const parameters::Table<BridgeOptions>& bridge_parameters();

// Reads `foxglove_bridge:` (required) and `dds:` (optional), calls root.finish().
// Throws config::ConfigError naming the file and key.
BridgeOptions read_bridge_options(config::YamlReader& root, const std::string& config_dir);
BridgeOptions read_bridge_options_file(const std::string& path);

// `--set` assignments "foxglove_bridge.KEY=V", "dds.KEY=V", validated; the DDS
// settings resolved (environment, then these). Throws std::invalid_argument.
void apply_overrides(BridgeOptions& options, const std::vector<std::string>& assignments);

// The effective configuration, in the layout read_bridge_options() reads.
std::string to_yaml(const BridgeOptions& options);

}  // namespace pixyslam::foxglove_node
