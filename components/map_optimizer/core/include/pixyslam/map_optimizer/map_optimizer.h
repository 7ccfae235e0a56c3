#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/parameters/parameters.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"

namespace ceres {
class LossFunction;
class Problem;
}  // namespace ceres

namespace pixyslam::map_optimizer {

// The full SLAM least-squares problem over keyframe poses and landmarks, solved
// with Ceres beside the filter (as cartographer's global optimisation beside its
// local SLAM): what the filter committed to (a map turned by a blind stretch's
// heading drift) is corrected when old landmarks are seen again.
//
//   minimise  sum_k |odometry residual k|^2 + sum_j rho(|observation residual j|^2)
//
// - odometry factors between consecutive keyframes: the pose of keyframe b in
//   the frame of keyframe a against the odometry composed between them with the
//   filter's motion model (ComposedMotion: the same unicycle steps and noise
//   densities), whitened by that covariance;
// - range/bearing factors with the filter's observation model (paper Eq. 3) and
//   its observation noise, under a Huber loss rho whose threshold is the 95 %
//   chi-square quantile of 2 dof (inside it plain least squares);
// - the first keyframe (the start pose the filter starts from) is held fixed: it
//   defines the frame, as it does for the filter;
// - a turn-rate scale error s per keyframe, slowly varying (first-order
//   Gauss-Markov, sd turn_scale_sigma, correlation time turn_scale_correlation_s):
//   the heading change between keyframes is (1 + s) times the odometry's. The
//   filter's white noise allows a heading error that grows with the square root
//   of the time; a turn rate off by a few percent for a minute is not white.
// Keyframes: one at every camera frame with a valid detection, and one at least
// every keyframe_interval_s in between, so a long blind stretch bends through
// several factors instead of one badly linearised one; none while the odometry
// reports a standstill (a parked robot's observations join the newest keyframe,
// and the standstill adds no motion noise), so a robot parked for hours among
// its landmarks does not grow the problem.
// Initial values: the pose guess given with a frame (the filter's estimate) or
// dead reckoning from the previous keyframe; a landmark's guess, else its first
// observation. Pure: no DDS, time passed in; one thread.
struct MapOptimizerOptions {
  slam::MotionNoise motion;
  double control_timeout_s = 5.0;
  // Odometry beyond these is dropped (counted), as the filter does: one sample
  // with a huge speed would overflow the motion noise of every later solve.
  double max_speed_mps = 10.0;
  double max_turn_rate_radps = 20.0;
  double range_sigma_m = 0.07;
  double range_sigma_per_m = 0.0;
  double bearing_sigma_rad = 0.027;
  double min_range_m = 0.05;
  double max_range_m = 50.0;
  int max_landmarks = 4096;  // the filter's max_map_landmarks: detections of more ids are dropped
  slam::IdRanges landmark_ids;  // the filter's association.landmark_ids: others dropped (empty: every id)
  double keyframe_interval_s = 1.0;
  // Huber threshold on the whitened residual norm: sqrt(chi2_2(0.95)).
  double huber_threshold = 2.4477;
  // The turn-rate scale state (0: none, the odometry factors alone).
  double turn_scale_sigma = 0.05;
  double turn_scale_correlation_s = 60.0;
  int max_iterations = 100;
  // Ceres stops when the cost changes by less than this fraction.
  double function_tolerance = 1e-8;

  // Motion and observation model exactly as the filter's.
  static MapOptimizerOptions from_filter(const slam::FilterOptions& filter);
};
// The optimiser's own keys (`optimizer:` of config/map_optimizer.yaml); the
// models' values come from the filter's (from_filter).
const parameters::Table<MapOptimizerOptions>& map_optimizer_parameters();

// Throws std::invalid_argument naming the field.
void validate(const MapOptimizerOptions& options);

struct Keyframe {
  double t_s = 0.0;
  slam::Pose2 pose = slam::Pose2::Zero();
};

struct LandmarkSolution {
  int id = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  // Marginal covariance from the last solve (Ceres' covariance of the solved
  // problem); NaN when not computed or rank deficient.
  Eigen::Matrix2d cov = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::size_t observations = 0;
};

struct SolveSummary {
  bool converged = false;       // Ceres stopped on a tolerance, not on the iteration limit or an error
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double solve_time_s = 0.0;    // Ceres' own total time
  std::size_t keyframes_free = 0;
  std::size_t landmarks_free = 0;
  std::size_t residuals = 0;
  std::string message;
};

// Counts of what was given and what was dropped.
struct OptimizerCounters {
  std::size_t odometry = 0;
  std::size_t odometry_dropped = 0;   // non-finite or before the last time
  std::size_t frames = 0;
  std::size_t frames_dropped = 0;     // non-finite time or before the last time
  std::size_t observations = 0;       // range/bearing factors added
  std::size_t observations_invalid = 0;  // non-finite or outside the range limits
  std::size_t observations_over_map_limit = 0;  // a new id beyond max_landmarks: dropped
  std::size_t observations_unknown_id = 0;  // an id outside landmark_ids: dropped
  std::size_t keyframes = 0;
  std::size_t solves = 0;

