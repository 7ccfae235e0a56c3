#pragma once

#include <string>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"

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

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

// reopen_period_s and status_period_s as lines of a `node:` mapping (two-space indent).
std::string to_yaml_lines(const BridgeProcessOptions& options);

}  // namespace pixyslam::bridge
