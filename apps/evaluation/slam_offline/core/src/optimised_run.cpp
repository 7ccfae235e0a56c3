#include "pixyslam/offline/optimised_run.h"

#include <chrono>
#include <limits>

namespace pixyslam::offline {

map_optimizer::MapOptimizerOptions optimizer_options(const slam::FilterOptions& options,
                                                     const std::vector<std::string>& optimizer_sets,
                                                     map_optimizer::SolveScheduleOptions& schedule) {
  map_optimizer::MapOptimizerOptions o = map_optimizer::MapOptimizerOptions::from_filter(options);
  for (const std::string& a : optimizer_sets) map_optimizer::apply_optimizer_override(o, schedule, a);
  return o;
}

OptimisedRun optimise_run(const slam::FilterOptions& options, const RunInput& input, const RunResult& filter,
                          const map_optimizer::SolveScheduleOptions& schedule,
                          const std::vector<std::string>& optimizer_sets) {
  OptimisedRun out;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  out.schedule = schedule;
  map_optimizer::MapOptimizer optimizer(optimizer_options(options, optimizer_sets, out.schedule), input.initial_pose,
                                        input.start_time_s);
  for (const eval::LandmarkRow& row : filter.landmarks) optimizer.set_landmark_guess(row.id, {row.x_m, row.y_m});
  optimizer.add_odometry({input.start_time_s, 0.0, 0.0});
  std::vector<map_optimizer::MapOptimizer::PoseAnchor> anchors;
  std::vector<double> times;
  anchors.reserve(filter.trajectory.size());
  times.reserve(filter.trajectory.size());
  map_optimizer::SolveSchedule due(out.schedule, input.start_time_s);
  auto record = [&](double t) {
    anchors.push_back(optimizer.anchor_now());
    times.push_back(t);
    const map_optimizer::SolveKind kind = due.due(t);
    switch (kind) {
      case map_optimizer::SolveKind::kWhole: out.whole_solves.push_back(optimizer.solve()); break;
      case map_optimizer::SolveKind::kWindow:
        out.window_solves.push_back(optimizer.solve(out.schedule.window_keyframes));
        break;
      case map_optimizer::SolveKind::kNone: return;
    }
    const std::vector<map_optimizer::SolveSummary>& done =
        kind == map_optimizer::SolveKind::kWhole ? out.whole_solves : out.window_solves;
    due.solved(kind, t, done.back().solve_time_s);
  };
  for_each_step(
      input,
      [&](const slam::OdometrySample& s, bool step) {
        optimizer.add_odometry(s);
        if (step) record(s.t_s);
      },
      [&](const slam::ObservationFrame& f) {
        // The filter's pose after this step, where the two agree on the steps.
        std::optional<slam::Pose2> guess;
        const std::size_t step = anchors.size();
        if (step < filter.trajectory.size() && filter.trajectory[step].t_s == f.t_s) {
          const eval::TimedPose& p = filter.trajectory[step];
          guess = slam::Pose2(p.x_m, p.y_m, p.theta_rad);
        }
        optimizer.add_frame(f, guess);
        record(f.t_s);
      });
  out.solve = optimizer.solve();
  out.landmark_covariances = optimizer.compute_landmark_covariances();
  out.counters = optimizer.counters();

  RunResult& r = out.result;
  r.trajectory.reserve(anchors.size());
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    const slam::Pose2 p = optimizer.pose_of(anchors[i]);
    r.trajectory.push_back({times[i], p.x(), p.y(), p.z()});
  }
  r.covariance.assign(r.trajectory.size(), Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  r.dead_reckoning = filter.dead_reckoning;
  for (const map_optimizer::LandmarkSolution& lm : optimizer.landmarks()) {
    r.landmarks.push_back({lm.id, lm.mean.x(), lm.mean.y(), lm.cov(0, 0), lm.cov(0, 1), lm.cov(1, 1)});
  }
  r.counters = filter.counters;
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu_time_s = thread_cpu_seconds() - cpu_start;
  return out;
}

}  // namespace pixyslam::offline
