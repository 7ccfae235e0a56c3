#include "pixyslam/offline/offline_run.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/eval/rigid_alignment.h"

namespace pixyslam::offline {

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

RunResult run_filter(const slam::FilterOptions& options, const RunInput& input, const StepHook& after_step) {
  RunResult result;
  slam::FastSlam2 filter(options, slam::PoseGaussian{input.initial_pose, input.initial_pose_cov});
  if (!input.prior_map.empty()) filter.set_prior_map(input.prior_map);
  slam::PoseGaussian dead_reckoning{input.initial_pose, Eigen::Matrix3d::Zero()};
  slam::OdometrySample control{input.start_time_s, 0.0, 0.0};
  double dr_time = input.start_time_s;

  auto record = [&](double t) {
    const slam::PoseEstimate e = filter.pose_estimate();
    result.trajectory.push_back({t, e.mean.x(), e.mean.y(), e.mean.z()});
    result.covariance.push_back(e.cov);
    result.dead_reckoning.push_back(
        {t, dead_reckoning.mean.x(), dead_reckoning.mean.y(), dead_reckoning.mean.z()});
    if (after_step) after_step(filter, t);
  };
  auto advance_dead_reckoning = [&](double t) {
    if (t > dr_time) dead_reckoning.mean = slam::move(dead_reckoning.mean, control.v_mps, control.w_radps, t - dr_time);
    dr_time = std::max(dr_time, t);
  };

  const std::size_t steps = input.odometry.size() + input.frames.size();
  result.trajectory.reserve(steps);
  result.covariance.reserve(steps);
  result.dead_reckoning.reserve(steps);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  filter.add_odometry(control);  // sets the filter's clock to the start time
  for_each_step(
      input,
      [&](const slam::OdometrySample& s, bool step) {
        if (!step) {
          control = s;
          filter.add_odometry(control);
          return;
        }
        advance_dead_reckoning(s.t_s);
        control = s;
        filter.add_odometry(s);
        record(s.t_s);
      },
      [&](const slam::ObservationFrame& f) {
        advance_dead_reckoning(f.t_s);
        filter.add_observations(f);
        record(f.t_s);
      });
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.cpu_time_s = thread_cpu_seconds() - cpu_start;
  for (const slam::LandmarkEstimate& lm : filter.landmarks_of_best()) {
    result.landmarks.push_back({lm.id, lm.mean.x(), lm.mean.y(), lm.cov(0, 0), lm.cov(0, 1), lm.cov(1, 1)});
  }
  result.counters = filter.counters();
  result.final_effective_sample_size = filter.pose_estimate().effective_sample_size;
  return result;
}

void for_each_step(const RunInput& input, const std::function<void(const slam::OdometrySample&, bool step)>& on_odometry,
                   const std::function<void(const slam::ObservationFrame&)>& on_frame) {
  std::size_t i = 0;
  std::size_t k = 0;
  while (i < input.odometry.size() || k < input.frames.size()) {
    const bool take_odometry =
        k == input.frames.size() ||
        (i < input.odometry.size() && input.odometry[i].t_s <= input.frames[k].t_s);
    if (take_odometry) {
      const slam::OdometrySample& s = input.odometry[i++];
      if (s.t_s < input.start_time_s) {
        on_odometry({input.start_time_s, s.v_mps, s.w_radps}, false);
      } else {
        on_odometry(s, true);
      }
    } else {
      const slam::ObservationFrame& f = input.frames[k++];
      if (f.t_s >= input.start_time_s) on_frame(f);
    }
  }
}

Report evaluate(const RunInput& input, const RunResult& result) {
  Report r;
  if (!input.truth.empty() && !result.trajectory.empty()) {
    r.has_truth = true;
    r.filter = eval::compare_trajectory(result.trajectory, input.truth);
    r.dead_reckoning = eval::compare_trajectory(result.dead_reckoning, input.truth);
    r.nees = trajectory_nees(result.trajectory, result.covariance, eval::sorted_by_time(input.truth));
  }
  if (!input.landmarks.empty() && !result.landmarks.empty()) {
    r.has_landmarks = true;
    std::vector<eval::LandmarkPoint> est;
    for (const eval::LandmarkRow& row : result.landmarks) est.push_back({row.id, row.x_m, row.y_m});
    r.landmarks = eval::compare_landmarks(est, input.landmarks);
  }
  return r;
}

namespace {

// The truth pose nearest to t (truth sorted by time, not empty).
const eval::TimedPose& truth_at(const std::vector<eval::TimedPose>& truth, double t) {
  auto it = std::lower_bound(truth.begin(), truth.end(), t,
                             [](const eval::TimedPose& p, double time) { return p.t_s < time; });
  if (it == truth.end()) return truth.back();
  if (it != truth.begin() && t - std::prev(it)->t_s < it->t_s - t) --it;
  return *it;
}

}  // namespace

DataLimits data_limits(const RunInput& input) {
  std::vector<eval::TimedPose> truth = input.truth;
  std::sort(truth.begin(), truth.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  std::vector<double> frame_times;
  for (const slam::ObservationFrame& f : input.frames) {
    if (!f.detections.empty() && f.t_s >= input.start_time_s) frame_times.push_back(f.t_s);
  }
  std::sort(frame_times.begin(), frame_times.end());
  if (truth.empty() || frame_times.empty()) {
    throw std::invalid_argument("data_limits: needs ground truth and at least one camera frame");
  }
  // Dead reckoning from the start pose through time-ordered odometry and frames;
  // `reset` puts the pose on the truth at every frame.
  const auto drive = [&](bool reset) {
    std::vector<eval::TimedPose> path;
    slam::Pose2 x = input.initial_pose;
    slam::OdometrySample control{input.start_time_s, 0.0, 0.0};
    double t = input.start_time_s;
    const auto advance = [&](double to) {
      if (to > t) x = slam::move(x, control.v_mps, control.w_radps, to - t);
      t = std::max(t, to);
    };
    std::size_t i = 0, k = 0;
    while (i < input.odometry.size() || k < frame_times.size()) {
      if (k == frame_times.size() || (i < input.odometry.size() && input.odometry[i].t_s <= frame_times[k])) {
        const slam::OdometrySample& s = input.odometry[i++];
        advance(s.t_s);
        control = s;
      } else {
        advance(frame_times[k++]);
        if (reset) {
          const eval::TimedPose& g = truth_at(truth, t);
          x = slam::Pose2(g.x_m, g.y_m, g.theta_rad);
        }
      }
      path.push_back({t, x.x(), x.y(), x.z()});
    }
    return path;
  };
  DataLimits limits;
  limits.blind_drift = eval::compare_trajectory(drive(true), truth);
  // Heading error of pure dead reckoning at its first step at or after at_s.
  const std::vector<eval::TimedPose> dead_reckoning = drive(false);
  const auto heading_error_at = [&](double at_s) {
    auto it = std::lower_bound(dead_reckoning.begin(), dead_reckoning.end(), at_s,
                               [](const eval::TimedPose& p, double time) { return p.t_s < time; });
    const eval::TimedPose& x = it == dead_reckoning.end() ? dead_reckoning.back() : *it;
    return slam::wrap_angle(x.theta_rad - truth_at(truth, x.t_s).theta_rad);
  };
  limits.first_frame_t_s = frame_times.front() - input.start_time_s;
  limits.heading_error_first_frame_rad = heading_error_at(frame_times.front());
  limits.heading_error_30s_later_rad = heading_error_at(frame_times.front() + 30.0);
  return limits;
}

void print_accuracy(const std::string& title, const Report& r) {
  constexpr double kDeg = 180.0 / M_PI;
  std::printf("== %s\n", title.c_str());
  if (r.has_truth) {
    std::printf("pose ATE RMSE          %.3f m   (dead reckoning %.3f m)\n", r.filter.ate_rmse_m,
                r.dead_reckoning.ate_rmse_m);
    std::printf("heading RMSE           %.2f deg (dead reckoning %.2f deg)\n", r.filter.heading_rmse_rad * kDeg,
                r.dead_reckoning.heading_rmse_rad * kDeg);
    std::printf("pose ATE after SE(2) alignment %.3f m, max position error %.3f m, %zu truth samples\n",
                r.filter.ate_rmse_aligned_m, r.filter.max_position_error_m, r.filter.samples);
    if (r.nees.steps > 0) {
      std::printf("pose NEES (3 dof)      mean %.2f (ideal 3), %.1f %% inside [%.4f, %.4f] (ideal 95), %.1f %% below "
                  "%.4f (ideal 97.5), %zu steps, %zu singular skipped\n",
                  r.nees.mean(), 100.0 * r.nees.fraction_inside(), kNees3Lower95, kNees3Upper95,
                  100.0 * r.nees.fraction_below_upper(), kNees3Upper95, r.nees.steps, r.nees.singular);
    }
  } else {
    std::printf("no robot ground truth: pose error not evaluated\n");
  }
  if (r.has_landmarks) {
    std::printf("landmark RMSE          %.3f m raw, %.3f m aligned (%zu matched, %zu missing, %zu extra)\n",
                r.landmarks.rmse_m, r.landmarks.rmse_aligned_m, r.landmarks.matched, r.landmarks.missing,
                r.landmarks.extra);
  }
}

void print_report(const std::string& title, const Report& r, const RunResult& res) {
  print_accuracy(title, r);
  const slam::FilterCounters& c = res.counters;
  std::printf("observations           %llu used, %llu new landmark, %llu gated, %llu invalid\n",
              static_cast<unsigned long long>(c.observations_used),
              static_cast<unsigned long long>(c.observations_new_landmark),
              static_cast<unsigned long long>(c.observations_gated),
              static_cast<unsigned long long>(c.observations_invalid));
  std::printf("filter                 %llu odometry samples, %llu frames, %llu resamples, final N_eff %.1f\n",
              static_cast<unsigned long long>(c.odometry_samples), static_cast<unsigned long long>(c.frames),
              static_cast<unsigned long long>(c.resamples), res.final_effective_sample_size);
  std::printf("wall time              %.2f s\n", res.wall_time_s);
}

RunInput restart_at_truth(const RunInput& input, double start_s) {
  const std::optional<eval::TimedPose> g =
      interpolate_pose(eval::sorted_by_time(input.truth), start_s, std::numeric_limits<double>::infinity());
  if (!g) throw std::invalid_argument("restart_at_truth: no ground truth at the start time");
  RunInput restarted = input;
  restarted.initial_pose = slam::Pose2(g->x_m, g->y_m, g->theta_rad);
  restarted.start_time_s = start_s;
  return restarted;
}

RunInput resumed_after(const RunInput& input, double checkpoint_t_s, const slam::MapCheckpoint& checkpoint,
                       double gap_s, double max_speed_mps, double max_turn_rate_radps, double control_timeout_s) {
  RunInput resumed = input;
  const slam::PoseGaussian pose =
      slam::resume_pose(checkpoint, gap_s, max_speed_mps, max_turn_rate_radps, control_timeout_s);
  resumed.initial_pose = pose.mean;
  resumed.initial_pose_cov = pose.cov;
  resumed.prior_map = checkpoint.landmarks;
  resumed.start_time_s = checkpoint_t_s + gap_s;
  resumed.odometry.erase(std::remove_if(resumed.odometry.begin(), resumed.odometry.end(),
                                        [&](const slam::OdometrySample& o) { return o.t_s < resumed.start_time_s; }),
                         resumed.odometry.end());
  return resumed;
}

}  // namespace pixyslam::offline

namespace pixyslam::offline {

const parameters::Table<MrclamSensorModel>& mrclam_sensor_parameters() {
  using O = MrclamSensorModel;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("range_scale", 0.5, 2.0, "", "range_true = range / (range_scale * cos(bearing)^exponent)",
                 [](O& o) -> double& { return o.range_scale; }),
      P::real<O>("range_cos_bearing_exponent", 0.0, 3.0, "", "... the exponent (off-axis shortening)",
                 [](O& o) -> double& { return o.range_cos_bearing_exponent; }),
      P::real<O>("odometry_delay_s", -2.0, 2.0, "s", "command-to-motion lag", [](O& o) -> double& { return o.odometry_delay_s; }),
      P::real<O>("speed_scale", 0.5, 2.0, "", "forward speed = commanded * max(0, speed_scale - loss * |turn rate|)",
                 [](O& o) -> double& { return o.speed_scale; }),
      P::real<O>("speed_loss_per_radps", 0.0, 10.0, "s/rad", "... the loss per rad/s of commanded turn rate",
                 [](O& o) -> double& { return o.speed_loss_per_radps; }),
  };
  return table;
}

MrclamSensorModel read_mrclam_sensor_model(config::YamlReader& root) {
  MrclamSensorModel m;
  if (!root.has("mrclam")) return m;
  config::YamlReader y = root.child("mrclam");
  config::read_parameters(y, mrclam_sensor_parameters(), m);
  y.finish();
  return m;
}

RunInput mrclam_input(const mrclam::RobotData& d, const MrclamSensorModel& model) {
  RunInput in;
  in.truth = d.groundtruth;
  in.landmarks = d.landmarks;
  if (!d.groundtruth.empty()) {
    const eval::TimedPose& g = d.groundtruth.front();
    in.initial_pose = slam::Pose2(g.x_m, g.y_m, g.theta_rad);
    in.start_time_s = g.t_s;
  } else {
    in.start_time_s = d.odometry.empty() ? 0.0 : d.odometry.front().t_s;
  }
  for (const mrclam::OdometryRow& o : d.odometry) {
    const double speed_factor = std::max(0.0, model.speed_scale - model.speed_loss_per_radps * std::abs(o.w_radps));
    in.odometry.push_back({o.t_s + model.odometry_delay_s, o.v_mps * speed_factor, o.w_radps});
  }
  for (const mrclam::MeasurementFrame& f : d.frames) in.frames.push_back(mrclam_frame(f, model));
  return in;
}

void keep_first_seconds(RunInput& input, double duration_s) {
  if (duration_s <= 0.0) return;
  const double end_s = input.start_time_s + duration_s;
  erase_after(input.truth, end_s);
  erase_after(input.odometry, end_s);
  erase_after(input.frames, end_s);
}

slam::ObservationFrame mrclam_frame(const mrclam::MeasurementFrame& f, const MrclamSensorModel& model) {
  slam::ObservationFrame frame{f.t_s, {}};
  for (const mrclam::Detection& det : f.detections) {
    slam::RangeBearing z;
    z.landmark_id = det.subject;
    z.range_m = det.range_m / (model.range_scale *
                               std::pow(std::cos(det.bearing_rad), model.range_cos_bearing_exponent));
    z.bearing_rad = det.bearing_rad;
    frame.detections.push_back(z);
  }
  return frame;
}

}  // namespace pixyslam::offline
