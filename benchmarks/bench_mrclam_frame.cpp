// Filter speed on real data: one UTIAS MRCLAM robot run through the offline
// runner (offline::run_filter, the same loop as slam_offline mrclam) once per
// particle count, with the config's filter options and `mrclam:` corrections.
//   bench_mrclam_frame --dataset DIR --robot N --config FILE --particles M1,M2,...
//                      [--frames F] [--seed S] [--repeat R]
// --frames F runs only the first F camera frames (and the odometry up to the
// last of them). --repeat R runs the list R times in turn and ends with each
// entry's least wall time and the ratios of those (on a shared machine the
// least of a few runs is the steadiest figure). Per M it prints the camera frames and odometry samples fed, the
// filter time (run_filter's wall time: every add_odometry/add_observations and
// the pose_estimate recorded after each step) and its CPU time (steadier on a
// shared machine), the wall time per camera frame, the pose ATE against the
// ground truth (when present) and the wall time ratio to the previous M.
//
// Instructions per camera frame (deterministic), one M per process:
//   valgrind --tool=callgrind --callgrind-out-file=/tmp/x
//     --toggle-collect='pixyslam::offline::run_filter*'
//     build/bin/bench_mrclam_frame --dataset DIR --robot 2 --config FILE --particles 100
// (one command line)
// collects the filter loop only (not the loading or the evaluation): the
// "summary:" line of /tmp/x divided by the camera frames printed. Without the
// toggle, (summary of the --frames F2 run - summary of the --frames F1 run) /
// (F2 - F1) gives the same per-frame count for frames F1..F2.
//
// Exit codes: 0 done, 77 dataset folder absent (SKIP), 2 bad arguments, 1 error.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

using namespace pixyslam;

// The first `frames` camera frames at or after the start, and the odometry up to
// the last of them (the filter's time ends there).
offline::RunInput first_frames(offline::RunInput input, std::size_t frames) {
  std::vector<slam::ObservationFrame> kept;
  for (const slam::ObservationFrame& f : input.frames) {
    if (kept.size() == frames) break;
    if (f.t_s >= input.start_time_s) kept.push_back(f);
  }
  if (kept.empty()) throw std::invalid_argument("--frames: no camera frame in the run");
  const double end_s = kept.back().t_s;
  std::vector<slam::OdometrySample> odometry;
  for (const slam::OdometrySample& s : input.odometry) {
    if (s.t_s <= end_s) odometry.push_back(s);
  }
  input.frames = std::move(kept);
  input.odometry = std::move(odometry);
  return input;
}

int run(int argc, char** argv) {
  std::string dataset, config_file, particles_text;
  int robot = 0, frames_limit = -1, repeat = 1;
  std::uint64_t seed = 0;
  app::Cli cli{"bench_mrclam_frame", "Filter speed on real data: one MRCLAM robot through the offline runner per "
                                     "particle count. Exit 77 when the data set folder is absent."};
  cli.option("--dataset", dataset, "the MRCLAM data set folder").required().type("DIR");
  cli.option("--robot", robot, "the robot").required().range(mrclam::kFirstRobot, mrclam::kLastRobot).type("N");
  app::add_config(cli, config_file, "filter: and mrclam: options").required();
  cli.option("--particles", particles_text, "particle counts, one run each").required().type("M1,M2,...");
  cli.option("--frames", frames_limit, "only the first F camera frames").range(1, 100000000).type("F");
  cli.option("--seed", seed, "the filter's seed (default: the config's)").seed().type("S");
  cli.option("--repeat", repeat, "run the list R times in turn, then print each entry's least time and their ratios")
      .range(1, 100)
      .type("R");
  if (const auto done = cli.parse(argc, argv)) return *done;
  if (!std::filesystem::is_directory(dataset)) {
    std::printf("SKIP: MRCLAM dataset folder %s not found\n", dataset.c_str());
    return 77;
  }
  {
    const std::vector<int> particles = app::parse_int_list(particles_text, "--particles", 1);
    config::YamlReader root = config::YamlReader::from_file(config_file);
    config::YamlReader filter_yaml = root.child("filter");
    slam::FilterOptions options = slam::read_filter_options(filter_yaml);
    if (cli.given("--seed")) options.seed = seed;
    const offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
    root.finish();

    const mrclam::RobotData data = mrclam::load_robot(dataset, robot);
    offline::RunInput input = offline::mrclam_input(data, model);
    std::size_t frames_all = 0;
    for (const auto& f : input.frames) frames_all += f.t_s >= input.start_time_s ? 1 : 0;
    if (frames_limit > 0) input = first_frames(std::move(input), static_cast<std::size_t>(frames_limit));
    std::size_t frames = 0, odometry = 0;
    for (const auto& f : input.frames) frames += f.t_s >= input.start_time_s ? 1 : 0;
    for (const auto& s : input.odometry) odometry += s.t_s >= input.start_time_s ? 1 : 0;

    std::printf("MRCLAM %s robot %d, config %s, seed %llu: %zu of %zu camera frames%s, %zu odometry samples\n",
                dataset.c_str(), robot, config_file.c_str(), static_cast<unsigned long long>(options.seed),
                frames, frames_all, frames_limit > 0 ? " (--frames)" : " (whole run)", odometry);
    std::printf("%8s %8s %9s %12s %10s %14s %10s %9s\n", "M", "frames", "odometry", "filter_s", "cpu_s",
                "us_per_frame", "ATE_m", "ratio");
    std::vector<double> least(particles.size(), 0.0);
    for (int round = 0; round < repeat; ++round) {
      double previous_s = 0.0;
      for (std::size_t k = 0; k < particles.size(); ++k) {
        slam::FilterOptions o = options;
        o.particles = particles[k];
        const offline::RunResult result = offline::run_filter(o, input);
        const offline::Report report = offline::evaluate(input, result);
        const double t = result.wall_time_s;
        char ate[32] = "-";
        if (report.has_truth) std::snprintf(ate, sizeof ate, "%.3f", report.filter.ate_rmse_m);
        char ratio[32] = "-";
        if (previous_s > 0.0) std::snprintf(ratio, sizeof ratio, "%.2fx", t / previous_s);
        std::printf("%8d %8zu %9zu %12.3f %10.3f %14.1f %10s %9s\n", particles[k], frames, odometry, t,
                    result.cpu_time_s, 1e6 * t / static_cast<double>(frames), ate, ratio);
        std::fflush(stdout);
        previous_s = t;
        if (round == 0 || t < least[k]) least[k] = t;
      }
    }
    if (repeat > 1) {
      std::printf("least of %d rounds:\n%8s %12s %14s %9s\n", repeat, "M", "filter_s", "us_per_frame", "ratio");
      for (std::size_t k = 0; k < particles.size(); ++k) {
        char ratio[32] = "-";
        if (k > 0) std::snprintf(ratio, sizeof ratio, "%.2fx", least[k] / least[k - 1]);
        std::printf("%8d %12.3f %14.1f %9s\n", particles[k], least[k], 1e6 * least[k] / static_cast<double>(frames),
                    ratio);
      }
    }
    return 0;
  }
}

}  // namespace

int main(int argc, char** argv) {
  return app::run_main("bench_mrclam_frame", [&] { return run(argc, argv); });
}
