// sim_evaluator: scores a live run against the simulator's ground truth.
// Subscribes to every topic, counts messages and sequence gaps per topic, and
// when stopped (SIGINT/SIGTERM, e.g. by the launcher) prints the pose ATE RMSE
// (estimate interpolated at the ground-truth times), heading RMSE, landmark
// RMSE raw and aligned, and writes the trajectories to --out.
//   sim_evaluator --dds-config config/slam_estimator.yaml [--out DIR] [--max-ate M]
// Exit code 3 if the ATE exceeds --max-ate or nothing was estimated.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::sim_evaluator {
namespace {

double seconds(std::uint64_t stamp_ns) { return static_cast<double>(stamp_ns) * 1e-9; }

// Everything received, under one lock (callbacks come from DDS threads).
struct Received {
  std::mutex mutex;
  std::vector<eval::TimedPose> estimate;
  std::vector<eval::TimedPose> truth;
  std::vector<eval::LandmarkPoint> true_landmarks;
  std::vector<eval::LandmarkPoint> map;
  double last_update_ms = 0.0;
  std::vector<double> update_ms;
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

int run(const app::CommandLine& args) {
  const dds::DdsOptions dds_options = dds::read_dds_options_file(args.get("dds-config"), "");

  Received r;
  dds::Participant participant(dds_options, "sim_evaluator");
  dds::Reader<msg::Odometry> odometry(participant, [](const msg::Odometry&) {});
  dds::Reader<msg::LandmarkObservation> observations(participant, [](const msg::LandmarkObservation&) {});
  dds::Reader<msg::GroundTruth> truth(participant, [&](const msg::GroundTruth& m) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.truth.push_back({seconds(m.header().stamp_ns()), m.pose().x_m(), m.pose().y_m(), m.pose().theta_rad()});
    if (r.true_landmarks.empty()) {
      for (const msg::TrueLandmark& l : m.landmarks()) r.true_landmarks.push_back({l.landmark_id(), l.x_m(), l.y_m()});
    }
  });
  dds::Reader<msg::MapState> maps(participant, [&](const msg::MapState& m) {
    std::lock_guard<std::mutex> lock(r.mutex);
    const double t = seconds(m.header().stamp_ns());
    if (!r.estimate.empty() && t < r.estimate.back().t_s) return;  // a late joiner's old state
    r.estimate.push_back({t, m.mean_pose().x_m(), m.mean_pose().y_m(), m.mean_pose().theta_rad()});
    r.update_ms.push_back(m.update_time_s() * 1e3);
    r.map.clear();
    for (const msg::LandmarkEstimate& l : m.landmarks()) r.map.push_back({l.landmark_id(), l.x_m(), l.y_m()});
  });
  std::fprintf(stderr, "sim_evaluator: listening on DDS domain %d\n", dds_options.domain_id);
  while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
  }

  std::lock_guard<std::mutex> lock(r.mutex);
  std::printf("sim_evaluator: messages per topic\n");
  print_topic(odometry);
  print_topic(observations);
  print_topic(maps);
  print_topic(truth);
  if (r.estimate.empty() || r.truth.empty()) {
    std::printf("sim_evaluator: no %s received: nothing to evaluate\n", r.estimate.empty() ? "MapState" : "GroundTruth");
    return 3;
  }
  const eval::TrajectoryErrors pose = eval::compare_trajectory(r.estimate, r.truth);
  const eval::LandmarkErrors landmarks = eval::compare_landmarks(r.map, r.true_landmarks);
  std::printf("sim_evaluator: %zu estimates over %.1f s, %zu ground-truth poses compared\n", r.estimate.size(),
              r.estimate.back().t_s - r.estimate.front().t_s, pose.samples);
  std::printf("  pose ATE RMSE        %.3f m (max %.3f m, after rigid alignment %.3f m)\n", pose.ate_rmse_m,
              pose.max_position_error_m, pose.ate_rmse_aligned_m);
  std::printf("  heading RMSE         %.2f deg\n", pose.heading_rmse_rad * 180.0 / M_PI);
  std::printf("  landmarks            %zu mapped of %zu, RMSE %.3f m raw, %.3f m aligned\n", landmarks.matched,
              r.true_landmarks.size(), landmarks.rmse_m, landmarks.rmse_aligned_m);

  if (args.has("out")) {
    const std::string out = args.get("out");
    std::filesystem::create_directories(out);
    eval::write_trajectory_csv(out + "/trajectory.csv", r.estimate);
    eval::write_trajectory_csv(out + "/ground_truth.csv", r.truth);
    std::printf("  trajectories         %s/trajectory.csv, %s/ground_truth.csv\n", out.c_str(), out.c_str());
  }
  const double max_ate = args.number("max-ate", 0.0);
  if (max_ate > 0.0 && !(pose.ate_rmse_m <= max_ate)) {
    std::printf("sim_evaluator: ATE %.3f m exceeds the limit %.3f m\n", pose.ate_rmse_m, max_ate);
    return 3;
  }
  return 0;
}

}  // namespace
}  // namespace pixyslam::sim_evaluator

int main(int argc, char** argv) {
  pixyslam::app::StopSignal::install();
  return pixyslam::app::run_main("sim_evaluator", [&] {
    const pixyslam::app::CommandLine args(argc, argv, {"dds-config", "out", "max-ate"});
    if (args.help()) {
      std::puts("usage: sim_evaluator --dds-config FILE [--out DIR] [--max-ate M]");
      return 0;
    }
    return pixyslam::sim_evaluator::run(args);
  });
}
