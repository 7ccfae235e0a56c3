// fleet_map: every robot's MapState on the domain fused into one landmark map
// (same landmark ids, covariance weighted, after checking that the robots'
// frames agree), published as FleetMap on pixyslam/fleet_map, until SIGINT/SIGTERM.
//   fleet_map --config config/fleet_map.yaml [--set KEY=VALUE ...] [--domain N] [--verbose]
// Exit status: 0 after a clean stop, 2 for a configuration or command-line
// error, 1 for any other failure.
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/fleet_map_node/fleet_map_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config;
  std::vector<std::string> overrides, domain;
  bool verbose = false;
  app::Cli cli{"fleet_map",
               "Every robot's MapState fused into one landmark map (FleetMap on pixyslam/fleet_map), frames checked, "
               "until SIGINT/SIGTERM."};
  app::add_config(cli, config, "config/fleet_map.yaml: fleet_map:, dds:");
  app::add_set(cli, overrides, "fleet_map.disagreement=set_aside");
  app::add_domain(cli, domain);
  app::add_verbose(cli, verbose);
  cli.footer("fleet_map parameters (fleet_map:):\n" +
             parameters::help_text(fleet_map_node::fleet_map_parameters(), "fleet_map") +
             "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
             parameters::help_text(dds::dds_parameters(), "dds") +
             "Exit status: 0 after a clean stop, 1 a failure, 2 a command-line or configuration error.");
  if (const auto done = cli.parse(argc, argv)) return *done;

  fleet_map_node::FleetMapOptions options;
  const std::optional<int> bad = app::configure("fleet_map", [&] {
    options = fleet_map_node::read_fleet_map_options_file(config);
    overrides.insert(overrides.end(), domain.begin(), domain.end());
    fleet_map_node::apply_overrides(options, overrides);
  });
  if (bad) return *bad;
  if (verbose) app::print_effective_configuration("fleet_map", fleet_map_node::to_yaml(options));

  return app::run_main("fleet_map", [&] {
    fleet_map_node::FleetMapNode node(options);
    node.start();
    std::fprintf(stderr, "fleet_map: fusing every robot's map on DDS domain %d every %g s\n", options.dds.domain_id,
                 options.period_s);
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    const fleet_map_node::FleetMapCounters c = node.counters();
    std::fprintf(stderr, "fleet_map: stopped; %llu map states, %zu robots at the end (%llu timed out; %llu stale, "
                         "%llu restarts, %llu beyond max_robots, %llu malformed), %llu fleet maps published (%llu "
                         "failed)\n",
                 static_cast<unsigned long long>(c.map_states), c.robots,
                 static_cast<unsigned long long>(c.robots_timed_out), static_cast<unsigned long long>(c.stale),
                 static_cast<unsigned long long>(c.restarts), static_cast<unsigned long long>(c.robots_over_limit),
                 static_cast<unsigned long long>(c.malformed),
                 static_cast<unsigned long long>(c.fleet_maps), static_cast<unsigned long long>(c.publish_failures));
    return 0;
  });
}
