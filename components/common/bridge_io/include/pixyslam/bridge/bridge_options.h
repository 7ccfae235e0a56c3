#pragma once

#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/bridge/process_options.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::bridge {

DeviceReaderOptions device_reader_options(const BridgeProcessOptions& options);

// The rule serial_link_parameters() leaves out: `section.baud` is a rate the
// platform supports (parameters::RuleError listing them otherwise).
void validate_serial_link(const BridgeProcessOptions& options, const std::string& section);

// The flags both bridges share: --config FILE, --device PATH, --set KEY=VALUE
// (the component's section or dds.), --verbose.
struct BridgeCommandLine {
  std::string config;
  std::string device;
  std::vector<std::string> overrides;
  std::vector<std::string> domain;  // --domain N: "dds.domain_id=N", after --set
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

}  // namespace pixyslam::bridge
