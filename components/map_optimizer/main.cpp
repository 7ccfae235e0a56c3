// map_optimizer: the map optimiser over DDS (components/map_optimizer): Odometry,
// LandmarkObservation and the estimator's MapState in, OptimisedMap out, until
// SIGINT/SIGTERM. Optional: the robot runs without it; it can run on another host.
//   map_optimizer --config config/map_optimizer.yaml [--out-dir DIR] [--set KEY=VALUE ...] [--domain N] [--verbose]
// --out-dir writes DIR/trajectory.csv (every keyframe of the final solution,
// and of each earlier problem as it ends: optimizer.max_keyframes) and
// DIR/landmarks.csv at exit, in slam_offline's formats.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/trajectory_output.h"
#include "pixyslam/map_optimizer_node/optimizer_node.h"

namespace {

// DIR/landmarks.csv: the last solution's landmarks.
void write_landmarks(const std::string& dir, const pixyslam::msg::OptimisedMap& map) {
  using namespace pixyslam;
  std::vector<eval::LandmarkRow> rows;
  for (const msg::OptimisedLandmark& l : map.landmarks()) {
    rows.push_back({l.landmark_id(), l.x_m(), l.y_m(), l.cov_xx_m2(), l.cov_xy_m2(), l.cov_yy_m2()});
  }
  eval::write_landmarks_csv(dir + "/landmarks.csv", rows);
  std::fprintf(stderr, "map_optimizer: wrote %s/landmarks.csv (%zu)\n", dir.c_str(), rows.size());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config, out_dir;
  std::vector<std::string> overrides;
  bool verbose = false;
  app::Cli cli{"map_optimizer", "The map optimiser over DDS: Odometry, LandmarkObservation and the estimator's MapState in, "
               "OptimisedMap out, until SIGINT/SIGTERM."};
  app::add_config(cli, config,
                  "config/map_optimizer.yaml: filter_config (the estimator's file: its noise, limits and start pose), "
                  "optimizer:, dds:");
  cli.option("--out-dir", out_dir, "DIR/trajectory.csv (every keyframe, solved; a segment's when it ends, the rest at exit) and at exit DIR/landmarks.csv")
      .type("DIR");
  std::vector<std::string> domain;
  app::add_set(cli, overrides, "optimizer.window_keyframes=50");
  app::add_domain(cli, domain);
  app::add_verbose(cli, verbose);
  cli.footer(map_optimizer_node::help_text());
  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("map_optimizer", [&] {
    map_optimizer_node::OptimizerNodeOptions options = map_optimizer_node::read_optimizer_node_options_file(config);
    try {
      overrides.insert(overrides.end(), domain.begin(), domain.end());  // --domain last: it wins
      map_optimizer_node::apply_overrides(options, overrides);
    } catch (const std::invalid_argument& e) {
      throw app::UsageError(std::string("--set: ") + e.what());
    }
    std::fprintf(stderr,
                 "map_optimizer: keyframe every %.2f s at most, window of %zu keyframes every %.1f s, whole problem "
                 "every %.1f s; DDS domain %d, profiles '%s'\n",
                 options.optimizer.keyframe_interval_s, options.schedule.window_keyframes, options.schedule.window_period_s,
                 options.schedule.whole_period_s, options.dds.domain_id, options.dds.profiles_file.c_str());
    if (verbose) app::print_effective_configuration("map_optimizer", map_optimizer_node::to_yaml(options));
    // Before the node: its thread writes here until the node is destroyed.
    std::optional<eval::TrajectoryOutput> trajectory;
    map_optimizer_node::OptimizerNode node(options);
    if (!out_dir.empty()) {
      trajectory.emplace(out_dir, "map_optimizer");  // a folder that cannot be written fails now, not at the end
      node.set_keyframe_sink([&trajectory](std::uint64_t stamp_ns, const slam::Pose2& pose) {
        trajectory->add(stamp_ns, pose.x(), pose.y(), pose.z());
      });
    }
    node.start();
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    const map_optimizer_node::OptimizerNodeCounters c = node.counters();
    std::fprintf(stderr, "map_optimizer: %llu window and %llu whole-problem solves, CPU %.3f s (Ceres %.3f s)\n",
                 static_cast<unsigned long long>(c.window_solves), static_cast<unsigned long long>(c.whole_solves),
                 c.cpu_time_s, c.solve_time_s);
    if (trajectory) {
      const std::size_t rows = trajectory->finish();
      std::fprintf(stderr, "map_optimizer: wrote %s (%zu keyframes)\n", trajectory->path().c_str(), rows);
      write_landmarks(out_dir, node.latest_map());
    }
    return trajectory && trajectory->failed() ? 1 : 0;  // the file ends early: the run's record is short
  });
}
