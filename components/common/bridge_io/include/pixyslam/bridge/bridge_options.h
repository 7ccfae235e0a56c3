#pragma once

#include <string>

#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/config/yaml_reader.h"
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

// Shortest text that reads back as the same double ("0.1", "1e-05").
std::string yaml_number(double value);
// A double-quoted YAML string.
std::string yaml_quoted(const std::string& text);
// The two keys above as lines of a `node:` mapping (two-space indent).
std::string to_yaml_lines(const BridgeProcessOptions& options);
// The options as a `dds:` mapping, as read_dds_options() reads it.
std::string to_yaml(const dds::DdsOptions& options);

}  // namespace pixyslam::bridge