  // Totals over several problems (a long run's segments).
  OptimizerCounters& operator+=(const OptimizerCounters& o) {
    odometry += o.odometry;
    odometry_dropped += o.odometry_dropped;
    frames += o.frames;
    frames_dropped += o.frames_dropped;
    observations += o.observations;
    observations_invalid += o.observations_invalid;
    observations_over_map_limit += o.observations_over_map_limit;
    observations_unknown_id += o.observations_unknown_id;
    keyframes += o.keyframes;
    solves += o.solves;
    return *this;
  }
};

// The whole problem copied out of a MapOptimizer (MapOptimizer::snapshot()):
// solvable on another thread while the optimiser goes on taking data and
// solving windows; its solution goes back with MapOptimizer::adopt().
struct OdometryFactor {
  std::size_t from = 0;  // keyframe indices
  std::size_t to = 0;
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();  // odometry composed between them, in from's frame
  Eigen::Matrix3d sqrt_information = Eigen::Matrix3d::Identity();
  // The turn-rate scale from `to` against from's: s_to - rho s_from, times
  // this (0 without the scale state).
  double scale_rho = 0.0;
  double scale_step_sqrt_information = 0.0;
};
struct ObservationFactor {
  std::size_t keyframe = 0;
  std::size_t landmark = 0;  // index into WholeProblem::landmark_ids
  double range_m = 0.0;
  double bearing_rad = 0.0;
  double range_sigma_m = 1.0;
  double bearing_sigma_rad = 1.0;
};
// A landmark known before the problem began (MapOptimizer::add_landmark_prior):
// a Gaussian prior on its position, whitened (sqrt_information = L^-1 for cov = L L^T).
struct LandmarkPrior {
  std::size_t landmark = 0;  // index into WholeProblem::landmark_ids
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Identity();
};
struct WholeProblem {
  MapOptimizerOptions options;
  std::vector<std::array<double, 3>> poses;  // keyframes; the first held fixed
  std::vector<double> turn_scales;           // per keyframe (empty without the scale state)
  std::vector<int> landmark_ids;
  std::vector<std::array<double, 2>> landmarks;
  std::vector<OdometryFactor> odometry;
  std::vector<ObservationFactor> observations;
  std::vector<LandmarkPrior> landmark_priors;
};
struct WholeSolution {
  std::vector<std::array<double, 3>> poses;
  std::vector<double> turn_scales;
  std::vector<int> landmark_ids;
  std::vector<std::array<double, 2>> landmarks;
  std::vector<Eigen::Matrix2d> landmark_covs;  // NaN when not computed or rank deficient
  SolveSummary summary;
};
// Pure: its own Ceres problem, nothing shared. With `covariances`, the
// landmarks' marginal covariances too.
WholeSolution solve_whole_problem(const WholeProblem& problem, bool covariances);

class MapOptimizer {
 public:
  MapOptimizer(const MapOptimizerOptions& options, const slam::Pose2& start_pose, double start_time_s);
  ~MapOptimizer();
  MapOptimizer(const MapOptimizer&) = delete;
  MapOptimizer& operator=(const MapOptimizer&) = delete;

  // Odometry in time order: held from its time until the next sample's (the
  // filter's zero-order hold; an unmeasured sample keeps the held control,
  // up to control_timeout_s after the last measured one).
  void add_odometry(const slam::OdometrySample& sample);
  // A camera frame: a keyframe at frame.t_s with a factor per valid detection.
  // `guess` (e.g. the filter's pose then) initialises the keyframe; without it,
  // dead reckoning from the previous keyframe. A frame without a valid
  // detection adds nothing but the odometry up to it.
  void add_frame(const slam::ObservationFrame& frame, const std::optional<slam::Pose2>& guess = std::nullopt);
  // The initial value of a landmark not in the problem yet (e.g. the filter's map).
  void set_landmark_guess(int id, const Eigen::Vector2d& position);
  // A landmark known before this problem began (the previous segment of a run
  // too long for one problem): it enters now with the Gaussian prior N(mean,
  // cov) and `observations` earlier sightings. False, and nothing added, for an
  // id already in the problem, a mean that is not finite or beyond 1e6 m, a
  // covariance that is not positive definite, or past max_landmarks.
  bool add_landmark_prior(int id, const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov, std::size_t observations);

