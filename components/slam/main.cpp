// slam_estimator: FastSLAM 2.0 over DDS. Odometry + LandmarkObservation in,
// MapState out, until SIGINT/SIGTERM.
//   slam_estimator --config config/slam_estimator.yaml [--seed S] [--out-dir DIR] [--checkpoint FILE]
//                  [--set KEY=VALUE ...] [--domain N] [--verbose]
// --checkpoint (or estimator.checkpoint.file) saves the pose and map every
// period and resumes from the file at start when it is fresh (a restart).
// --out-dir writes DIR/trajectory.csv (the mean pose after every filter step, as it goes) and DIR/landmarks.csv at exit.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam_node/estimator_node.h"
#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/trajectory_output.h"

namespace {

// DIR/landmarks.csv: the last MapState's landmarks.
void write_landmarks(const std::string& dir, const pixyslam::slam_node::EstimatorNode& node) {
  using namespace pixyslam;
  std::vector<eval::LandmarkRow> rows;
  // A named copy: iterating over a member of the returned temporary would dangle.
  const msg::MapState last = node.latest_map_state();
  for (const msg::LandmarkEstimate& l : last.landmarks()) {
    rows.push_back({l.landmark_id(), l.x_m(), l.y_m(), l.cov_xx_m2(), l.cov_xy_m2(), l.cov_yy_m2()});
  }
  eval::write_landmarks_csv(dir + "/landmarks.csv", rows);
  std::fprintf(stderr, "slam_estimator: wrote %s/landmarks.csv (%zu)\n", dir.c_str(), rows.size());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config, out_dir, checkpoint, seed;
  std::vector<std::string> overrides;
  bool verbose = false;
  app::Cli cli{"slam_estimator", "FastSLAM 2.0 over DDS: Odometry and LandmarkObservation in, MapState out, until SIGINT/SIGTERM."};
  app::add_config(cli, config, "config/slam_estimator.yaml: filter:, estimator:, dds:");
  cli.option("--seed", seed, "the same as --set filter.seed=S").type("S");
  cli.option("--out-dir", out_dir, "DIR/trajectory.csv (the mean pose after every filter step, written as it goes) and at exit DIR/landmarks.csv")
      .type("DIR");
  cli.option("--checkpoint", checkpoint,
                 "save pose and map here every period, resume from it at start when fresh (estimator.checkpoint.file)")
      .type("FILE");
  std::vector<std::string> domain;
  app::add_set(cli, overrides, "filter.particles=300");
  app::add_domain(cli, domain);
  app::add_verbose(cli, verbose);
  cli.footer(slam_node::help_text());
  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("slam_estimator", [&] {
    slam_node::EstimatorOptions options = slam_node::read_estimator_options_file(config);
    if (!seed.empty()) overrides.push_back("filter.seed=" + seed);  // after --set: the flag wins
    try {
      overrides.insert(overrides.end(), domain.begin(), domain.end());  // --domain last: it wins
      slam_node::apply_overrides(options, overrides);
    } catch (const std::invalid_argument& e) {
      throw app::UsageError(std::string("--seed/--set: ") + e.what());
    }
    if (!checkpoint.empty()) options.checkpoint.file = checkpoint;
    std::fprintf(stderr, "slam_estimator: %d particles, seed %llu, DDS domain %d, profiles '%s'\n",
                 options.filter.particles, static_cast<unsigned long long>(options.filter.seed),
                 options.dds.domain_id, options.dds.profiles_file.c_str());
    if (verbose) app::print_effective_configuration("slam_estimator", slam_node::to_yaml(options));

    // Before the node: its filter thread writes here until the node is destroyed.
    std::optional<eval::TrajectoryOutput> trajectory;
    slam_node::EstimatorNode node(options);
    if (!out_dir.empty()) {
      trajectory.emplace(out_dir, "slam_estimator");  // a folder that cannot be written fails now, not at the end
      node.set_step_observer([&trajectory](std::uint64_t stamp_ns, const slam::Pose2& pose) {
        trajectory->add(stamp_ns, pose.x(), pose.y(), pose.z());
      });
    }
    node.start();
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    if (trajectory) {
      const std::size_t rows = trajectory->finish();
      std::fprintf(stderr, "slam_estimator: wrote %s (%zu poses)\n", trajectory->path().c_str(), rows);
      write_landmarks(out_dir, node);
    }
    return trajectory && trajectory->failed() ? 1 : 0;  // the file ends early: the run's record is short
  });
}
