// Filter speed on real data: one UTIAS MRCLAM robot run through the offline
// runner (offline::run_filter, the same loop as slam_offline mrclam) once per
// particle count, with the config's filter options and `mrclam:` corrections.
//   bench_mrclam_frame --dataset DIR --robot N --config FILE --particles M1,M2,...
//                      [--frames F] [--seed S]
// --frames F runs only the first F camera frames (and the odometry up to the
// last of them). Per M it prints the camera frames and odometry samples fed, the
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
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

using namespace pixyslam;

long parse_long(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') throw std::invalid_argument(what + ": not an integer: '" + text + "'");
  return v;
}

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::string digits;
    for (char c : item) {
      if (c != '_' && c != ' ') digits += c;  // allow 10_000
    }
    const long v = parse_long(digits, "--particles");
    if (v < 1) throw std::invalid_argument("--particles: need values >= 1");
    out.push_back(static_cast<int>(v));
  }
  if (out.empty()) throw std::invalid_argument("--particles: empty list");
  return out;
}

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

int usage(const char* why) {
  std::fprintf(stderr,
               "bench_mrclam_frame: %s\n"
               "usage: bench_mrclam_frame --dataset DIR --robot N --config FILE --particles M1,M2,... "
               "[--frames F] [--seed S]\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> args;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::printf("usage: bench_mrclam_frame --dataset DIR --robot N --config FILE --particles M1,M2,... "
                  "[--frames F] [--seed S]\n");
      return 0;
    }
    const std::string key = argv[i];
    if (key.rfind("--", 0) != 0 || i + 1 >= argc) return usage(("bad argument '" + key + "'").c_str());
    args[key.substr(2)] = argv[++i];
  }
  for (const char* required : {"dataset", "robot", "config", "particles"}) {
    if (!args.count(required)) return usage((std::string("missing --") + required).c_str());
  }
  for (const auto& kv : args) {
    if (kv.first != "dataset" && kv.first != "robot" && kv.first != "config" && kv.first != "particles" &&
        kv.first != "frames" && kv.first != "seed") {
      return usage(("unknown option --" + kv.first).c_str());
    }
  }
  const std::string dataset = args["dataset"];
  if (!std::filesystem::is_directory(dataset)) {
    std::printf("SKIP: MRCLAM dataset folder %s not found\n", dataset.c_str());
    return 77;
  }
  try {
    const int robot = static_cast<int>(parse_long(args["robot"], "--robot"));
    const std::vector<int> particles = parse_list(args["particles"]);
    long frames_limit = -1;
    if (args.count("frames")) {
      frames_limit = parse_long(args["frames"], "--frames");
      if (frames_limit < 1) throw std::invalid_argument("--frames: need F >= 1");
    }

    config::YamlReader root = config::YamlReader::from_file(args["config"]);
    config::YamlReader filter_yaml = root.child("filter");
    slam::FilterOptions options = slam::read_filter_options(filter_yaml);
    if (args.count("seed")) options.seed = static_cast<std::uint64_t>(parse_long(args["seed"], "--seed"));
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
                dataset.c_str(), robot, args["config"].c_str(), static_cast<unsigned long long>(options.seed),
                frames, frames_all, frames_limit > 0 ? " (--frames)" : " (whole run)", odometry);
    std::printf("%8s %8s %9s %12s %10s %14s %10s %9s\n", "M", "frames", "odometry", "filter_s", "cpu_s",
                "us_per_frame", "ATE_m", "ratio");
    double previous_s = 0.0;
    for (const int m : particles) {
      slam::FilterOptions o = options;
      o.particles = m;
      const offline::RunResult result = offline::run_filter(o, input);
      const offline::Report report = offline::evaluate(input, result);
      const double t = result.wall_time_s;
      char ate[32] = "-";
      if (report.has_truth) std::snprintf(ate, sizeof ate, "%.3f", report.filter.ate_rmse_m);
      char ratio[32] = "-";
      if (previous_s > 0.0) std::snprintf(ratio, sizeof ratio, "%.2fx", t / previous_s);
      std::printf("%8d %8zu %9zu %12.3f %10.3f %14.1f %10s %9s\n", m, frames, odometry, t, result.cpu_time_s,
                  1e6 * t / static_cast<double>(frames), ate, ratio);
      std::fflush(stdout);
      previous_s = t;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_mrclam_frame: %s\n", e.what());
    return 1;
  }
}
