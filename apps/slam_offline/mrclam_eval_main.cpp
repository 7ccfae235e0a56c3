// mrclam_eval: the accuracy table of the FastSLAM core on MRCLAM, one parameter
// set for every robot, several seeds per robot.
//   mrclam_eval --dataset DIR --config FILE [--robots 1,2,3,4,5] [--seeds 1,2,3]
//               [--association known_id|maximum_likelihood]
// --association maximum_likelihood withholds the landmark ids from the filter
// (the landmark columns then match nothing by id; ATE and heading still count).
// Exit codes: 0 done, 77 dataset folder absent (skip), 1 error,
// 3 a robot's mean ATE is not better than dead reckoning.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "mrclam_dataset.h"
#include "offline_run.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

using namespace pixyslam;

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0') throw std::invalid_argument("not an integer list: '" + text + "'");
    out.push_back(static_cast<int>(v));
  }
  return out;
}

int run(int argc, char** argv) {
  std::string dataset, config_path, association;
  std::vector<int> robots{1, 2, 3, 4, 5}, seeds{1, 2, 3};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--dataset") dataset = value;
    else if (key == "--config") config_path = value;
    else if (key == "--robots") robots = parse_list(value);
    else if (key == "--seeds") seeds = parse_list(value);
    else if (key == "--association") association = value;
    else throw std::invalid_argument("unknown argument '" + key + "'");
  }
  if (argc % 2 == 0 || dataset.empty() || config_path.empty()) {
    throw std::invalid_argument("usage: mrclam_eval --dataset DIR --config FILE [--robots 1,2] [--seeds 1,2]");
  }
  if (!std::filesystem::is_directory(dataset)) {
    std::printf("SKIP: dataset folder %s not found\n", dataset.c_str());
    return 77;
  }
  config::YamlReader root = config::YamlReader::from_file(config_path);
  config::YamlReader filter_yaml = root.child("filter");
  slam::FilterOptions options = slam::read_filter_options(filter_yaml);
  const offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
  root.finish();
  if (association == "maximum_likelihood") {
    options.association = slam::Association::kMaximumLikelihood;
  } else if (!association.empty() && association != "known_id") {
    throw std::invalid_argument("--association must be known_id or maximum_likelihood");
  }

  std::printf("%-6s %-5s %9s %9s %9s %10s %10s %11s %11s %8s %5s %8s\n", "robot", "seed", "ATE_m", "ATE_al_m", "DR_ATE_m",
              "head_deg", "DR_head", "lm_raw_m", "lm_align_m", "gated", "map", "wall_s");
  constexpr double kDeg = 180.0 / M_PI;
  bool all_better = true;
  double sum_ate = 0, sum_ate_aligned = 0, sum_head = 0, sum_lm = 0, sum_lma = 0, sum_wall = 0;
  int runs = 0;
  for (int robot : robots) {
    const mrclam::RobotData data = mrclam::load_robot(dataset, robot);
    const offline::RunInput input = offline::mrclam_input(data, model);
    double robot_ate = 0, robot_dr = 0;
    for (int seed : seeds) {
      options.seed = static_cast<std::uint64_t>(seed);
      const offline::RunResult res = offline::run_filter(options, input);
      const offline::Report rep = offline::evaluate(input, res);
      std::printf("%-6d %-5d %9.3f %9.3f %9.3f %10.2f %10.2f %11.3f %11.3f %8llu %5zu %8.2f\n", robot, seed,
                  rep.filter.ate_rmse_m, rep.filter.ate_rmse_aligned_m, rep.dead_reckoning.ate_rmse_m, rep.filter.heading_rmse_rad * kDeg,
                  rep.dead_reckoning.heading_rmse_rad * kDeg, rep.landmarks.rmse_m, rep.landmarks.rmse_aligned_m,
                  static_cast<unsigned long long>(res.counters.observations_gated), res.landmarks.size(),
                  res.wall_time_s);
      std::fflush(stdout);
      robot_ate += rep.filter.ate_rmse_m;
      robot_dr += rep.dead_reckoning.ate_rmse_m;
      sum_ate += rep.filter.ate_rmse_m;
      sum_ate_aligned += rep.filter.ate_rmse_aligned_m;
      sum_head += rep.filter.heading_rmse_rad * kDeg;
      sum_lm += rep.landmarks.rmse_m;
      sum_lma += rep.landmarks.rmse_aligned_m;
      sum_wall += res.wall_time_s;
      ++runs;
    }
    // Without robot ground truth (Dataset1, Dataset2) only the map is scored.
    if (!input.truth.empty() && robot_ate >= robot_dr) all_better = false;
    if (!input.truth.empty() && !input.frames.empty()) {
      const offline::DataLimits limits = offline::data_limits(input);
      std::printf("limits robot %d: dead reckoning reset to the truth at every frame: ATE %.3f m; "
                  "dead-reckoning heading error at the first frame (%.1f s) %.1f deg, 30 s later %.1f deg\n",
                  robot, limits.blind_drift.ate_rmse_m, limits.first_frame_t_s,
                  limits.heading_error_first_frame_rad * kDeg, limits.heading_error_30s_later_rad * kDeg);
    }
  }
  std::printf("MEAN over %d runs: ATE %.3f m (%.3f m after SE(2) alignment), heading %.2f deg, landmarks %.3f m raw / "
              "%.3f m aligned, %.2f s per run\n",
              runs, sum_ate / runs, sum_ate_aligned / runs, sum_head / runs, sum_lm / runs, sum_lma / runs, sum_wall / runs);
  if (!all_better) {
    std::printf("FAIL: some robot's mean ATE is not better than dead reckoning\n");
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mrclam_eval: %s\n", e.what());
    return 1;
  }
}
