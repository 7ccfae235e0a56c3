#include "pixyslam/bridge/bridge_options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "pixyslam/serial/serial_port.h"

namespace pixyslam::bridge {

DeviceReaderOptions device_reader_options(const BridgeProcessOptions& o) {
  DeviceReaderOptions d;
  d.reopen_period = std::chrono::milliseconds(std::llround(o.reopen_period_s * 1000.0));
  d.silence_warn = std::chrono::milliseconds(std::llround(o.silence_warn_s * 1000.0));
  return d;
}

void validate_serial_link(const BridgeProcessOptions& o, const std::string& section) {
  if (serial::is_supported_baud(o.baud)) return;
  std::string rates;
  for (const long b : serial::supported_bauds()) rates += (rates.empty() ? "" : ", ") + std::to_string(b);
  throw parameters::RuleError(section, "baud",
                              "value " + std::to_string(o.baud) + " is not a standard serial rate (" + rates + ")");
}

void add_bridge_flags(app::Cli& cli, BridgeCommandLine& args, const std::string& config_help,
                      const std::string& set_example) {
  app::add_config(cli, args.config, config_help);
  cli.option("--device", args.device, "the serial device (overrides node.serial_device)").type("PATH");
  app::add_set(cli, args.overrides, set_example + " or dds.participant_profile=lan_multicast");
  app::add_domain(cli, args.domain);
  app::add_verbose(cli, args.verbose);
}

void apply_command_line(const BridgeCommandLine& args, std::string& serial_device, dds::DdsOptions& dds) {
  if (!args.device.empty()) {
    serial_device = args.device;
    if (serial_device.front() != '/') {
      throw std::invalid_argument("--device '" + serial_device + "' is not an absolute path");
    }
  }
  std::vector<std::string> rest = args.overrides;
  std::vector<std::string> dds_overrides = parameters::take_section(rest, "dds");
  dds_overrides.insert(dds_overrides.end(), args.domain.begin(), args.domain.end());  // --domain wins
  if (!rest.empty()) throw std::invalid_argument("--set " + rest.front() + ": not a parameter of this process");
  // The DDS settings resolved here, once: file, environment, command line.
  dds::resolve_settings(dds, dds_overrides);
  const std::string& profiles = dds.profiles_file;
  if (profiles.empty()) return;
  const std::string where = args.config + ": dds.profiles_file (or --set / PIXYSLAM_DDS_PROFILES_FILE)";
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(profiles, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
    throw config::ConfigError(where + ": " + profiles + ": not a regular file" +
                              (std::filesystem::is_directory(st) ? " (a directory)" : ""));
  }
  if (!std::ifstream(profiles).good()) throw config::ConfigError(where + ": cannot read '" + profiles + "'");
}

}  // namespace pixyslam::bridge
