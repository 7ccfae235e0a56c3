// Map optimiser cost over a whole run, as the live process solves it: one
// UTIAS MRCLAM robot (or the simulated world without --dataset) through the
// filter, then the optimiser fed the same input in order with the live
// schedule (the newest window every --window-period s of data, the whole
// problem every --whole-period s, and once at the end).
//   bench_map_optimizer --dataset DIR --robot N --config FILE
//                       [--window-period S] [--window-keyframes K] [--whole-period S]
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
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/optimised_run.h"
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
  int window_keyframes = 0;
  map_optimizer::SolveScheduleOptions schedule;  // the live process's defaults
  app::Cli cli{"bench_map_optimizer", "Map optimiser cost over a whole run with the live process's solve schedule."};
  app::Cli::Option& dataset_option =
      cli.option("--dataset", dataset, "a MRCLAM data set (exit 77 when the folder is absent); without: the simulated "
                                       "world of the config's world: section").type("DIR");
  app::Cli::Option& robot_option = cli.option("--robot", robot, "the MRCLAM robot").range(mrclam::kFirstRobot, mrclam::kLastRobot).type("N");
  dataset_option.needs(robot_option);
  robot_option.needs(dataset_option);
  app::add_config(cli, config_file, "filter: (and mrclam: or world:) options").required();
  cli.option("--window-period", schedule.window_period_s, "data time between window solves, default 1 "
                                                          "(as config/map_optimizer.yaml)").positive().type("S");
  cli.option("--window-keyframes", window_keyframes, "keyframes a window solve frees, default 100").range(1, 1000000)
      .type("K");
  cli.option("--whole-period", schedule.whole_period_s, "data time between whole-problem solves, default 10")
      .positive().type("S");
  cli.option("--whole-max-duty", schedule.whole_max_duty,
             "whole solves take at most this fraction of data time, default 0.1 (0: no bound)")
      .range(0.0, 1.0).type("F");
  if (const auto done = cli.parse(argc, argv)) return *done;
  if (cli.given("--window-keyframes")) schedule.window_keyframes = static_cast<std::size_t>(window_keyframes);

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
  const offline::OptimisedRun opt = offline::optimise_run(options, input, filter, schedule);
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
