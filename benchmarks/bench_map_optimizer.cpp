// Map optimiser cost over a whole run, as the live process solves it: one
// UTIAS MRCLAM robot (or the simulated world without --dataset) through the
// filter, then the optimiser fed the same input in order with the live
// schedule (config/map_optimizer.yaml's defaults: the newest window every
// optimizer.window_period_s of data, the whole problem every
// optimizer.whole_period_s, and once at the end).
//   bench_map_optimizer --dataset DIR --robot N --config FILE [--set optimizer.KEY=V ...]
//   bench_map_optimizer --config config/slam_sim.yaml        (the simulated world)
// Prints the data time, the optimiser thread's CPU time in all and per minute
// of data, the window and whole-problem solves (count, mean and max Ceres time),
// and the filter's and the optimiser's ATE. Instruction counts:
//   valgrind --tool=callgrind --toggle-collect='pixyslam::offline::optimise_run*' build/bin/bench_map_optimizer ...
// Exit codes: 0 done, 77 dataset folder absent (SKIP), 2 bad arguments, 1 error.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/optimised_run.h"
#include "pixyslam/offline/optimizer_sets.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

using namespace pixyslam;

void print_solves(const char* label, const std::vector<map_optimizer::SolveSummary>& solves) {
  double sum = 0.0, worst = 0.0;
  for (const map_optimizer::SolveSummary& s : solves) {
    sum += s.solve_time_s;
    worst = std::max(worst, s.solve_time_s);
  }
  std::printf("%-14s %6zu solves, Ceres time %.3f s in all, mean %.4f s, max %.4f s\n", label, solves.size(), sum,
              solves.empty() ? 0.0 : sum / static_cast<double>(solves.size()), worst);
}

int run(int argc, char** argv) {
  std::string dataset, config_file;
  int robot = 0;
  std::vector<std::string> overrides;
  app::Cli cli{"bench_map_optimizer", "Map optimiser cost over a whole run with the live process's solve schedule."};
  app::Cli::Option& dataset_option =
      cli.option("--dataset", dataset, "a MRCLAM data set (exit 77 when the folder is absent); without: the simulated "
                                       "world of the config's world: section").type("DIR");
  app::Cli::Option& robot_option = cli.option("--robot", robot, "the MRCLAM robot").range(mrclam::kFirstRobot, mrclam::kLastRobot).type("N");
  dataset_option.needs(robot_option);
  robot_option.needs(dataset_option);
  app::add_config(cli, config_file, "filter: (and mrclam: or world:) options").required();
  app::add_set(cli, overrides, "optimizer.window_period_s=2");
  const map_optimizer::MapOptimizerOptions core_defaults;
  const map_optimizer::SolveScheduleOptions schedule_defaults;
  cli.footer("optimizer parameters for --set (the map_optimizer process's keys; the noise models are the filter's):\n" +
             parameters::help_text(map_optimizer::map_optimizer_parameters(), "optimizer", core_defaults) +
             parameters::help_text(map_optimizer::solve_schedule_parameters(), "optimizer", schedule_defaults) +
             "Exit status: 0 done, 1 a failure, 2 a command-line or configuration error, 77 the data set folder "
             "is absent.");
  if (const auto done = cli.parse(argc, argv)) return *done;
  std::vector<std::string> optimizer_sets;
  if (const auto failed = app::configure("bench_map_optimizer", [&] {
        optimizer_sets = parameters::take_section(overrides, "optimizer");
        if (!overrides.empty()) throw std::invalid_argument("'" + overrides.front() + "': not an optimizer. parameter");
        offline::check_optimizer_sets(slam::FilterOptions{}, optimizer_sets, true);  // a bad key or value now
      })) {
    return *failed;
  }

  config::YamlReader root = config::YamlReader::from_file(config_file);
  config::YamlReader filter_yaml = root.child("filter");
  const slam::FilterOptions options = slam::read_filter_options(filter_yaml);
  offline::RunInput input;
  if (!dataset.empty()) {
    if (!std::filesystem::is_directory(dataset)) {
      std::printf("SKIP: dataset folder %s not found\n", dataset.c_str());
      return 77;
    }
    const offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
    root.finish();
    input = offline::mrclam_input(mrclam::load_robot(dataset, robot), model);
  } else {
    config::YamlReader world_yaml = root.child("world");
    const sim::WorldRun run = sim::simulate(sim::read_world_options(world_yaml));
    root.finish();
    input.initial_pose = run.initial_pose;
    input.start_time_s = run.truth.front().t_s;
    input.odometry = run.odometry;
    input.frames = run.frames;
    input.truth = run.truth;
    for (const sim::Pole& p : run.poles) input.landmarks.push_back({p.id, p.x_m, p.y_m});
  }
  const offline::RunResult filter = offline::run_filter(options, input);
  const offline::OptimisedRun opt =
      offline::optimise_run(options, input, filter, map_optimizer::SolveScheduleOptions{}, optimizer_sets);
  const map_optimizer::SolveScheduleOptions& schedule = opt.schedule;  // the live process's, after --set
  const double data_s = filter.trajectory.empty() ? 0.0 : filter.trajectory.back().t_s - input.start_time_s;
  std::printf("data %.1f s, %zu keyframes, %zu observation factors; schedule: window of %zu keyframes every %.1f s, "
              "whole problem every %.1f s (at most %.0f %% of data time)\n",
              data_s, opt.counters.keyframes, opt.counters.observations, schedule.window_keyframes,
              schedule.window_period_s, schedule.whole_period_s, 100.0 * schedule.whole_max_duty);
  std::printf("optimiser CPU %.3f s in all, %.3f s per minute of data (%.2f %% of one core); filter CPU %.3f s\n",
              opt.result.cpu_time_s, data_s > 0.0 ? 60.0 * opt.result.cpu_time_s / data_s : 0.0,
              data_s > 0.0 ? 100.0 * opt.result.cpu_time_s / data_s : 0.0, filter.cpu_time_s);
  print_solves("window", opt.window_solves);
  print_solves("whole", opt.whole_solves);
  print_solves("final whole", {opt.solve});
  const offline::Report f = offline::evaluate(input, filter);
  const offline::Report o = offline::evaluate(input, opt.result);
  if (f.has_truth) {
    std::printf("ATE: filter %.3f m, optimiser %.3f m; landmarks: filter %.3f m, optimiser %.3f m\n", f.filter.ate_rmse_m,
                o.filter.ate_rmse_m, f.landmarks.rmse_m, o.landmarks.rmse_m);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return app::run_main("bench_map_optimizer", [&] { return run(argc, argv); });
}
