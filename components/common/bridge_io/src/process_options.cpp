#include "pixyslam/bridge/process_options.h"

namespace pixyslam::bridge {

BridgeProcessOptions read_bridge_process_options(config::YamlReader& node) {
  BridgeProcessOptions o;
  o.reopen_period_s = node.number("reopen_period_s", 0.01, 3600.0, o.reopen_period_s);
  o.status_period_s = node.number("status_period_s", 0.0, 86400.0, o.status_period_s);
  return o;
}

std::string to_yaml_lines(const BridgeProcessOptions& o) {
  return "  reopen_period_s: " + yaml_number(o.reopen_period_s) + "\n" +
         "  status_period_s: " + yaml_number(o.status_period_s) + "\n";
}

}  // namespace pixyslam::bridge
