// mrclam_eval: the accuracy table of the FastSLAM core on MRCLAM, one parameter
// set for every robot, several seeds per robot.
//   mrclam_eval --dataset DIR --config FILE [--robots 1,2,3,4,5] [--seeds 1,2,3]
//               [--association known_id|maximum_likelihood] [--segments SECONDS] [--loro]
//               [--blind-return] [--resume GAP_S] [--optimise] [--set filter.KEY=V|mrclam.KEY=V|optimizer.KEY=V ...]
// --association maximum_likelihood withholds the landmark ids from the filter
// (the landmark columns then match nothing by id; ATE and heading still count).
// Every run also reports the pose NEES against the truth (3 dof, ideal mean 3).
// --segments SECONDS adds, per robot with ground truth and seed, runs restarted
// from the ground-truth pose every SECONDS s (each start keeping at least SECONDS
// s of truth after it), each running to the end of the robot's data: one line
// per segment, then count, mean, median, p90 and worst ATE and heading RMSE and
// the pooled NEES per robot and over all segments (docs/mrclam.md).
// --loro (leave one robot out) adds, per robot of --robots with ground truth:
// the `mrclam:` corrections fitted (pixyslam/mrclam/mrclam_fit.h) on the
// OTHER robots of the data set with ground truth (of 1..5, whatever --robots
// says), then the filter on this robot with the config's filter options and
// each seed, with the fitted corrections, the config's `mrclam:` values (the
// main table's runs) and neutral corrections (1, 0, 0, 1, 0): ATE and heading
// RMSE of each, per robot (means over the seeds) and the mean over robots. The
// fit on all robots with ground truth is printed first. With --segments, the
// segment statistics of the three corrections per robot too.
// --blind-return adds, per robot with ground truth and seed, the blind-stretch
// cases of blind_return.h restarted from the truth every 60 s (the heading bias
// alternating in sign): heading error at the return, after it and at the end
// (docs/mrclam.md, "Blind stretch and return").
// --resume GAP_S adds, per robot with ground truth and seed, the estimator
// killed every 60 s and restarted GAP_S s later from a checkpoint taken then
// (slam::resume_pose; the gap's odometry lost): the ATE and heading RMSE from
// the restart to the end, beside the uninterrupted run's over the same time and
// a resume from the saved pose alone (docs/robustness.md).
// --optimise adds, to every full run and segment (and the LORO runs with the
// held-out fit), the map optimiser over the whole run after the filter
// (optimised_run.h): its ATE, heading RMSE and landmark errors beside the filter's.
// --out-dir DIR writes the numbers behind the tables as CSV for plots
// (scripts/plot_results.py): runs.csv (one row per full run), segments.csv (one
// per segment start) and errors_robotR_seedS.csv (per truth pose of a full run:
// time since the robot's first truth pose, position and heading error of the
// filter and of dead reckoning).
// Exit codes: 0 done, 77 dataset folder absent (skip), 1 error or a robot's
// mean ATE not better than dead reckoning, 2 command-line or config error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/offline/blind_return.h"
#include "pixyslam/fleet_map/map_fusion.h"
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/mrclam/mrclam_fit.h"
#include "pixyslam/offline/offline_run.h"
#include "pixyslam/offline/optimizer_sets.h"
#include "pixyslam/slam/map_checkpoint.h"
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
#include "pixyslam/offline/optimised_run.h"
#endif
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"
#include "pixyslam/offline/segment_eval.h"

