// slam_offline: runs the FastSLAM 2.0 core without DDS.
//   slam_offline sim      --config FILE --out-dir DIR [--seed S] [--set K=V] [--optimise] [--write-dataset DIR]
//   slam_offline mrclam   --dataset DIR --robot N --config FILE --out-dir DIR [--seed S] [--set K=V] [--optimise]
//   slam_offline hardware --config FILE --sim-config FILE --out-dir DIR [--duration S] [...]
// Writes DIR/trajectory.csv and DIR/landmarks.csv and prints the evaluation.
// --optimise (any mode): the map optimiser over the whole run after the filter;
// trajectory.csv and landmarks.csv are then its solution, the filter's go to
// filter_trajectory.csv and filter_landmarks.csv, and both are evaluated.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/offline/hardware_input.h"
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"
#include "pixyslam/offline/optimizer_sets.h"
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
#include "pixyslam/offline/optimised_run.h"
#endif
#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/eval/csv_io.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

using namespace pixyslam;

struct Args {
  std::string mode;  // sim, mrclam or hardware
  std::string config;
  std::string out_dir;
  std::string seed;
  std::vector<std::string> sets;  // --set
  bool optimise = false;
  std::string write_dataset;  // sim
  std::string dataset;        // mrclam
  int robot = 0;              // mrclam
  double mrclam_duration_s = 0.0;  // mrclam: 0 = all
  std::string sim_config;     // hardware
  double duration_s = 85.0;   // hardware
};

offline::RunInput sim_input(const sim::WorldRun& run) {
  offline::RunInput in;
  in.initial_pose = run.initial_pose;
  in.start_time_s = 0.0;
  in.odometry = run.odometry;
  in.frames = run.frames;
  in.truth = run.truth;
  for (const sim::Pole& p : run.poles) in.landmarks.push_back({p.id, p.x_m, p.y_m});
  return in;
}

// The simulated recording as MRCLAM robot 1: odometry and camera frames as
// measured, truth at every odometry sample, pole ids shifted so that the
// smallest is above the robots' subject numbers 1..5.
mrclam::RobotData sim_recording(const sim::WorldRun& run) {
  int smallest = 6;
  for (const sim::Pole& p : run.poles) smallest = std::min(smallest, p.id);
  const int shift = 6 - smallest;
  mrclam::RobotData d;
  d.robot = 1;
  for (const slam::OdometrySample& o : run.odometry) d.odometry.push_back({o.t_s, o.v_mps, o.w_radps});
  for (const slam::ObservationFrame& f : run.frames) {
    mrclam::MeasurementFrame frame{f.t_s, {}};
    for (const slam::RangeBearing& z : f.detections) frame.detections.push_back({z.landmark_id + shift, z.range_m, z.bearing_rad});
    d.frames.push_back(std::move(frame));
  }
  d.groundtruth = run.truth;
  for (const sim::Pole& p : run.poles) d.landmarks.push_back({p.id + shift, p.x_m, p.y_m});
  if (shift != 0) std::printf("dataset: landmark subjects are the pole ids + %d\n", shift);
  return d;
}

#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
void print_solve(const offline::OptimisedRun& opt) {
  const map_optimizer::SolveSummary& s = opt.solve;
  std::printf("map optimiser: %zu keyframes, %zu landmarks, %zu factors (%zu observations, %zu invalid); "
              "%s after %d iterations, cost %.1f -> %.1f, solve %.3f s, %.3f s CPU in all; landmark covariances %s\n",
              opt.counters.keyframes, s.landmarks_free, s.residuals, opt.counters.observations,
              opt.counters.observations_invalid, s.converged ? "converged" : "NOT converged", s.iterations,
              s.initial_cost, s.final_cost, s.solve_time_s, opt.result.cpu_time_s,
              opt.landmark_covariances ? "computed" : "rank deficient");
}
#endif

