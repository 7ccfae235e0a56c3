#pragma once

#include <string>

#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::bridge {

// Process settings every bridge has, in its config file's `node:` mapping.
struct BridgeProcessOptions {
  double reopen_period_s = 1.0;   // between attempts to open a missing or hung-up device
  double status_period_s = 10.0;  // counters to the log this often (0: only at exit)
};

// Reads reopen_period_s [0.01, 3600] and status_period_s [0, 86400] (both
// optional) from `node`; does not call finish() (the caller reads its own keys
// of the same mapping first).
BridgeProcessOptions read_bridge_process_options(config::YamlReader& node);

DeviceReaderOptions device_reader_options(const BridgeProcessOptions& options);

// The flags both bridges share: --config FILE, --device PATH, --set KEY=VALUE
// (the component's section or dds.), --verbose.
struct BridgeCommandLine {
  std::string config;
  std::string device;
  std::vector<std::string> overrides;
  bool verbose = false;
};
void add_bridge_flags(app::Cli& cli, BridgeCommandLine& args, const std::string& config_help,
                      const std::string& set_example);

// The bridges' command-line overrides of what the config file set: --device
// PATH replaces `serial_device` (std::invalid_argument unless it is an
// absolute path); the DDS settings resolved (dds::resolve_settings: the
// environment, then the `dds.` overrides; any other left is an error). The
// profiles file must be readable: config::ConfigError naming it otherwise.
void apply_command_line(const BridgeCommandLine& args, std::string& serial_device, dds::DdsOptions& dds);

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

// reopen_period_s and status_period_s as lines of a `node:` mapping (two-space indent).
std::string to_yaml_lines(const BridgeProcessOptions& options);

}  // namespace pixyslam::bridge
