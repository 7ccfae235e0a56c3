// encoder_bridge: the Arduino's wheel-encoder lines (serial) -> Odometry over
// DDS at publish_rate_hz, until SIGINT/SIGTERM.
//   encoder_bridge --config config/encoder_bridge.yaml [--device PATH] [--set KEY=VALUE ...] [--domain N] [--verbose]
// --device overrides node.serial_device; --set encoder_bridge.KEY=V,
// node.KEY=V or dds.KEY=V a parameter. --verbose prints the effective configuration to
// stdout; logs go to stderr. Exit status: 0 after a clean stop, 2 for a
// configuration or command-line error, 1 for any other failure.
#include <chrono>
#include <cstdio>
#include <optional>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/encoder_node/encoder_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  bridge::BridgeCommandLine args;
  app::Cli cli{"encoder_bridge", "The Arduino's wheel-encoder lines (serial) -> Odometry over DDS, until SIGINT/SIGTERM."};
  bridge::add_bridge_flags(cli, args, "config/encoder_bridge.yaml: encoder_bridge:, node:, dds:",
                           "encoder_bridge.publish_rate_hz=20");
  cli.footer(encoder_node::help_text());
  if (const auto done = cli.parse(argc, argv)) return *done;

  encoder_node::EncoderNodeOptions options;
  const std::optional<int> bad = app::configure("encoder_bridge", [&] {
    options = encoder_node::read_encoder_node_options_file(args.config);
    encoder_node::apply_overrides(options, args.overrides);
    bridge::apply_command_line(args, options.process.serial_device, options.dds);
  });
  if (bad) return *bad;
  if (args.verbose) app::print_effective_configuration("encoder_bridge", encoder_node::to_yaml(options));

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