namespace {

using namespace pixyslam;

// --optimise, with the optimizer. section of --set.
struct OptimiseRequest {
  bool on = false;
  std::vector<std::string> sets;
  explicit operator bool() const { return on; }
};

// The map optimiser's solution of a filter run, when asked for (--optimise).
std::optional<offline::RunResult> optimised(const OptimiseRequest& optimise, const slam::FilterOptions& options,
                                            const offline::RunInput& input, const offline::RunResult& filter) {
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
  if (optimise) {
    return offline::optimise_run(options, input, filter, map_optimizer::SolveScheduleOptions::at_end_only(),
                                 optimise.sets)
        .result;
  }
#else
  (void)options, (void)input, (void)filter;
  if (optimise) throw std::runtime_error("--optimise: this build has no map optimiser (built without Ceres)");
#endif
  return std::nullopt;
}

// One restarted run of --segments.
struct Segment {
  int robot = 0;
  int seed = 0;
  double start_s = 0.0;   // since the robot's first truth pose
  double length_s = 0.0;  // to the end of its trajectory
  eval::TrajectoryErrors errors;
  offline::NeesStats nees;
  std::optional<eval::TrajectoryErrors> optimised;  // --optimise
};

void print_nees(const char* label, const offline::NeesStats& n) {
  if (n.steps + n.singular == 0) return;
  std::printf("%s NEES mean %.2f (ideal 3), %.1f %% inside [%.4f, %.4f] (ideal 95), %.1f %% below %.4f "
              "(ideal 97.5); %zu steps, %zu singular skipped\n",
              label, n.mean(), 100.0 * n.fraction_inside(), offline::kNees3Lower95, offline::kNees3Upper95,
              100.0 * n.fraction_below_upper(), offline::kNees3Upper95, n.steps, n.singular);
}

// count, mean, median, p90, worst of ATE and heading, and the pooled NEES.
void print_segment_summary(const std::string& label, const std::vector<Segment>& segments) {
  constexpr double kDeg = 180.0 / M_PI;
  std::vector<double> ate, heading;
  offline::NeesStats nees;
  for (const Segment& s : segments) {
    ate.push_back(s.errors.ate_rmse_m);
    heading.push_back(s.errors.heading_rmse_rad * kDeg);
    nees.merge(s.nees);
  }
  const offline::Summary a = offline::summarize(ate), h = offline::summarize(heading);
  std::printf("%s: %zu segments, ATE mean %.3f median %.3f p90 %.3f worst %.3f m; "
              "heading RMSE mean %.2f median %.2f p90 %.2f worst %.2f deg\n",
              label.c_str(), a.count, a.mean, a.median, a.p90, a.max, h.mean, h.median, h.p90, h.max);
  print_nees((label + ":").c_str(), nees);
  std::vector<double> opt_ate, opt_heading;
  for (const Segment& s : segments) {
    if (!s.optimised) continue;
    opt_ate.push_back(s.optimised->ate_rmse_m);
    opt_heading.push_back(s.optimised->heading_rmse_rad * kDeg);
  }
  if (opt_ate.empty()) return;
  const offline::Summary oa = offline::summarize(opt_ate), oh = offline::summarize(opt_heading);
  std::printf("%s, map optimiser: %zu segments, ATE mean %.3f median %.3f p90 %.3f worst %.3f m; "
              "heading RMSE mean %.2f median %.2f p90 %.2f worst %.2f deg\n",
              label.c_str(), oa.count, oa.mean, oa.median, oa.p90, oa.max, oh.mean, oh.median, oh.p90, oh.max);
}

// The runs of one robot and seed restarted from the truth every every_s seconds.
std::vector<Segment> run_segments(const slam::FilterOptions& options, const offline::RunInput& input, int robot,
                                  double every_s, const OptimiseRequest& optimise) {
  const std::vector<eval::TimedPose> truth = eval::sorted_by_time(input.truth);
  std::vector<Segment> out;
  for (double start : offline::segment_starts(truth, every_s)) {
    const offline::RunInput restarted = offline::restart_at_truth(input, start);
    const offline::RunResult res = offline::run_filter(options, restarted);
    if (res.trajectory.empty()) continue;
    Segment s;
    s.robot = robot;
    s.seed = static_cast<int>(options.seed);
    s.start_s = start - truth.front().t_s;
    s.length_s = res.trajectory.back().t_s - start;
    s.errors = eval::compare_trajectory(res.trajectory, truth);
    s.nees = offline::trajectory_nees(res.trajectory, res.covariance, truth);
    if (const auto opt = optimised(optimise, options, restarted, res)) {
      s.optimised = eval::compare_trajectory(opt->trajectory, truth);
    }
    out.push_back(s);
  }
  return out;
}

// ATE and heading RMSE (deg) of one full run.
struct RunScore {
  double ate_m = 0.0;
  double heading_deg = 0.0;
};

offline::MrclamSensorModel model_of(const mrclam::CorrectionFit& f) {
  offline::MrclamSensorModel m;
  m.range_scale = f.range.range_scale;
  m.range_cos_bearing_exponent = f.range.cos_bearing_exponent;
  m.odometry_delay_s = f.delay.delay_s;
  m.speed_scale = f.speed.speed_scale;
  m.speed_loss_per_radps = f.speed.speed_loss_per_radps;
  return m;
}

std::string robot_list(const std::vector<const mrclam::RobotData*>& robots) {
  std::string out;
  for (const mrclam::RobotData* r : robots) out += (out.empty() ? "" : ",") + std::to_string(r->robot);
  return out;
}

void print_fit(const std::string& label, const mrclam::CorrectionFit& f) {
  std::printf("%s: range_scale %.4f range_cos_bearing_exponent %.3f odometry_delay_s %.2f speed_scale %.4f "
              "speed_loss_per_radps %.3f\n",
              label.c_str(), f.range.range_scale, f.range.cos_bearing_exponent, f.delay.delay_s, f.speed.speed_scale,
              f.speed.speed_loss_per_radps);
  std::printf("%*s  range: %zu detections, %zu inliers; range error robust sd %.3f m (uncorrected %.3f m), RMS %.3f m "
              "(uncorrected %.3f m); bearing error robust sd %.4f rad, RMS %.4f rad, median %+.4f rad\n",
              static_cast<int>(label.size()), "", f.range.samples, f.range.inliers, f.range.range_sigma_m,
              f.range.range_sigma_before_m, f.range.range_rms_m, f.range.range_rms_before_m, f.range.bearing_sigma_rad,
              f.range.bearing_rms_rad, f.range.bearing_median_rad);
  std::printf("%*s  delay: correlation %.4f (%.4f at %.2f s), %zu samples; speed: %zu windows, %zu inliers, "
              "residual robust sd %.4f m/s\n",
              static_cast<int>(label.size()), "", f.delay.correlation, f.delay.correlation_at_zero,
              f.delay.lags_s.empty() ? 0.0 : f.delay.lags_s.front(), f.delay.samples, f.speed.samples,
              f.speed.inliers, f.speed.sigma_mps);
}

// mrclam_eval --loro (see the top of this file). `config_scores[robot]` holds
// the main table's runs (config corrections, one per seed), `config_segments`
// the segments run with them (empty without --segments).
void run_loro(const std::string& dataset, slam::FilterOptions options, const offline::MrclamSensorModel& config_model,
              const std::vector<int>& robots, const std::vector<int>& seeds, double segment_every_s,
              const OptimiseRequest& optimise,
              const std::map<int, std::vector<RunScore>>& config_scores,
              const std::map<int, std::vector<Segment>>& config_segments) {
  constexpr double kDeg = 180.0 / M_PI;
  std::printf("\nLORO: leave one robot out: the mrclam: corrections fitted on the other robots with ground truth\n");
  std::vector<mrclam::RobotData> pool;
  for (int r = mrclam::kFirstRobot; r <= mrclam::kLastRobot; ++r) {
    mrclam::RobotData d = mrclam::load_robot(dataset, r);
    if (!d.groundtruth.empty()) pool.push_back(std::move(d));
  }
  if (pool.size() < 2) {
    std::printf("LORO: %zu robot(s) with ground truth in %s: nothing to leave out\n", pool.size(), dataset.c_str());
    return;
  }
  std::vector<const mrclam::RobotData*> all;
  for (const mrclam::RobotData& d : pool) all.push_back(&d);
  print_fit("fit on robots " + robot_list(all), mrclam::fit_corrections(all));
  std::printf("config mrclam:        range_scale %.4f range_cos_bearing_exponent %.3f odometry_delay_s %.2f "
              "speed_scale %.4f speed_loss_per_radps %.3f\n",
              config_model.range_scale, config_model.range_cos_bearing_exponent, config_model.odometry_delay_s,
              config_model.speed_scale, config_model.speed_loss_per_radps);
  const offline::MrclamSensorModel neutral;  // 1, 0, 0, 1, 0

  struct RobotRow {
    int robot = 0;
    std::string fitted_on;
    offline::MrclamSensorModel fit;
    RunScore loro, config, neutral;  // means over the seeds
    RunScore loro_optimised;          // --optimise: the map optimiser with the held-out fit
    std::vector<Segment> loro_segments, neutral_segments;
  };
  std::vector<RobotRow> rows;
  std::printf("%-6s %-5s %9s %9s %9s %10s %10s %10s\n", "robot", "seed", "ATE_loro", "ATE_cfg", "ATE_neut",
              "head_loro", "head_cfg", "head_neut");
  for (int robot : robots) {
    const auto held_out = std::find_if(pool.begin(), pool.end(), [&](const auto& d) { return d.robot == robot; });
    if (held_out == pool.end()) {
      std::printf("robot %d: no ground truth, not evaluated\n", robot);
      continue;
    }
    std::vector<const mrclam::RobotData*> others;
    for (const mrclam::RobotData& d : pool) {
      if (d.robot != robot) others.push_back(&d);
    }
    RobotRow row;
    row.robot = robot;
    row.fitted_on = robot_list(others);
    const mrclam::CorrectionFit fit = mrclam::fit_corrections(others);
    print_fit("loro robot " + std::to_string(robot) + ", fit on robots " + row.fitted_on, fit);
    row.fit = model_of(fit);
    const offline::RunInput with_fit = offline::mrclam_input(*held_out, row.fit);
    const offline::RunInput with_neutral = offline::mrclam_input(*held_out, neutral);
    const auto config_it = config_scores.find(robot);
    for (std::size_t i = 0; i < seeds.size(); ++i) {
      options.seed = static_cast<std::uint64_t>(seeds[i]);
      RunScore score[3];
      const offline::RunInput* inputs[2] = {&with_fit, &with_neutral};
      for (int m = 0; m < 2; ++m) {
        const offline::RunResult res = offline::run_filter(options, *inputs[m]);
        const offline::Report rep = offline::evaluate(*inputs[m], res);
        score[m == 0 ? 0 : 2] = {rep.filter.ate_rmse_m, rep.filter.heading_rmse_rad * kDeg};
        if (m != 0) continue;
        if (const auto opt = optimised(optimise, options, *inputs[m], res)) {
          const offline::Report o = offline::evaluate(*inputs[m], *opt);
          std::printf("%-6d %-5d map optimiser with the held-out fit: ATE %.3f m, heading RMSE %.2f deg\n", robot,
                      seeds[i], o.filter.ate_rmse_m, o.filter.heading_rmse_rad * kDeg);
          row.loro_optimised.ate_m += o.filter.ate_rmse_m / static_cast<double>(seeds.size());
          row.loro_optimised.heading_deg += o.filter.heading_rmse_rad * kDeg / static_cast<double>(seeds.size());
        }
      }
      if (config_it != config_scores.end() && i < config_it->second.size()) score[1] = config_it->second[i];
      std::printf("%-6d %-5d %9.3f %9.3f %9.3f %10.2f %10.2f %10.2f\n", robot, seeds[i], score[0].ate_m,
                  score[1].ate_m, score[2].ate_m, score[0].heading_deg, score[1].heading_deg, score[2].heading_deg);
      std::fflush(stdout);
      const double n = static_cast<double>(seeds.size());
      row.loro.ate_m += score[0].ate_m / n;
      row.loro.heading_deg += score[0].heading_deg / n;
      row.config.ate_m += score[1].ate_m / n;
      row.config.heading_deg += score[1].heading_deg / n;
      row.neutral.ate_m += score[2].ate_m / n;
      row.neutral.heading_deg += score[2].heading_deg / n;
      if (segment_every_s > 0.0) {
        for (const Segment& g : run_segments(options, with_fit, robot, segment_every_s, optimise)) {
          row.loro_segments.push_back(g);
        }
        for (const Segment& g : run_segments(options, with_neutral, robot, segment_every_s, OptimiseRequest{})) {
          row.neutral_segments.push_back(g);
        }
      }
    }
    rows.push_back(std::move(row));
  }
  if (rows.empty()) return;

  std::printf("\nLORO table (means over seeds %s; fit: corrections fitted on the other robots)\n",
              [&] {
                std::string s;
                for (int seed : seeds) s += (s.empty() ? "" : ",") + std::to_string(seed);
                return s;
              }()
                  .c_str());
  std::printf("%-6s %-10s %8s %6s %7s %8s %7s %9s %9s %9s %10s %10s %10s\n", "robot", "fit_on", "r_scale", "r_exp",
              "delay_s", "v_scale", "v_loss", "ATE_loro", "ATE_cfg", "ATE_neut", "head_loro", "head_cfg", "head_neut");
  RunScore mean_loro, mean_config, mean_neutral;
  const double n = static_cast<double>(rows.size());
  for (const RobotRow& r : rows) {
    std::printf("%-6d %-10s %8.4f %6.3f %7.2f %8.4f %7.3f %9.3f %9.3f %9.3f %10.2f %10.2f %10.2f\n", r.robot,
                r.fitted_on.c_str(), r.fit.range_scale, r.fit.range_cos_bearing_exponent, r.fit.odometry_delay_s,
                r.fit.speed_scale, r.fit.speed_loss_per_radps, r.loro.ate_m, r.config.ate_m, r.neutral.ate_m,
                r.loro.heading_deg, r.config.heading_deg, r.neutral.heading_deg);
    mean_loro.ate_m += r.loro.ate_m / n;
    mean_loro.heading_deg += r.loro.heading_deg / n;
    mean_config.ate_m += r.config.ate_m / n;
    mean_config.heading_deg += r.config.heading_deg / n;
    mean_neutral.ate_m += r.neutral.ate_m / n;
    mean_neutral.heading_deg += r.neutral.heading_deg / n;
  }
  std::printf("LORO MEAN over %zu robots: ATE %.3f m with the held-out fit, %.3f m with the config's mrclam:, %.3f m "
              "neutral; heading RMSE %.2f / %.2f / %.2f deg\n",
              rows.size(), mean_loro.ate_m, mean_config.ate_m, mean_neutral.ate_m, mean_loro.heading_deg,
              mean_config.heading_deg, mean_neutral.heading_deg);
  if (optimise) {
    RunScore mean_optimised;
    for (const RobotRow& r : rows) {
      std::printf("LORO robot %d, map optimiser with the held-out fit: ATE %.3f m, heading RMSE %.2f deg\n", r.robot,
                  r.loro_optimised.ate_m, r.loro_optimised.heading_deg);
      mean_optimised.ate_m += r.loro_optimised.ate_m / n;
      mean_optimised.heading_deg += r.loro_optimised.heading_deg / n;
    }
    std::printf("LORO MEAN over %zu robots, map optimiser with the held-out fit: ATE %.3f m, heading RMSE %.2f deg\n",
                rows.size(), mean_optimised.ate_m, mean_optimised.heading_deg);
  }
  if (segment_every_s > 0.0) {
    std::printf("\nLORO SEGMENTS (restarted from the truth every %.0f s):\n", segment_every_s);
    std::vector<Segment> all_loro, all_config, all_neutral;
    for (const RobotRow& r : rows) {
      const auto c = config_segments.find(r.robot);
      const std::vector<Segment> config = c == config_segments.end() ? std::vector<Segment>{} : c->second;
      print_segment_summary("loro segments robot " + std::to_string(r.robot) + " fit    ", r.loro_segments);
      print_segment_summary("loro segments robot " + std::to_string(r.robot) + " config ", config);
      print_segment_summary("loro segments robot " + std::to_string(r.robot) + " neutral", r.neutral_segments);
      all_loro.insert(all_loro.end(), r.loro_segments.begin(), r.loro_segments.end());
      all_config.insert(all_config.end(), config.begin(), config.end());
      all_neutral.insert(all_neutral.end(), r.neutral_segments.begin(), r.neutral_segments.end());
    }
    print_segment_summary("LORO SEGMENTS all robots fit    ", all_loro);
    print_segment_summary("LORO SEGMENTS all robots config ", all_config);
    print_segment_summary("LORO SEGMENTS all robots neutral", all_neutral);
  }
}

// One line: mean, median, p90 and worst of `values`, after a label padded to `width`.
void print_distribution(const char* label, int width, const std::vector<double>& values, const char* unit) {
  const offline::Summary x = offline::summarize(values);
  std::printf("  %-*s mean %7.3f median %7.3f p90 %7.3f worst %7.3f %s\n", width, label, x.mean, x.median, x.p90, x.max,
              unit);
}

// Per robot with ground truth and per seed (options.seed set): `run` with the
// robot's truth in time order and its starts every `every_s` seconds.
template <class Run>
void for_each_run_with_starts(const std::vector<std::pair<int, offline::RunInput>>& inputs,
                              const std::vector<int>& seeds, double every_s, slam::FilterOptions& options,
                              const Run& run) {
  for (const auto& [robot, input] : inputs) {
    if (input.truth.empty()) continue;
    const std::vector<eval::TimedPose> truth = eval::sorted_by_time(input.truth);
    const std::vector<double> starts = offline::segment_starts(truth, every_s);
    for (int seed : seeds) {
      options.seed = static_cast<std::uint64_t>(seed);
      run(robot, input, truth, starts, seed);
    }
  }
}

// mrclam_eval --blind-return (see the top of this file).
void run_blind_return(slam::FilterOptions options, const std::vector<std::pair<int, offline::RunInput>>& inputs,
                      const std::vector<int>& seeds, const OptimiseRequest& optimise) {
  constexpr double kDeg = 180.0 / M_PI;
  constexpr double kEveryS = 60.0;
  const offline::BlindReturnOptions cases;
  std::printf("\nBLIND RETURN: restarted from the truth every %.0f s; landmarks for %.0f s, then %.0f s blind with "
              "+-%.3f rad/s added to the turn rate, then %.0f s of new landmarks beyond %.1f m only, then all; "
              "scored %.0f s from the first landmark of the first stretch seen again\n",
              kEveryS, cases.seen_s, cases.blind_s, cases.heading_bias_radps, cases.far_s, cases.far_min_range_m,
              cases.after_s);
  std::printf("%-5s %-5s %8s %8s %9s %9s %9s %9s %9s %9s\n", "robot", "seed", "start_s", "return_s", "DR_ret",
              "DR_end", "err_ret", "rmse_aft", "err_end", "ATE_aft");
  std::vector<double> at_return, after, at_end, ate_after, dr_at_return, dr_at_end, opt_after, opt_at_end, opt_ate_after;
  std::size_t skipped = 0;
  for_each_run_with_starts(inputs, seeds, kEveryS, options, [&](int robot, const offline::RunInput& input,
                                                                 const std::vector<eval::TimedPose>& truth,
                                                                 const std::vector<double>& starts, int seed) {
    for (std::size_t k = 0; k < starts.size(); ++k) {
      offline::BlindReturnOptions o = cases;
      if (k % 2 == 1) o.heading_bias_radps = -o.heading_bias_radps;
      const std::optional<offline::BlindReturnCase> c =
          offline::make_blind_return(offline::restart_at_truth(input, starts[k]), o);
      if (!c) {
        if (seed == seeds.front()) ++skipped;
        continue;
      }
      const offline::RunResult res = offline::run_filter(options, c->input);
      const offline::ReturnScore score = offline::score_return(*c, res.trajectory);
      const offline::ReturnScore dr = offline::score_return(*c, res.dead_reckoning);
      std::printf("%-5d %-5d %8.1f %8.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.3f", robot, seed,
                  starts[k] - truth.front().t_s, c->return_s - starts[k], dr.heading_error_at_return_rad * kDeg,
                  dr.heading_error_end_rad * kDeg, score.heading_error_at_return_rad * kDeg, score.heading_rmse_after_rad * kDeg,
                  score.heading_error_end_rad * kDeg, score.ate_after_m);
      if (const auto opt = optimised(optimise, options, c->input, res)) {
        const offline::ReturnScore os = offline::score_return(*c, opt->trajectory);
        std::printf("  optimised: rmse_aft %.1f err_end %.1f ATE_aft %.3f", os.heading_rmse_after_rad * kDeg,
                    os.heading_error_end_rad * kDeg, os.ate_after_m);
        opt_after.push_back(os.heading_rmse_after_rad * kDeg);
        opt_at_end.push_back(os.heading_error_end_rad * kDeg);
        opt_ate_after.push_back(os.ate_after_m);
      }
      std::printf("\n");
      std::fflush(stdout);
      dr_at_return.push_back(dr.heading_error_at_return_rad * kDeg);
      dr_at_end.push_back(dr.heading_error_end_rad * kDeg);
      at_return.push_back(score.heading_error_at_return_rad * kDeg);
      after.push_back(score.heading_rmse_after_rad * kDeg);
      at_end.push_back(score.heading_error_end_rad * kDeg);
      ate_after.push_back(score.ate_after_m);
    }
  });
  const auto line = [](const char* label, const std::vector<double>& v, const char* unit) {
    print_distribution(label, 36, v, unit);
  };
  std::printf("BLIND RETURN: %zu cases (%zu starts without a return skipped)\n", at_return.size(), skipped);
  line("dead-reckoning heading error at return", dr_at_return, "deg");
  line("dead-reckoning heading error, last 10 s", dr_at_end, "deg");
  line("heading error at return", at_return, "deg");
  line("heading RMSE after return", after, "deg");
  line("heading error, last 10 s", at_end, "deg");
  line("ATE after return", ate_after, "m");
  if (!opt_after.empty()) {
    line("map optimiser: heading RMSE after return", opt_after, "deg");
    line("map optimiser: heading error, last 10 s", opt_at_end, "deg");
    line("map optimiser: ATE after return", opt_ate_after, "m");
  }
}

// mrclam_eval --resume GAP_S (see the top of this file).
void run_resume(slam::FilterOptions options, const std::vector<std::pair<int, offline::RunInput>>& inputs,
                const std::vector<int>& seeds, double gap_s) {
  constexpr double kDeg = 180.0 / M_PI;
  constexpr double kEveryS = 60.0;
  // The estimator's checkpoint.max_speed_mps and max_turn_rate_radps defaults.
  constexpr double kMaxSpeedMps = 0.5, kMaxTurnRateRadps = 1.0;
  std::printf("\nRESUME: the estimator killed every %.0f s and restarted %.2f s later from its checkpoint (pose "
              "widened for the gap by %.1f m/s and %.1f rad/s, map as prior; the gap's odometry lost); scored to the "
              "end against the uninterrupted run over the same time\n",
              kEveryS, gap_s, kMaxSpeedMps, kMaxTurnRateRadps);
  std::printf("%-5s %-5s %8s %9s %9s %9s %9s %9s %9s\n", "robot", "seed", "kill_s", "ATE_run", "ATE_res", "ATE_pose",
              "head_run", "head_res", "head_pose");
  std::vector<double> run_ate, res_ate, pose_ate, run_head, res_head, pose_head, res_extra, pose_extra;
  for_each_run_with_starts(inputs, seeds, kEveryS, options, [&](int robot, const offline::RunInput& input,
                                                                 const std::vector<eval::TimedPose>& truth,
                                                                 const std::vector<double>& starts, int seed) {
    // The uninterrupted run, with a checkpoint at the first step of each start (after the first).
    std::vector<std::pair<double, slam::MapCheckpoint>> checkpoints;
    std::size_t next = 1;
    const offline::RunResult full = offline::run_filter(options, input, [&](const slam::FastSlam2& f, double t) {
      if (next < starts.size() && t >= starts[next]) {
        checkpoints.emplace_back(t, slam::checkpoint_of(f, 0));
        ++next;
      }
    });
    for (const auto& [kill_s, checkpoint] : checkpoints) {
      const double resume_s = kill_s + gap_s;
      std::vector<eval::TimedPose> run_after;
      for (const eval::TimedPose& p : full.trajectory) {
        if (p.t_s >= resume_s) run_after.push_back(p);
      }
      if (run_after.empty()) continue;
      // As resumed, and as resumed from the pose alone (the held control not
      // saved: a version-1 checkpoint), which is what the control buys.
      slam::MapCheckpoint pose_only = checkpoint;
      pose_only.control_v_mps = pose_only.control_w_radps = 0.0;
      const auto resumed = [&](const slam::MapCheckpoint& c) {
        return offline::run_filter(options, offline::resumed_after(input, kill_s, c, gap_s, kMaxSpeedMps,
                                                                   kMaxTurnRateRadps, options.control_timeout_s))
            .trajectory;
      };
      const eval::TrajectoryErrors run = eval::compare_trajectory(run_after, truth);
      const eval::TrajectoryErrors res = eval::compare_trajectory(resumed(checkpoint), truth);
      const eval::TrajectoryErrors pose = eval::compare_trajectory(resumed(pose_only), truth);
      std::printf("%-5d %-5d %8.1f %9.3f %9.3f %9.3f %9.1f %9.1f %9.1f\n", robot, seed, kill_s - truth.front().t_s,
                  run.ate_rmse_m, res.ate_rmse_m, pose.ate_rmse_m, run.heading_rmse_rad * kDeg,
                  res.heading_rmse_rad * kDeg, pose.heading_rmse_rad * kDeg);
      std::fflush(stdout);
      run_ate.push_back(run.ate_rmse_m);
      res_ate.push_back(res.ate_rmse_m);
      pose_ate.push_back(pose.ate_rmse_m);
      run_head.push_back(run.heading_rmse_rad * kDeg);
      res_head.push_back(res.heading_rmse_rad * kDeg);
      pose_head.push_back(pose.heading_rmse_rad * kDeg);
      res_extra.push_back(res.ate_rmse_m - run.ate_rmse_m);
      pose_extra.push_back(pose.ate_rmse_m - run.ate_rmse_m);
    }
  });
  std::printf("RESUME: %zu restarts, %.2f s gap\n", run_ate.size(), gap_s);
  const std::vector<std::tuple<const char*, const std::vector<double>*, const char*>> rows = {
      {"ATE after the restart, uninterrupted run", &run_ate, "m"},
      {"ATE after the restart, resumed", &res_ate, "m"},
      {"ATE after the restart, resumed from the pose only", &pose_ate, "m"},
      {"resumed minus uninterrupted ATE", &res_extra, "m"},
      {"resumed from the pose only minus uninterrupted", &pose_extra, "m"},
      {"heading RMSE, uninterrupted run", &run_head, "deg"},
      {"heading RMSE, resumed", &res_head, "deg"},
      {"heading RMSE, resumed from the pose only", &pose_head, "deg"}};
  for (const auto& [label, values, unit] : rows) print_distribution(label, 44, *values, unit);
}

// The CSV files of --out-dir (none when the folder is empty).
class CsvOutput {
 public:
  explicit CsvOutput(std::string dir) : dir_(std::move(dir)) {
    if (dir_.empty()) return;
    std::filesystem::create_directories(dir_);
    runs_ = open("runs.csv");
    runs_ << "robot,seed,ate_m,ate_aligned_m,dr_ate_m,heading_deg,dr_heading_deg,landmarks_raw_m,"
             "landmarks_aligned_m,nees_inside_fraction\n";
  }
  void run(int robot, int seed, const offline::RunInput& input, const offline::RunResult& res,
           const offline::Report& rep) {
    if (dir_.empty()) return;
    constexpr double kDeg = 180.0 / M_PI;
    runs_ << robot << ',' << seed << ',' << rep.filter.ate_rmse_m << ',' << rep.filter.ate_rmse_aligned_m << ','
          << rep.dead_reckoning.ate_rmse_m << ',' << rep.filter.heading_rmse_rad * kDeg << ','
          << rep.dead_reckoning.heading_rmse_rad * kDeg << ',' << rep.landmarks.rmse_m << ','
          << rep.landmarks.rmse_aligned_m << ',' << rep.nees.fraction_inside() << '\n';
    if (input.truth.empty() || res.trajectory.empty()) return;
    const std::vector<eval::TimedPose> truth = eval::sorted_by_time(input.truth);
    const std::vector<eval::PoseError> filter = eval::pose_errors(res.trajectory, truth);
    const std::vector<eval::PoseError> dr = eval::pose_errors(res.dead_reckoning, truth);
    std::ofstream out = open("errors_robot" + std::to_string(robot) + "_seed" + std::to_string(seed) + ".csv");
    out << "t_s,position_m,heading_deg,dr_position_m,dr_heading_deg\n";
    for (std::size_t i = 0; i < filter.size() && i < dr.size(); ++i) {
      out << filter[i].t_s - truth.front().t_s << ',' << filter[i].position_m << ',' << filter[i].heading_rad * kDeg
          << ',' << dr[i].position_m << ',' << dr[i].heading_rad * kDeg << '\n';
    }
  }
  void segments(const std::vector<Segment>& all) {
    if (dir_.empty()) return;
    std::ofstream out = open("segments.csv");
    out << "robot,seed,start_s,length_s,ate_m,heading_deg,nees_inside_fraction\n";
    for (const Segment& g : all) {
      out << g.robot << ',' << g.seed << ',' << g.start_s << ',' << g.length_s << ',' << g.errors.ate_rmse_m << ','
          << g.errors.heading_rmse_rad * 180.0 / M_PI << ',' << g.nees.fraction_inside() << '\n';
    }
  }

