// encoder_bridge: the Arduino's wheel-encoder lines (serial) -> Odometry over
// DDS at publish_rate_hz, until SIGINT/SIGTERM.
//   encoder_bridge --config config/encoder_bridge.yaml [--device PATH] [--dds-config FILE]
// --device overrides encoder_bridge.serial_device, --dds-config the Fast DDS XML
// profiles file (dds.profiles_file). Prints the effective configuration to
// stdout, logs to stderr. Exit status: 0 after a clean stop, 2 for a
// configuration or command-line error, 1 for any other failure.
#include <chrono>
#include <cstdio>
#include <optional>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/encoder_node/encoder_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  constexpr const char* kUsage =
      "usage: encoder_bridge --config FILE [--device PATH] [--dds-config FILE]";

  encoder_node::EncoderNodeOptions options;
  const std::optional<int> early_exit =
      app::set_up("encoder_bridge", kUsage, argc, argv, {"config", "device", "dds-config"},
                  [&](const app::CommandLine& args) {
                    options = encoder_node::read_encoder_node_options_file(args.get("config"));
                    bridge::apply_command_line(args, options.encoder.serial_device, options.dds);
                  });
  if (early_exit) return *early_exit;
  app::print_effective_configuration("encoder_bridge", encoder_node::to_yaml(options));

  return app::run_main("encoder_bridge", [&] {
    encoder_node::EncoderNode node(options);
    node.start();
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    std::fprintf(stderr, "encoder_bridge: stopped (signal %d)\n", app::StopSignal::signal_number());
    return 0;
  });
}
