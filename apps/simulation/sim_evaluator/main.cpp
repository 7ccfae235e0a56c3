// sim_evaluator: scores a live run against the simulator's ground truth.
// Subscribes to every topic, counts messages and sequence gaps per topic, and
// when stopped (SIGINT/SIGTERM, e.g. by the launcher) prints the pose ATE RMSE
// (estimate interpolated at the ground-truth times), heading RMSE, landmark
// RMSE raw and aligned, and writes the trajectories to --out-dir. When the map
// optimiser runs (pixyslam/optimised_map), the same for its newest solution
// (keyframes against the truth, its landmarks) and its CPU time.
//   sim_evaluator [--config config/slam_estimator.yaml] [--set dds.KEY=V ...] [--domain N] [--out-dir DIR] [--max-ate M]
//                 [--max-optimised-ratio R] [--verbose]
// Exit code 1 if the ATE exceeds --max-ate or nothing was estimated; with
// --max-optimised-ratio also when no OptimisedMap arrived or its landmark RMSE
// is above R times the filter's (1: at most the filter's).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/newest_stamp.h"
#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::sim_evaluator {
namespace {

double seconds(std::uint64_t stamp_ns) { return static_cast<double>(stamp_ns) * 1e-9; }

// A map's landmarks, each id once (the first): a sample from another
// participant may repeat one, which would leave the map unscorable.
template <class Landmarks>
std::vector<eval::LandmarkPoint> unique_landmarks(const Landmarks& landmarks, std::uint64_t& duplicates) {
  std::vector<eval::LandmarkPoint> out;
  std::set<int> ids;
  for (const auto& l : landmarks) {
    if (ids.insert(l.landmark_id()).second) {
      out.push_back({l.landmark_id(), l.x_m(), l.y_m()});
    } else {
      ++duplicates;
    }
  }
  return out;
}

// MapStates this far outside the ground truth's time span are not scored.
constexpr double kScoredMarginS = 10.0;

// Everything received, under one lock (callbacks come from DDS threads).
struct Received {
  std::mutex mutex;
  std::vector<eval::TimedPose> estimate;
  std::vector<eval::TimedPose> truth;
  std::vector<eval::LandmarkPoint> true_landmarks;
  std::vector<eval::LandmarkPoint> map;
  // Stale MapState and OptimisedMap samples are dropped; one stamped far ahead
  // (any participant can send one) does not stop the rest (dds::NewestStamp).
  dds::NewestStamp map_order, optimised_order;
  std::uint64_t duplicate_landmark_ids = 0;
  double last_update_ms = 0.0;
  std::vector<double> update_ms;
  // The newest OptimisedMap.
  std::size_t optimised_maps = 0;
  std::vector<eval::TimedPose> optimised_keyframes;
  std::vector<eval::LandmarkPoint> optimised_landmarks;
  double optimiser_cpu_s = 0.0;
};

template <class Message>
void print_topic(const dds::Reader<Message>& reader) {
  std::printf("  %-32s %8llu received, %llu lost (sequence gaps)", std::string(dds::MessageTraits<Message>::topic).c_str(),
              static_cast<unsigned long long>(reader.received()), static_cast<unsigned long long>(reader.lost()));
  const std::uint64_t malformed = reader.malformed() + reader.callback_errors();
  if (malformed > 0 || reader.seq_jumps() > 0) {
    std::printf(", %llu malformed (dropped), %llu seq jumps", static_cast<unsigned long long>(malformed),
                static_cast<unsigned long long>(reader.seq_jumps()));
  }
  std::printf("\n");
}

struct Arguments {
  std::string config;
  std::vector<std::string> dds_overrides;  // --set dds.KEY=V, then --domain
  std::string out_dir;
  double max_ate_m = 0.0;
  double max_optimised_ratio = -1.0;  // < 0: not checked
  bool verbose = false;
};

int run(const Arguments& args) {
  dds::DdsOptions dds_options = dds::read_dds_options_file(args.config, dds::default_profiles_file());
  dds::resolve_settings(dds_options, args.dds_overrides);
  if (args.verbose) app::print_effective_configuration("sim_evaluator", dds::to_yaml(dds_options));

  Received r;
  dds::Participant participant(dds_options, "sim_evaluator");
  // One robot's run (dds.robot_id): several robots may share the domain.
  const std::string& robot = dds_options.robot_id;
  dds::Reader<msg::Odometry> odometry(participant, [](const msg::Odometry&) {}, robot);
  dds::Reader<msg::LandmarkObservation> observations(participant, [](const msg::LandmarkObservation&) {}, robot);
  dds::Reader<msg::GroundTruth> truth(participant, [&](const msg::GroundTruth& m) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.truth.push_back({seconds(m.header().stamp_ns()), m.pose().x_m(), m.pose().y_m(), m.pose().theta_rad()});
    if (r.true_landmarks.empty()) r.true_landmarks = unique_landmarks(m.landmarks(), r.duplicate_landmark_ids);
  }, robot);
  dds::Reader<msg::MapState> maps(participant, [&](const msg::MapState& m) {
    std::lock_guard<std::mutex> lock(r.mutex);
    if (!r.map_order.take(m.header().stamp_ns())) return;  // a late joiner's old state
    r.estimate.push_back({seconds(m.header().stamp_ns()), m.mean_pose().x_m(), m.mean_pose().y_m(),
                          m.mean_pose().theta_rad()});
    r.update_ms.push_back(m.update_time_s() * 1e3);
    r.map = unique_landmarks(m.landmarks(), r.duplicate_landmark_ids);
  }, robot);
  dds::Reader<msg::OptimisedMap> optimised(participant, [&](const msg::OptimisedMap& m) {
    std::lock_guard<std::mutex> lock(r.mutex);
    if (!r.optimised_order.take(m.header().stamp_ns())) return;  // an older solution
    ++r.optimised_maps;
    r.optimised_keyframes.clear();
    for (const msg::OptimisedKeyframe& k : m.keyframes()) {
      r.optimised_keyframes.push_back({seconds(k.stamp_ns()), k.pose().x_m(), k.pose().y_m(), k.pose().theta_rad()});
    }
    r.optimised_landmarks = unique_landmarks(m.landmarks(), r.duplicate_landmark_ids);
    r.optimiser_cpu_s = m.cpu_time_s();
  }, robot);
  std::fprintf(stderr, "sim_evaluator: listening on DDS domain %d\n", dds_options.domain_id);
  while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
  }

  std::lock_guard<std::mutex> lock(r.mutex);
  std::printf("sim_evaluator: messages per topic\n");
  print_topic(odometry);
  print_topic(observations);
  print_topic(maps);
  print_topic(truth);
  print_topic(optimised);
  if (r.map_order.time_resets() + r.optimised_order.time_resets() + r.duplicate_landmark_ids > 0) {
    std::printf("sim_evaluator: %llu samples stamped far behind the newest taken (the time went back), %llu repeated "
                "landmark ids dropped\n",
                static_cast<unsigned long long>(r.map_order.time_resets() + r.optimised_order.time_resets()),
                static_cast<unsigned long long>(r.duplicate_landmark_ids));
  }
  // In time order, whatever order the samples came in; estimates stamped far
  // outside the truth's time (made up by another participant) are not scored.
  r.estimate = eval::sorted_by_time(std::move(r.estimate));
  r.truth = eval::sorted_by_time(std::move(r.truth));
  r.optimised_keyframes = eval::sorted_by_time(std::move(r.optimised_keyframes));
  if (!r.truth.empty()) {
    const double from_s = r.truth.front().t_s - kScoredMarginS, to_s = r.truth.back().t_s + kScoredMarginS;
    const std::size_t before = r.estimate.size();
    r.estimate.erase(std::remove_if(r.estimate.begin(), r.estimate.end(),
                                    [&](const eval::TimedPose& p) { return p.t_s < from_s || p.t_s > to_s; }),
                     r.estimate.end());
    if (r.estimate.size() < before) {
      std::printf("sim_evaluator: %zu MapStates stamped more than %.0f s outside the ground truth's time not scored\n",
                  before - r.estimate.size(), kScoredMarginS);
    }
  }
  if (r.estimate.empty() || r.truth.empty()) {
    std::printf("sim_evaluator: no %s received: nothing to evaluate\n", r.estimate.empty() ? "MapState" : "GroundTruth");
    return 1;
  }
  const eval::TrajectoryErrors pose = eval::compare_trajectory(r.estimate, r.truth);
  const eval::LandmarkErrors landmarks = eval::compare_landmarks(r.map, r.true_landmarks);
  std::printf("sim_evaluator: %zu estimates over %.1f s, %zu ground-truth poses compared\n", r.estimate.size(),
              r.estimate.back().t_s - r.estimate.front().t_s, pose.samples);
  std::printf("  pose ATE RMSE        %.3f m (max %.3f m at %.1f s, after rigid alignment %.3f m)\n",
              pose.ate_rmse_m, pose.max_position_error_m, pose.max_position_error_t_s - r.estimate.front().t_s,
              pose.ate_rmse_aligned_m);
  std::printf("  heading RMSE         %.2f deg\n", pose.heading_rmse_rad * 180.0 / M_PI);
  std::printf("  landmarks            %zu mapped of %zu, RMSE %.3f m raw, %.3f m aligned\n", landmarks.matched,
              r.true_landmarks.size(), landmarks.rmse_m, landmarks.rmse_aligned_m);

  bool optimised_ok = false;
  if (r.optimised_maps > 0 && !r.optimised_keyframes.empty()) {
    const eval::TrajectoryErrors opt_pose = eval::compare_trajectory(r.optimised_keyframes, r.truth);
    const eval::LandmarkErrors opt_landmarks = eval::compare_landmarks(r.optimised_landmarks, r.true_landmarks);
    std::printf("  map optimiser        %zu solutions; newest: %zu keyframes, pose ATE %.3f m, heading RMSE %.2f deg; "
                "landmarks %zu mapped, RMSE %.3f m raw, %.3f m aligned; optimiser CPU %.3f s\n",
                r.optimised_maps, r.optimised_keyframes.size(), opt_pose.ate_rmse_m,
                opt_pose.heading_rmse_rad * 180.0 / M_PI, opt_landmarks.matched, opt_landmarks.rmse_m,
                opt_landmarks.rmse_aligned_m, r.optimiser_cpu_s);
    optimised_ok = opt_landmarks.matched > 0 &&
                   opt_landmarks.rmse_m <= args.max_optimised_ratio * landmarks.rmse_m;
  } else {
    std::printf("  map optimiser        no OptimisedMap received\n");
  }

  if (!args.out_dir.empty()) {
    const std::string& out = args.out_dir;
    std::filesystem::create_directories(out);
    eval::write_trajectory_csv(out + "/trajectory.csv", r.estimate);
    eval::write_trajectory_csv(out + "/ground_truth.csv", r.truth);
    std::printf("  trajectories         %s/trajectory.csv, %s/ground_truth.csv\n", out.c_str(), out.c_str());
  }
  if (args.max_ate_m > 0.0 && !(pose.ate_rmse_m <= args.max_ate_m)) {
    std::printf("sim_evaluator: ATE %.3f m exceeds the limit %.3f m\n", pose.ate_rmse_m, args.max_ate_m);
    return 1;
  }
  if (args.max_optimised_ratio >= 0.0 && !optimised_ok) {
    std::printf("sim_evaluator: the map optimiser's landmarks are missing or above %.2f times the filter's RMSE\n",
                args.max_optimised_ratio);
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace pixyslam::sim_evaluator

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  sim_evaluator::Arguments args;
  app::Cli cli{"sim_evaluator", "Scores a live run against the simulator's ground truth when stopped (SIGINT/SIGTERM): pose ATE, "
               "heading and landmark RMSE of the filter and of the map optimiser's newest solution."};
  cli.option("--config", args.config, "a YAML with a dds: mapping (e.g. config/slam_estimator.yaml)")
      .existing_file()
      .type("FILE");
  std::vector<std::string> sets, domain;
  app::add_set(cli, sets, "dds.participant_profile=lan_multicast");
  app::add_domain(cli, domain);
  cli.footer("DDS settings for --set (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
             parameters::help_text(pixyslam::dds::dds_parameters(), "dds") +
             "Exit status: 0 scored, 1 ATE above --max-ate, nothing estimated or no OptimisedMap as required, 2 "
             "command-line or config error.");
  cli.option("--out-dir", args.out_dir, "write DIR/trajectory.csv and DIR/ground_truth.csv").type("DIR");
  cli.option("--max-ate", args.max_ate_m, "exit 1 if the pose ATE is above M (0: no check)")
      .type("M")
      .non_negative();
  cli.option("--max-optimised-ratio", args.max_optimised_ratio,
                 "exit 1 if no OptimisedMap arrived or its landmark RMSE is above R times the filter's")
      .type("R")
      .non_negative();
  app::add_verbose(cli, args.verbose);
  if (const auto done = cli.parse(argc, argv)) return *done;
  args.dds_overrides = sets;
  args.dds_overrides.insert(args.dds_overrides.end(), domain.begin(), domain.end());
  return app::run_main("sim_evaluator", [&] { return sim_evaluator::run(args); });
}