 private:
  std::ofstream open(const std::string& name) const {
    std::ofstream f(dir_ + "/" + name);
    if (!f) throw std::runtime_error("cannot write " + dir_ + "/" + name);
    f.precision(9);
    return f;
  }
  std::string dir_;
  std::ofstream runs_;
};

// The robots' final maps of one seed, fused into the fleet map (fleet_map::fuse_maps).
struct FleetRuns {
  std::vector<fleet_map::RobotMap> maps;
  std::vector<std::pair<int, double>> single_rmse;  // robot, its landmark RMSE
  std::vector<eval::LandmarkPoint> truth;
  void add(int robot, const offline::RunResult& res, const offline::Report& rep,
           const std::vector<eval::LandmarkPoint>& true_landmarks) {
    fleet_map::RobotMap m;
    m.robot_id = mrclam::robot_id(robot);
    for (const eval::LandmarkRow& l : res.landmarks) {
      fleet_map::LandmarkEstimate e;
      e.id = l.id;
      e.mean = {l.x_m, l.y_m};
      e.cov << l.cov_xx, l.cov_xy, l.cov_xy, l.cov_yy;
      m.landmarks.push_back(e);
    }
    maps.push_back(std::move(m));
    if (rep.has_landmarks) single_rmse.emplace_back(robot, rep.landmarks.rmse_m);
    if (truth.empty()) truth = true_landmarks;
  }
};

// Per seed: the fleet map's landmark RMSE beside the best and the mean single robot's.
void print_fleet(const std::map<int, FleetRuns>& fleet) {
  if (fleet.empty() || fleet.begin()->second.maps.size() < 2 || fleet.begin()->second.truth.empty()) return;
  std::printf("\nFLEET MAP: the robots' final maps fused (covariance weighted, frames checked; fleet_map::fuse_maps)\n");
  double sum_fleet = 0.0, sum_best = 0.0, sum_mean = 0.0;
  for (const auto& [seed, runs] : fleet) {
    const fleet_map::FleetMap f = fleet_map::fuse_maps(runs.maps);
    std::vector<eval::LandmarkPoint> fused;
    for (const fleet_map::FusedLandmark& l : f.landmarks) fused.push_back({l.id, l.mean.x(), l.mean.y()});
    const eval::LandmarkErrors e = eval::compare_landmarks(fused, runs.truth);
    std::pair<int, double> best{0, 1e300};
    double mean = 0.0;
    for (const auto& [robot, rmse] : runs.single_rmse) {
      if (rmse < best.second) best = {robot, rmse};
      mean += rmse / static_cast<double>(runs.single_rmse.size());
    }
    std::string checks;
    for (const fleet_map::FrameCheck& c : f.robots) {
      char one[200];
      std::snprintf(one, sizeof one, "%s%s %s (%zu shared, F %.1f / %.1f, offset %.2f m, %.1f deg, residual %.2f m)",
                    checks.empty() ? "" : "; ", c.robot_id.c_str(), fleet_map::to_string(c.verdict), c.common,
                    c.f_statistic, c.threshold, c.offset_m, c.rotation_rad * 180.0 / M_PI, c.residual_m);
      checks += one;
    }
    std::printf("fleet seed %d: landmarks %.3f m raw / %.3f m aligned (%zu mapped, %zu missing); best robot %d %.3f m, "
                "mean of robots %.3f m\n  frames: %s\n",
                seed, e.rmse_m, e.rmse_aligned_m, e.matched, e.missing, best.first, best.second, mean, checks.c_str());
    sum_fleet += e.rmse_m;
    sum_best += best.second;
    sum_mean += mean;
  }
  const double n = static_cast<double>(fleet.size());
  std::printf("FLEET MEAN over %zu seeds: landmarks %.3f m fused, best single robot %.3f m, mean single robot %.3f m\n",
              fleet.size(), sum_fleet / n, sum_best / n, sum_mean / n);
}

struct EvalArguments {
  std::string dataset, config_path, association = "known_id", out_dir;
  std::vector<int> robots{1, 2, 3, 4, 5}, seeds{1, 2, 3};
  std::vector<std::string> sets;  // --set: filter.KEY=V, mrclam.KEY=V or optimizer.KEY=V
  double segment_every_s = 0.0;  // 0: no segments
  bool loro = false, blind_return = false;
  double resume_gap_s = -1.0;  // < 0: no resume evaluation
  OptimiseRequest optimise;
};

int run(const EvalArguments& args) {
  const std::string& dataset = args.dataset;
  const std::string& config_path = args.config_path;
  const std::string& association = args.association;
  const std::vector<int>& robots = args.robots;
  const std::vector<int>& seeds = args.seeds;
  const double segment_every_s = args.segment_every_s;
  const bool loro = args.loro, blind_return = args.blind_return;
  OptimiseRequest optimise = args.optimise;
  if (!std::filesystem::is_directory(dataset)) {
    std::printf("SKIP: dataset folder %s not found\n", dataset.c_str());
    return 77;
  }
  config::YamlReader root = config::YamlReader::from_file(config_path);
  config::YamlReader filter_yaml = root.child("filter");
  slam::FilterOptions options = slam::read_filter_options(filter_yaml);
  offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
  root.finish();
  std::vector<std::string> filter_sets = args.sets;
  const std::vector<std::string> mrclam_sets = parameters::take_section(filter_sets, "mrclam");
  optimise.sets = parameters::take_section(filter_sets, "optimizer");
  try {
    offline::check_optimizer_sets(options, optimise.sets, optimise.on);
    slam::apply_overrides(options, filter_sets);
    for (const std::string& a : mrclam_sets) {
      parameters::apply_override(model, offline::mrclam_sensor_parameters(), "mrclam", a);
    }
  } catch (const std::invalid_argument& e) {
    throw app::UsageError(std::string("--set: ") + e.what());
  }
  if (association == "maximum_likelihood") options.association = slam::Association::kMaximumLikelihood;
  CsvOutput csv(args.out_dir);

  std::printf("%-6s %-5s %9s %9s %9s %10s %10s %11s %11s %8s %5s %8s %7s %6s %6s\n", "robot", "seed", "ATE_m",
              "ATE_al_m", "DR_ATE_m", "head_deg", "DR_head", "lm_raw_m", "lm_align_m", "gated", "map", "wall_s",
              "NEES", "in95%", "<ub%");
  constexpr double kDeg = 180.0 / M_PI;
  bool all_better = true;
  double sum_ate = 0, sum_ate_aligned = 0, sum_head = 0, sum_lm = 0, sum_lma = 0, sum_wall = 0;
  double worst_ate = 0.0;  // the full run with the largest ATE
  int worst_robot = 0, worst_seed = 0;
  int runs = 0;
  offline::NeesStats nees_all;
  // Landmark errors, NaN (printed "nan") without landmark ground truth.
  const auto lm_raw = [](const offline::Report& r) {
    return r.has_landmarks ? r.landmarks.rmse_m : std::numeric_limits<double>::quiet_NaN();
  };
  const auto lm_aligned = [](const offline::Report& r) {
    return r.has_landmarks ? r.landmarks.rmse_aligned_m : std::numeric_limits<double>::quiet_NaN();
  };
  // --optimise: the same sums for the map optimiser's solutions.
  struct Sums {
    double ate = 0, ate_aligned = 0, head = 0, lm = 0, lma = 0, worst = 0;
    int runs = 0;
    void add(const offline::Report& r, double landmarks_raw, double landmarks_aligned) {
      ate += r.filter.ate_rmse_m;
      ate_aligned += r.filter.ate_rmse_aligned_m;
      head += r.filter.heading_rmse_rad * 180.0 / M_PI;
      lm += landmarks_raw;
      lma += landmarks_aligned;
      worst = std::max(worst, r.filter.ate_rmse_m);
      ++runs;
    }
  } opt_sum;
  std::vector<std::pair<int, offline::RunInput>> inputs;  // kept for the segments
  std::map<int, std::vector<RunScore>> config_scores;     // kept for --loro
  std::map<int, std::vector<Segment>> config_segments;
  std::map<int, FleetRuns> fleet;                          // by seed: the robots' final maps
  for (int robot : robots) {
    const mrclam::RobotData data = mrclam::load_robot(dataset, robot);
    const offline::RunInput input = offline::mrclam_input(data, model);
    if (segment_every_s > 0.0 || blind_return || args.resume_gap_s >= 0.0) inputs.emplace_back(robot, input);
    double robot_ate = 0, robot_dr = 0;
    for (int seed : seeds) {
      options.seed = static_cast<std::uint64_t>(seed);
      const offline::RunResult res = offline::run_filter(options, input);
      const offline::Report rep = offline::evaluate(input, res);
      std::printf("%-6d %-5d %9.3f %9.3f %9.3f %10.2f %10.2f %11.3f %11.3f %8llu %5zu %8.2f %7.2f %6.1f %6.1f\n",
                  robot, seed, rep.filter.ate_rmse_m, rep.filter.ate_rmse_aligned_m, rep.dead_reckoning.ate_rmse_m,
                  rep.filter.heading_rmse_rad * kDeg, rep.dead_reckoning.heading_rmse_rad * kDeg, lm_raw(rep),
                  lm_aligned(rep), static_cast<unsigned long long>(res.counters.observations_gated),
                  res.landmarks.size(), res.wall_time_s, rep.nees.mean(), 100.0 * rep.nees.fraction_inside(),
                  100.0 * rep.nees.fraction_below_upper());
      std::fflush(stdout);
      config_scores[robot].push_back({rep.filter.ate_rmse_m, rep.filter.heading_rmse_rad * kDeg});
      fleet[seed].add(robot, res, rep, input.landmarks);
      csv.run(robot, seed, input, res, rep);
      if (const auto opt = optimised(optimise, options, input, res)) {
        const offline::Report o = offline::evaluate(input, *opt);
        std::printf("%-6d %-5d %9.3f %9.3f %9s %10.2f %10s %11.3f %11.3f %8s %5zu %8.2f  (map optimiser)\n", robot,
                    seed, o.filter.ate_rmse_m, o.filter.ate_rmse_aligned_m, "", o.filter.heading_rmse_rad * kDeg, "",
                    lm_raw(o), lm_aligned(o), "", opt->landmarks.size(), opt->wall_time_s);
        std::fflush(stdout);
        opt_sum.add(o, lm_raw(o), lm_aligned(o));
      }
      robot_ate += rep.filter.ate_rmse_m;
      robot_dr += rep.dead_reckoning.ate_rmse_m;
      sum_ate += rep.filter.ate_rmse_m;
      if (rep.filter.ate_rmse_m > worst_ate) {
        worst_ate = rep.filter.ate_rmse_m;
        worst_robot = robot;
        worst_seed = seed;
      }
      sum_ate_aligned += rep.filter.ate_rmse_aligned_m;
      sum_head += rep.filter.heading_rmse_rad * kDeg;
      sum_lm += lm_raw(rep);
      sum_lma += lm_aligned(rep);
      sum_wall += res.wall_time_s;
      nees_all.merge(rep.nees);
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
  if (worst_ate > 0.0) {
    std::printf("WORST run: ATE %.3f m (robot %d, seed %d)\n", worst_ate, worst_robot, worst_seed);
  }
  if (nees_all.steps + nees_all.singular > 0) print_nees("POOLED over the full runs: pose", nees_all);
  print_fleet(fleet);
  if (opt_sum.runs > 0) {
    const double n = opt_sum.runs;
    std::printf("MEAN over %d runs, map optimiser: ATE %.3f m (%.3f m after SE(2) alignment, worst run %.3f m), "
                "heading %.2f deg, landmarks %.3f m raw / %.3f m aligned\n",
                opt_sum.runs, opt_sum.ate / n, opt_sum.ate_aligned / n, opt_sum.worst, opt_sum.head / n, opt_sum.lm / n,
                opt_sum.lma / n);
  }

  if (segment_every_s > 0.0) {
    std::printf("\nSEGMENTS: restarted from the ground truth every %.0f s, each to the end of the robot's data\n",
                segment_every_s);
    std::printf("%-7s %-5s %-5s %8s %9s %9s %9s %7s %6s %6s\n", "segment", "robot", "seed", "start_s", "length_s",
                "ATE_m", "head_deg", "NEES", "in95%", "<ub%");
    std::vector<Segment> all;
    for (const auto& [robot, input] : inputs) {
      if (input.truth.empty()) {
        std::printf("robot %d: no ground truth, no segments\n", robot);
        continue;
      }
      std::vector<Segment> of_robot;
      for (int seed : seeds) {
        options.seed = static_cast<std::uint64_t>(seed);
        for (const Segment& g : run_segments(options, input, robot, segment_every_s, optimise)) {
          std::printf("%-7zu %-5d %-5d %8.1f %9.1f %9.3f %9.2f %7.2f %6.1f %6.1f", all.size() + of_robot.size() + 1,
                      g.robot, g.seed, g.start_s, g.length_s, g.errors.ate_rmse_m, g.errors.heading_rmse_rad * kDeg,
                      g.nees.mean(), 100.0 * g.nees.fraction_inside(), 100.0 * g.nees.fraction_below_upper());
          if (g.optimised) {
            std::printf("  optimised ATE %.3f m, heading %.2f deg", g.optimised->ate_rmse_m,
                        g.optimised->heading_rmse_rad * kDeg);
          }
          std::printf("\n");
          std::fflush(stdout);
          of_robot.push_back(g);
        }
      }
      print_segment_summary("segments robot " + std::to_string(robot), of_robot);
      config_segments[robot] = of_robot;
      all.insert(all.end(), of_robot.begin(), of_robot.end());
    }
    csv.segments(all);
    if (!all.empty()) {
      print_segment_summary("SEGMENTS all robots", all);
      const Segment& worst = *std::max_element(all.begin(), all.end(), [](const Segment& a, const Segment& b) {
        return a.errors.ate_rmse_m < b.errors.ate_rmse_m;
      });
      std::printf("worst segment: robot %d seed %d start %.1f s: ATE %.3f m, heading RMSE %.2f deg\n", worst.robot,
                  worst.seed, worst.start_s, worst.errors.ate_rmse_m, worst.errors.heading_rmse_rad * kDeg);
    }
  }
  if (blind_return) run_blind_return(options, inputs, seeds, optimise);
  if (args.resume_gap_s >= 0.0) run_resume(options, inputs, seeds, args.resume_gap_s);
  if (loro) {
    run_loro(dataset, options, model, robots, seeds, segment_every_s, optimise, config_scores, config_segments);
  }
  if (!all_better) {
    std::printf("FAIL: some robot's mean ATE is not better than dead reckoning\n");
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  EvalArguments a;
  std::string robots, seeds;
  app::Cli cli{"mrclam_eval",
               "The accuracy table of the FastSLAM core on an MRCLAM data set: one parameter set for every robot, "
               "several seeds per robot; segment starts, leave-one-robot-out and blind-return evaluations."};
  cli.option("--dataset", a.dataset, "the MRCLAM data set folder (exit 77 when absent: a skip)").required().type("DIR");
  app::add_config(cli, a.config_path, "filter options (filter:) and corrections (mrclam:)");
  app::add_set(cli, a.sets, "filter.delayed_sampling.split_heading=true or mrclam.odometry_delay_s=0, both listed below");
  cli.option("--robots", robots, "robots to run (default 1,2,3,4,5)").type("LIST");
  cli.option("--seeds", seeds, "filter seeds per robot (default 1,2,3; they replace filter.seed)").type("LIST");
  cli.option("--association", a.association, "known_id (default) or maximum_likelihood (ids withheld)")
      .choices({"known_id", "maximum_likelihood"})
      .type("M");
  cli.option("--segments", a.segment_every_s, "also restart each robot from the ground truth every S seconds")
      .positive()
      .type("S");
  cli.flag("--loro", a.loro,
           "leave one robot out: per robot with ground truth, the mrclam: corrections fitted on the other robots; "
           "ATE and heading RMSE with that fit, the config's values and neutral corrections");
  cli.flag("--blind-return", a.blind_return,
           "restarts every 60 s with a blind stretch, then far new landmarks, then the first ones again: the "
           "heading error before and after they return");
  cli.option("--resume", a.resume_gap_s,
             "the estimator killed every 60 s and restarted GAP_S s later from its checkpoint: the error after the "
             "restart against the uninterrupted run's")
      .non_negative()
      .type("GAP_S");
  cli.flag("--optimise", a.optimise.on,
           "also the map optimiser (Ceres) over every run after the filter (--set optimizer.KEY=V: the "
           "optimiser's and its solve schedule's keys that map_optimizer --help lists)");
  cli.option("--out-dir", a.out_dir,
             "write runs.csv, segments.csv and errors_robotR_seedS.csv (error over time) there, for "
             "scripts/plot_results.py")
      .type("DIR");
  cli.footer("filter parameters (filter:):\n" + parameters::help_text(slam::filter_parameters(), "filter") +
             "MRCLAM sensor model (mrclam:):\n" +
             parameters::help_text(offline::mrclam_sensor_parameters(), "mrclam") +
             "Exit status: 0 done, 1 an error or a robot's mean ATE not better than dead reckoning, 2 a bad "
             "command line or config, 77 the data set folder is absent (skip).");
  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("mrclam_eval", [&] {
    if (cli.given("--robots")) {
      a.robots = app::parse_int_list(robots, "--robots", 1);
      app::check_usage([&] { mrclam::check_robot_list(a.robots, "--robots"); });
    }
    if (cli.given("--seeds")) a.seeds = app::parse_int_list(seeds, "--seeds", 0);
    return run(a);
  });
}