  // Solves for every keyframe and landmark, or, with window_keyframes, for the
  // newest that many keyframes and the landmarks they see (the rest held).
  SolveSummary solve(std::optional<std::size_t> window_keyframes = std::nullopt);
  // Landmark marginal covariances of the current solution (one Ceres covariance
  // computation; false and NaN covariances when the problem is rank deficient).
  bool compute_landmark_covariances();
  // The whole problem as it stands, for solve_whole_problem() elsewhere.
  WholeProblem snapshot() const;
  // Takes a solution of an earlier snapshot: its keyframes and landmarks get
  // the solved values; keyframes and landmarks added since move with the
  // rigid correction of the snapshot's newest keyframe (their odometry and
  // observations are relative to it), until the next solve refines them.
  void adopt(const WholeSolution& solution);

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  std::vector<LandmarkSolution> landmarks() const;
  const OptimizerCounters& counters() const { return counters_; }
  // Where the robot is now, as the newest keyframe and the odometry since it
  // (in that keyframe's frame): pose_of() gives the pose in the current
  // solution, so a trajectory recorded as anchors follows every later solve.
  struct PoseAnchor {
    std::size_t keyframe = 0;
    Eigen::Vector3d relative = Eigen::Vector3d::Zero();
  };
  PoseAnchor anchor_now() const;
  slam::Pose2 pose_of(const PoseAnchor& anchor) const;
  slam::Pose2 current_pose() const { return pose_of(anchor_now()); }

 private:
  struct LandmarkBlock {
    std::array<double, 2> xy{};
    Eigen::Matrix2d cov = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
    std::size_t observations = 0;
    std::size_t last_keyframe = 0;  // newest keyframe that sees it
  };
  void integrate_to(double t_s);
  void close_keyframe(double t_s, const std::optional<slam::Pose2>& guess);
  void sync_keyframes();

  MapOptimizerOptions options_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::LossFunction> loss_;  // shared by the observation factors
  std::deque<std::array<double, 3>> pose_blocks_;  // stable addresses for Ceres
  std::deque<double> scale_blocks_;                // per keyframe, with the scale state
  std::vector<Keyframe> keyframes_;                // pose_blocks_ as poses
  std::map<int, LandmarkBlock> landmarks_;
  // The factors as added (snapshot()), landmarks by id.
  std::vector<OdometryFactor> odometry_factors_;
  struct ObservationRecord {
    int landmark_id;
    ObservationFactor factor;  // its landmark index is set by snapshot()
  };
  std::vector<ObservationRecord> observation_records_;
  struct PriorRecord {
    int landmark_id;
    LandmarkPrior prior;  // its landmark index is set by snapshot()
  };
  std::vector<PriorRecord> prior_records_;
  std::map<int, Eigen::Vector2d> landmark_guesses_;
  slam::ComposedMotion open_motion_;  // odometry since the newest keyframe
  std::size_t newest_observations_ = 0;  // observation factors on the newest keyframe
  double last_time_s_ = 0.0;
  double last_measured_s_ = 0.0;
  double keyframe_due_s_ = 0.0;  // a keyframe at the latest then, unless standing still
  double held_v_ = 0.0;
  double held_w_ = 0.0;
  OptimizerCounters counters_;
};

// When to solve while the data come (the map_optimizer process and
// bench_map_optimizer share it): the whole problem every whole_period_s of data
// time, else the newest window_keyframes every window_period_s. A period of 0
// turns that solve off; the caller solves the whole problem at the end. The
// whole problem grows with the run (0.25 s at 15 minutes here, ten times that
// on a Pi-class core): with whole_max_duty, after a whole solve that took T s
// the next waits at least T / whole_max_duty of data time, so whole solves take
// at most that fraction of the run however long it gets (window solves have a
// fixed size).
struct SolveScheduleOptions {
  std::size_t window_keyframes = 100;  // the newest keyframes a window solve frees
  double window_period_s = 1.0;        // data time between window solves
  double whole_period_s = 10.0;        // data time between whole-problem solves
  double whole_max_duty = 0.1;         // 0: no bound
  // No solve on the way: only the caller's solve at the end.
  static SolveScheduleOptions at_end_only() { return {100, 0.0, 0.0, 0.0}; }
};
// Its keys in the `optimizer:` section (config/map_optimizer.yaml).
const parameters::Table<SolveScheduleOptions>& solve_schedule_parameters();

// One --set "optimizer.KEY=V" applied to the table that declares KEY: the
// optimiser's or the schedule's. std::invalid_argument naming an unknown key or
// a bad value.
void apply_optimizer_override(MapOptimizerOptions& options, SolveScheduleOptions& schedule,
                              const std::string& assignment);

enum class SolveKind { kNone, kWindow, kWhole };

class SolveSchedule {
 public:
  SolveSchedule(const SolveScheduleOptions& options, double start_s);
  // The solve due once the data reach t_s; a whole solve also restarts the
  // window period (it solved the window too). While the caller cannot start a
  // whole solve (whole_possible false: the last one still runs elsewhere) a due
  // whole solve stays due, to start at the first call after, and a window may
  // be due meanwhile.
  SolveKind due(double t_s, bool whole_possible = true);
  // A solve due at t_s took `seconds` (CPU): whole_max_duty spaces the next
  // whole solve by it.
  void solved(SolveKind kind, double t_s, double seconds);
  const SolveScheduleOptions& options() const { return options_; }

 private:
  SolveScheduleOptions options_;
  double next_window_s_;
  double next_whole_s_;
};

}  // namespace pixyslam::map_optimizer
