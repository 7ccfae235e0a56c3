#include "pixyslam/bridge/bridge_options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace pixyslam::bridge {

BridgeProcessOptions read_bridge_process_options(config::YamlReader& node) {
  BridgeProcessOptions o;
  o.reopen_period_s = node.number("reopen_period_s", 0.01, 3600.0, o.reopen_period_s);
  o.status_period_s = node.number("status_period_s", 0.0, 86400.0, o.status_period_s);
  return o;
}

DeviceReaderOptions device_reader_options(const BridgeProcessOptions& o) {
  DeviceReaderOptions d;
  d.reopen_period = std::chrono::milliseconds(std::llround(o.reopen_period_s * 1000.0));
  return d;
}

void apply_command_line(const app::CommandLine& args, std::string& serial_device, dds::DdsOptions& dds) {
  if (args.has("device")) {
    serial_device = args.get("device");
    if (serial_device.empty() || serial_device.front() != '/') {
      throw std::invalid_argument("--device '" + serial_device + "' is not an absolute path");
    }
  }
  // The DDS settings resolved here, once: file, environment, command line.
  dds::resolve_settings(dds, args.has("dds-config") ? std::vector<std::string>{"dds.profiles_file=" + args.get("dds-config")}
                                                    : std::vector<std::string>{});
  const std::string& profiles = dds.profiles_file;
  if (profiles.empty()) return;
  const std::string where =
      args.has("dds-config") ? std::string("--dds-config") : args.get("config") + ": key 'dds.profiles_file'";
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(profiles, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
    throw config::ConfigError(where + ": " + profiles + ": not a regular file" +
                              (std::filesystem::is_directory(st) ? " (a directory)" : ""));
  }
  if (!std::ifstream(profiles).good()) throw config::ConfigError(where + ": cannot read '" + profiles + "'");
}

std::string to_yaml_lines(const BridgeProcessOptions& o) {
  return "  reopen_period_s: " + yaml_number(o.reopen_period_s) + "\n" +
         "  status_period_s: " + yaml_number(o.status_period_s) + "\n";
}

}  // namespace pixyslam::bridge