int run(const Args& args) {
  const std::string& config_path = args.config;
  config::YamlReader root = config::YamlReader::from_file(config_path);
  config::YamlReader filter_yaml = root.child("filter");
  slam::FilterOptions options = slam::read_filter_options(filter_yaml);
  std::vector<std::string> overrides;
  overrides.insert(overrides.end(), args.sets.begin(), args.sets.end());
  if (!args.seed.empty()) overrides.push_back("filter.seed=" + args.seed);  // after --set: the flag wins
  // world. (sim) and mrclam. (mrclam) apply to those sections; the rest to filter:.
  const std::vector<std::string> world_sets = parameters::take_section(overrides, "world");
  const std::vector<std::string> mrclam_sets = parameters::take_section(overrides, "mrclam");
  const std::vector<std::string> optimizer_sets = parameters::take_section(overrides, "optimizer");
  const auto set_error = [](const std::invalid_argument& e) { return app::UsageError(std::string("--seed/--set: ") + e.what()); };
  try {
    slam::apply_overrides(options, overrides);
    if (!world_sets.empty() && args.mode != "sim") throw std::invalid_argument(world_sets.front() + ": world. is for slam_offline sim");
    if (!mrclam_sets.empty() && args.mode != "mrclam") {
      throw std::invalid_argument(mrclam_sets.front() + ": mrclam. is for slam_offline mrclam");
    }
    offline::check_optimizer_sets(options, optimizer_sets, args.optimise);
  } catch (const std::invalid_argument& e) {
    throw set_error(e);
  }

  offline::RunInput input;
  std::string title;
  if (args.mode == "hardware") {
    // The estimator's file: only its filter matters offline.
    const std::string& sim_config = args.sim_config;
    const std::string folder = std::filesystem::path(sim_config).parent_path().string();
    robot_sim::RobotSimConfig hw = robot_sim::load_robot_sim_config(
        sim_config, (std::filesystem::path(folder) / "pixy_bridge.yaml").string(),
        (std::filesystem::path(folder) / "encoder_bridge.yaml").string());
    // The estimator's own sections are its business; any other is an error, as in sim and mrclam.
    for (const char* section : {"estimator", "dds"}) {
      if (root.has(section)) root.child(section);
    }
    root.finish();
    // --seed is the filter's: the bytes stay robot_sim's (hardware.seed in --sim-config).
    input = offline::hardware_input(hw, args.duration_s);
    title = "emulated hardware, " + std::to_string(input.landmarks.size()) + " visible poles, " +
            std::to_string(input.frames.size()) + " frames with detections";
  } else if (args.mode == "sim") {
    config::YamlReader world_yaml = root.child("world");
    sim::WorldOptions world = sim::read_world_options(world_yaml);
    root.finish();
    try {
      for (const std::string& a : world_sets) parameters::apply_override(world, sim::world_parameters(), "world", a);
      sim::validate(world);
    } catch (const std::invalid_argument& e) {
      throw set_error(e);
    }
    const sim::WorldRun run = sim::simulate(world);
    input = sim_input(run);
    if (!args.write_dataset.empty()) {
      mrclam::write_robot(args.write_dataset, sim_recording(run));
      std::printf("wrote the recording as robot 1 of the MRCLAM data set %s\n", args.write_dataset.c_str());
    }
    title = "simulated world, " + std::to_string(run.poles.size()) + " poles, " +
            std::to_string(run.frames.size()) + " camera frames";
  } else {
    offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
    root.finish();
    try {
      for (const std::string& a : mrclam_sets) {
        parameters::apply_override(model, offline::mrclam_sensor_parameters(), "mrclam", a);
      }
    } catch (const std::invalid_argument& e) {
      throw set_error(e);
    }
    const std::string& dataset = args.dataset;
    const int robot = args.robot;
    const mrclam::RobotData data = mrclam::load_robot(dataset, robot);
    input = offline::mrclam_input(data, model);
    offline::keep_first_seconds(input, args.mrclam_duration_s);
    std::printf("MRCLAM %s robot %d: %zu odometry rows, %zu frames, landmarks from %s\n", dataset.c_str(), robot,
                data.odometry.size(), data.frames.size(),
                data.landmark_file.empty() ? "nowhere (no landmark file)" : data.landmark_file.c_str());
    std::printf("dropped rows           %zu robot (subjects 1-5 not in the landmark file), %zu unknown barcode\n", data.counts.robot_rows,
                data.counts.unknown_barcode_rows);
    title = "MRCLAM robot " + std::to_string(robot);
  }
  std::printf("filter: %d particles, seed %llu, resample %s\n", options.particles,
              static_cast<unsigned long long>(options.seed), slam::to_string(options.resample_mode).c_str());

#ifndef PIXYSLAM_HAVE_MAP_OPTIMIZER
  if (args.optimise) throw std::runtime_error("--optimise: this build has no map optimiser (built without Ceres)");
#endif
  const std::filesystem::path out = args.out_dir;
  const offline::RunResult result = offline::run_filter(options, input);
  std::filesystem::create_directories(out);
  const auto write = [&out](const std::string& prefix, const offline::RunResult& r) {
    eval::write_trajectory_csv((out / (prefix + "trajectory.csv")).string(), r.trajectory);
    eval::write_landmarks_csv((out / (prefix + "landmarks.csv")).string(), r.landmarks);
    std::printf("wrote %s and %s\n", (out / (prefix + "trajectory.csv")).c_str(),
                (out / (prefix + "landmarks.csv")).c_str());
  };
  offline::print_report(title, offline::evaluate(input, result), result);
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
  if (args.optimise) {
    const offline::OptimisedRun opt = offline::optimise_run(
        options, input, result, map_optimizer::SolveScheduleOptions::at_end_only(), optimizer_sets);
    offline::print_accuracy(title + ", map optimiser", offline::evaluate(input, opt.result));
    print_solve(opt);
    write("filter_", result);
    write("", opt.result);
    return 0;
  }
#endif
  write("", result);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  app::Cli cli{"slam_offline",
               "Runs the FastSLAM 2.0 core without DDS on a simulated world, an MRCLAM robot or the emulated "
               "hardware; writes OUT/trajectory.csv and OUT/landmarks.csv and prints the evaluation."};
  auto common = [&](app::Cli& mode) {
    app::add_config(mode, args.config, "the YAML with the filter: section (and world: in sim mode)");
    mode.option("--out-dir", args.out_dir, "write trajectory.csv and landmarks.csv into DIR").required().type("DIR");
    mode.option("--seed", args.seed, "the filter's seed (filter.seed)").type("S");
    app::add_set(mode, args.sets, "filter.particles=300 (slam_estimator --help lists them; sim also world.KEY=V, "
                                  "mrclam also mrclam.KEY=V, both listed below; with --optimise optimizer.KEY=V, "
                                  "the optimiser's and its solve schedule's keys that map_optimizer --help lists)");
    mode.flag("--optimise",
              args.optimise,
              "also solve the whole run with the map optimiser (Ceres): its solution goes to trajectory.csv and "
              "landmarks.csv, the filter's to filter_trajectory.csv and filter_landmarks.csv");
  };
  app::Cli& sim = cli.subcommand("sim", "the simulated world of the config's world: section");
  common(sim);
  sim.footer("world parameters (world:; path, poles and initial_pose apart):\n" +
             parameters::help_text(sim::world_parameters(), "world"));
  sim.option("--write-dataset", args.write_dataset,
             "also write the recording as robot 1 of an MRCLAM data set in DIR, with its ground truth")
      .type("DIR");
  app::Cli& mrclam = cli.subcommand("mrclam", "one robot of an MRCLAM data set");
  common(mrclam);
  mrclam.footer("MRCLAM sensor model (mrclam:):\n" + parameters::help_text(offline::mrclam_sensor_parameters(), "mrclam"));
  mrclam.option("--dataset", args.dataset, "the data set's folder (e.g. ../shared/data/mrclam/Dataset6)")
      .required()
      .type("DIR");
  mrclam.option("--robot", args.robot, "the robot, 1-5").required().range(mrclam::kFirstRobot, mrclam::kLastRobot).type("N");
  mrclam.option("--duration", args.mrclam_duration_s,
                "only the first S seconds of the recording from the robot's start (default: all; as dataset_bridge "
                "--duration)")
      .non_negative()
      .type("S");
  app::Cli& hardware = cli.subcommand(
      "hardware", "the robot_sim hardware decoded by the bridges' parsers (their configs beside --sim-config)");
  common(hardware);
  hardware.option("--sim-config", args.sim_config, "robot_sim's YAML").required().existing_file().type("FILE");
  hardware.option("--duration", args.duration_s, "seconds of hardware time (default 85; > 0)").positive().type("S");
  if (const auto done = cli.parse(argc, argv)) return *done;
  args.mode = sim.chosen() ? "sim" : mrclam.chosen() ? "mrclam" : "hardware";
  return app::run_main("slam_offline", [&] { return run(args); });
}
