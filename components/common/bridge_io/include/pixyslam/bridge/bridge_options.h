#pragma once

#include <string>

#include "pixyslam/app/command_line.h"
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

// The bridges' command-line overrides of what args.get("config") set:
// --device PATH replaces `serial_device` (std::invalid_argument unless it is an
// absolute path), --dds-config FILE replaces dds.profiles_file; the DDS
// settings resolved (dds::resolve_settings: the environment). The profiles
// file must be readable: config::ConfigError naming --dds-config or the config
// file's key dds.profiles_file otherwise.
void apply_command_line(const app::CommandLine& args, std::string& serial_device, dds::DdsOptions& dds);

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

// reopen_period_s and status_period_s as lines of a `node:` mapping (two-space indent).
std::string to_yaml_lines(const BridgeProcessOptions& options);

}  // namespace pixyslam::bridge
