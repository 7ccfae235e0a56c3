// foxglove_bridge: the live system in Foxglove (foxglove.dev), as ROS users get
// it from foxglove_bridge: a Foxglove WebSocket server (foxglove.websocket.v1)
// with every DDS topic (CDR, OMG IDL schema) and the pixyslam/viz/* channels
// drawn by Foxglove's 3D panel, until SIGINT/SIGTERM.
//   foxglove_bridge --config config/foxglove_bridge.yaml [--port N] [--set KEY=VALUE ...] [--domain N] [--verbose]
// In Foxglove: Open connection -> Foxglove WebSocket -> ws://HOST:8765, then
// import docs/foxglove_layout.json. Listens on 127.0.0.1 unless
// foxglove_bridge.address says otherwise.
// Exit status: 0 after a clean stop, 2 for a configuration or command-line
// error (a port in use included), 1 for any other failure.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/foxglove_node/bridge_node.h"
#include "pixyslam/parameters/parameters.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  std::string config;
  int port = -1;
  std::vector<std::string> overrides;
  bool verbose = false;
  app::Cli cli{"foxglove_bridge",
               "Serves the live DDS topics to Foxglove over its WebSocket protocol (foxglove.websocket.v1), with "
               "3D scene channels pixyslam/viz/*, until SIGINT/SIGTERM."};
  app::add_config(cli, config, "config/foxglove_bridge.yaml: foxglove_bridge:, dds:");
  cli.option("--port", port, "TCP port (overrides foxglove_bridge.port; 0: any free port)").range(0, 65535).type("PORT");
  std::vector<std::string> domain;
  app::add_set(cli, overrides, "foxglove_bridge.address=0.0.0.0");
  app::add_domain(cli, domain);
  app::add_verbose(cli, verbose);
  cli.footer("foxglove_bridge parameters (foxglove_bridge:; topics apart):\n" +
             parameters::help_text(foxglove_node::bridge_parameters(), "foxglove_bridge") +
             "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
             parameters::help_text(pixyslam::dds::dds_parameters(), "dds"));
  if (const auto done = cli.parse(argc, argv)) return *done;

  foxglove_node::BridgeOptions options;
  const std::optional<int> bad = app::configure("foxglove_bridge", [&] {
    options = foxglove_node::read_bridge_options_file(config);
    if (port >= 0) overrides.push_back("foxglove_bridge.port=" + std::to_string(port));
    overrides.insert(overrides.end(), domain.begin(), domain.end());  // --domain last: it wins
    foxglove_node::apply_overrides(options, overrides);
  });
  if (bad) return *bad;
  if (verbose) {
    std::printf("# foxglove_bridge: effective configuration\n%s", foxglove_node::to_yaml(options).c_str());
    std::fflush(stdout);
  }
  return app::run_main("foxglove_bridge", [&] {
    std::unique_ptr<foxglove_node::BridgeNode> node;
    try {
      node = std::make_unique<foxglove_node::BridgeNode>(options);
    } catch (const std::runtime_error& e) {
      if (std::string(e.what()).find("cannot listen") != std::string::npos) throw app::UsageError(e.what());
      throw;
    }
    std::fprintf(stderr, "foxglove_bridge: %zu channels on ws://%s:%u (DDS domain %d, profile '%s')\n",
                 node->channels().size(), options.server.address.c_str(), static_cast<unsigned>(node->port()),
                 options.dds.domain_id, options.dds.participant_profile.c_str());
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node->stop();
    const foxglove_node::BridgeCounters c = node->counters();
    std::fprintf(stderr,
                 "foxglove_bridge: %llu samples received (%llu malformed, %llu seq gaps), %llu clients (%llu refused, "
                 "%llu bad requests), %llu messages sent, %llu dropped (slow client %llu, backlog %llu)\n",
                 static_cast<unsigned long long>(c.samples_received),
                 static_cast<unsigned long long>(c.samples_malformed), static_cast<unsigned long long>(c.seq_gaps),
                 static_cast<unsigned long long>(c.server.clients_accepted),
                 static_cast<unsigned long long>(c.server.clients_refused),
                 static_cast<unsigned long long>(c.server.bad_requests),
                 static_cast<unsigned long long>(c.server.messages_sent),
                 static_cast<unsigned long long>(c.server.dropped_slow_client + c.server.dropped_backlog),
                 static_cast<unsigned long long>(c.server.dropped_slow_client),
                 static_cast<unsigned long long>(c.server.dropped_backlog));
    return 0;
  });
}
