// pixy_bridge: the Pixy's UART block stream (serial) -> one LandmarkObservation
// per camera frame over DDS, until SIGINT/SIGTERM.
//   pixy_bridge --config config/pixy_bridge.yaml [--device PATH] [--dds-config FILE]
// --device overrides node.serial_device, --dds-config the Fast DDS XML profiles
// file (dds.profiles_file). Prints the effective configuration to stdout, logs
// to stderr. Exit status: 0 after a clean stop, 2 for a configuration or
// command-line error, 1 for any other failure.
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy_node/pixy_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  constexpr const char* kUsage = "usage: pixy_bridge --config FILE [--device PATH] [--dds-config FILE]";

  pixy_node::PixyNodeOptions options;
  try {
    const app::CommandLine args(argc, argv, {"config", "device", "dds-config"});
    if (args.help()) {
      std::puts(kUsage);
      return 0;
    }
    const std::string& config_file = args.get("config");
    options = pixy_node::read_pixy_node_options_file(config_file);
    if (args.has("device")) {
      options.serial_device = args.get("device");
      if (options.serial_device.empty() || options.serial_device.front() != '/') {
        throw std::invalid_argument("--device '" + options.serial_device + "' is not an absolute path");
      }
    }
    if (args.has("dds-config")) options.dds.profiles_file = args.get("dds-config");
    const std::string& profiles = options.dds.profiles_file;
    if (!profiles.empty() && !std::ifstream(profiles).good()) {
      throw config::ConfigError((args.has("dds-config") ? std::string("--dds-config")
                                                        : config_file + ": key 'dds.profiles_file'") +
                                ": cannot read '" + profiles + "'");
    }
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "pixy_bridge: config error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "pixy_bridge: %s\n%s\n", e.what(), kUsage);
    return 2;
  }
  std::printf("# pixy_bridge: effective configuration\n%s", pixy_node::to_yaml(options).c_str());
  std::fflush(stdout);

  try {
    pixy_node::PixyNode node(options);
    node.start();
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    std::fprintf(stderr, "pixy_bridge: stopped (signal %d)\n", app::StopSignal::signal_number());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixy_bridge: %s\n", e.what());
    return 1;
  }
}
