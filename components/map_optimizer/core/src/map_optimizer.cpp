#include "pixyslam/map_optimizer/map_optimizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <ceres/ceres.h>

namespace pixyslam::map_optimizer {
namespace {

// A numerical floor on an odometry factor's covariance (1 mm, 1 mrad): the
// unicycle model gives no sideways noise, and a stationary robot none at all.
constexpr double kOdometryCovarianceFloor = 1e-6;
// A robot parked in view of poles adds every frame's sightings to the newest
// keyframe: past this many it gets a new one (zero motion, the floor above), so
// no keyframe holds an unbounded number of factors and max_keyframes bounds the
// problem of a robot that stands for days. Far above a moving robot's (one
// frame's detections, at most 64).
constexpr std::size_t kMaxObservationsPerKeyframe = 256;

template <typename T>
T wrapped(const T& a) {
  using std::atan2;
  using std::cos;
  using std::sin;
  return atan2(sin(a), cos(a));
}

// Keyframe b seen from keyframe a against the composed odometry (in a's frame),
// its rotation larger by `extra` (the turn-rate scale's share) and its
// displacement turned by half of that (the chord of the arc).
template <typename T>
Eigen::Matrix<T, 3, 1> odometry_error(const T* a, const T* b, const T& extra, const Eigen::Vector3d& delta) {
  using std::cos;
  using std::sin;
  const T dx = b[0] - a[0];
  const T dy = b[1] - a[1];
  const T c = cos(a[2]);
  const T s = sin(a[2]);
  const T ch = cos(extra * T(0.5));
  const T sh = sin(extra * T(0.5));
  const T px = ch * T(delta.x()) - sh * T(delta.y());
  const T py = sh * T(delta.x()) + ch * T(delta.y());
  Eigen::Matrix<T, 3, 1> e;
  e << c * dx + s * dy - px, -s * dx + c * dy - py, wrapped(b[2] - a[2] - T(delta.z()) - extra);
  return e;
}

struct OdometryResidual {
  Eigen::Vector3d delta;
  Eigen::Matrix3d sqrt_information;

  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() * odometry_error(a, b, T(0.0), delta);
    return true;
  }
};

// The same with a's turn-rate scale s: the rotation is (1 + s) times the odometry's.
struct ScaledOdometryResidual {
  Eigen::Vector3d delta;
  Eigen::Matrix3d sqrt_information;

  template <typename T>
  bool operator()(const T* a, const T* b, const T* scale, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() * odometry_error(a, b, scale[0] * T(delta.z()), delta);
    return true;
  }
};

// First-order Gauss-Markov step of the turn-rate scale: s_b = rho s_a + noise.
struct ScaleStepResidual {
  double rho;
  double sqrt_information;

  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    residual[0] = (b[0] - T(rho) * a[0]) * T(sqrt_information);
    return true;
  }
};

// The first keyframe's scale: zero mean, sd turn_scale_sigma (the process's stationary sd).
struct ScalePriorResidual {
  double sqrt_information;

  template <typename T>
  bool operator()(const T* s, T* residual) const {
    residual[0] = s[0] * T(sqrt_information);
    return true;
  }
};

// Paper Eq. 3: z = (|m - p|, atan2(m - p) - theta), whitened by the sigmas.
struct RangeBearingResidual {
  double range_m;
  double bearing_rad;
  double range_sigma_m;
  double bearing_sigma_rad;

  template <typename T>
  bool operator()(const T* pose, const T* landmark, T* residual) const {
    using std::atan2;
    using std::sqrt;
    const T dx = landmark[0] - pose[0];
    const T dy = landmark[1] - pose[1];
    const T q = dx * dx + dy * dy;
    if (!(q > T(1e-12))) return false;  // landmark on the pose: the bearing is undefined
    residual[0] = (T(range_m) - sqrt(q)) / T(range_sigma_m);
    residual[1] = wrapped(T(bearing_rad) - (atan2(dy, dx) - pose[2])) / T(bearing_sigma_rad);
    return true;
  }
};

// A landmark's Gaussian prior: sqrt_information (m - mean).
struct LandmarkPriorResidual {
  Eigen::Vector2d mean;
  Eigen::Matrix2d sqrt_information;

  template <typename T>
  bool operator()(const T* landmark, T* residual) const {
    const Eigen::Matrix<T, 2, 1> e(landmark[0] - T(mean.x()), landmark[1] - T(mean.y()));
    Eigen::Map<Eigen::Matrix<T, 2, 1>> r(residual);
    r = sqrt_information.cast<T>() * e;
    return true;
  }
};

void add_landmark_prior_factor(ceres::Problem& problem, const LandmarkPrior& prior, double* landmark) {
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LandmarkPriorResidual, 2, 2>(
                               new LandmarkPriorResidual{prior.mean, prior.sqrt_information}),
                           nullptr, landmark);
}

bool finite(const slam::Pose2& p) { return p.allFinite(); }

bool scale_state(const MapOptimizerOptions& o) { return o.turn_scale_sigma > 0.0; }

// An odometry factor between two keyframes' blocks, with the turn-rate scale
// step when `scales` (from's, to's) are given.
void add_odometry_factor(ceres::Problem& problem, const OdometryFactor& f, double* from, double* to,
                         double* scale_from = nullptr, double* scale_to = nullptr) {
  if (!scale_from) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<OdometryResidual, 3, 3, 3>(new OdometryResidual{f.delta, f.sqrt_information}),
        nullptr, from, to);
    return;
  }
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledOdometryResidual, 3, 3, 3, 1>(
                               new ScaledOdometryResidual{f.delta, f.sqrt_information}),
                           nullptr, from, to, scale_from);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaleStepResidual, 1, 1, 1>(
                               new ScaleStepResidual{f.scale_rho, f.scale_step_sqrt_information}),
                           nullptr, scale_from, scale_to);
}

void add_scale_prior(ceres::Problem& problem, const MapOptimizerOptions& o, double* scale) {
  problem.AddParameterBlock(scale, 1);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ScalePriorResidual, 1, 1>(
                               new ScalePriorResidual{1.0 / o.turn_scale_sigma}),
                           nullptr, scale);
}

ceres::CostFunction* observation_cost(const ObservationFactor& f) {
  return new ceres::AutoDiffCostFunction<RangeBearingResidual, 2, 3, 2>(
      new RangeBearingResidual{f.range_m, f.bearing_rad, f.range_sigma_m, f.bearing_sigma_rad});
}

ceres::Solver::Options solver_options(const MapOptimizerOptions& o) {
  ceres::Solver::Options solver;
  solver.max_num_iterations = o.max_iterations;
  solver.function_tolerance = o.function_tolerance;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  solver.linear_solver_type = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                                      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
                                  ? ceres::SPARSE_NORMAL_CHOLESKY
                                  : ceres::DENSE_QR;
  return solver;
}

void fill_summary(const ceres::Solver::Summary& summary, SolveSummary& out) {
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.solve_time_s = summary.total_time_in_seconds;
  out.message = summary.message;
}

// Landmark covariances of a solved problem into `covs` (NaN where not computed).
bool landmark_covariances(ceres::Problem& problem, const std::vector<const double*>& landmarks,
                          std::vector<Eigen::Matrix2d>& covs) {
  covs.assign(landmarks.size(), Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  if (landmarks.empty()) return true;
  ceres::Covariance::Options options;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (const double* l : landmarks) blocks.emplace_back(l, l);
  if (!covariance.Compute(blocks, &problem)) return false;
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> c;
    if (covariance.GetCovarianceBlock(landmarks[i], landmarks[i], c.data())) covs[i] = c;
  }
  return true;
}

// a o b for planar poses (x, y, theta).
std::array<double, 3> compose(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  return {a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], slam::wrap_angle(a[2] + b[2])};
}

std::array<double, 3> inverse(const std::array<double, 3>& a) {
  const double c = std::cos(a[2]);
  const double s = std::sin(a[2]);
  return {-c * a[0] - s * a[1], s * a[0] - c * a[1], slam::wrap_angle(-a[2])};
}

}  // namespace

MapOptimizerOptions MapOptimizerOptions::from_filter(const slam::FilterOptions& filter) {
  MapOptimizerOptions o;
  o.motion = filter.motion;
  o.control_timeout_s = filter.control_timeout_s;
  o.max_speed_mps = filter.max_speed_mps;
  o.max_turn_rate_radps = filter.max_turn_rate_radps;
  o.range_sigma_m = filter.range_sigma_m;
  o.range_sigma_per_m = filter.range_sigma_per_m;
  o.bearing_sigma_rad = filter.bearing_sigma_rad;
  o.min_range_m = filter.min_range_m;
  o.max_range_m = filter.max_range_m;
  o.max_landmarks = filter.max_map_landmarks;
  if (filter.association == slam::Association::kKnownId) o.landmark_ids = slam::parse_landmark_ids(filter.landmark_ids);
  return o;
}

const parameters::Table<MapOptimizerOptions>& map_optimizer_parameters() {
  using O = MapOptimizerOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("keyframe_interval_s", 0.01, 3600.0, "s", "a keyframe at most this often (and at each observation)",
                 [](O& o) -> double& { return o.keyframe_interval_s; }),
      P::real<O>("huber_threshold", 1e-3, 1e6, "", "Huber threshold on the whitened residual norm",
                 [](O& o) -> double& { return o.huber_threshold; }),
      P::integer<O, int>("max_iterations", 1, 10000, "", "Ceres iterations per solve at most",
                         [](O& o) -> int& { return o.max_iterations; }),
      P::real<O>("turn_scale_sigma", 0.0, 1.0, "",
                 "sd of the slowly varying turn-rate scale error (heading change (1 + s) x the odometry's; 0: none)",
                 [](O& o) -> double& { return o.turn_scale_sigma; }),
      P::real<O>("turn_scale_correlation_s", 0.1, 1e6, "s", "... its correlation time",
                 [](O& o) -> double& { return o.turn_scale_correlation_s; }),
  };
  return table;
}

void validate(const MapOptimizerOptions& o) {
  parameters::check_ranges(o, map_optimizer_parameters(), "optimizer");
  auto require = [](bool ok, const char* field, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("map optimiser option ") + field + ": " + what);
  };
  require(std::isfinite(o.control_timeout_s) && o.control_timeout_s > 0.0, "control_timeout_s", "must be > 0");
  require(std::isfinite(o.range_sigma_m) && o.range_sigma_m > 0.0, "range_sigma_m", "must be > 0");
  require(std::isfinite(o.range_sigma_per_m) && o.range_sigma_per_m >= 0.0, "range_sigma_per_m", "must be >= 0");
  require(std::isfinite(o.bearing_sigma_rad) && o.bearing_sigma_rad > 0.0, "bearing_sigma_rad", "must be > 0");
  require(std::isfinite(o.min_range_m) && o.min_range_m >= 0.0, "min_range_m", "must be >= 0");
  require(std::isfinite(o.max_range_m) && o.max_range_m > o.min_range_m, "max_range_m", "must be > min_range_m");
  require(o.max_landmarks >= 1, "max_landmarks", "must be >= 1");
  require(std::isfinite(o.function_tolerance) && o.function_tolerance > 0.0, "function_tolerance", "must be > 0");
}

MapOptimizer::MapOptimizer(const MapOptimizerOptions& options, const slam::Pose2& start_pose, double start_time_s)
    : options_(options) {
  validate(options_);
  if (!finite(start_pose) || !std::isfinite(start_time_s)) {
    throw std::invalid_argument("map optimiser: start pose and time must be finite");
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  loss_ = std::make_unique<ceres::HuberLoss>(options_.huber_threshold);
  pose_blocks_.push_back({start_pose.x(), start_pose.y(), slam::wrap_angle(start_pose.z())});
  problem_->AddParameterBlock(pose_blocks_.back().data(), 3);
  problem_->SetParameterBlockConstant(pose_blocks_.back().data());
  if (scale_state(options_)) {
    scale_blocks_.push_back(0.0);
    add_scale_prior(*problem_, options_, &scale_blocks_.back());
  }
  keyframes_.push_back({start_time_s, start_pose});
  last_time_s_ = start_time_s;
  last_measured_s_ = start_time_s;
  keyframe_due_s_ = start_time_s + options_.keyframe_interval_s;
  counters_.keyframes = 1;
}

MapOptimizer::~MapOptimizer() = default;

void MapOptimizer::integrate_to(double t_s) {
  while (last_time_s_ < t_s) {
    double next = std::min(t_s, keyframe_due_s_);
    const double timeout_at = last_measured_s_ + options_.control_timeout_s;
    double v = held_v_;
    double w = held_w_;
    bool measured = true;
    if (last_time_s_ >= timeout_at) {
      // Unknown motion: one stretch up to t_s, whatever its length (a gap of
      // days, or a hostile stamp, must not add a keyframe every interval).
      v = 0.0;
      w = 0.0;
      measured = false;
      next = t_s;
    } else {
      next = std::min(next, timeout_at);
    }
    // A measured standstill (the odometry reports zero) moves nothing and adds
    // no noise: a parked robot adds neither keyframes nor uncertainty.
    if (!(measured && v == 0.0 && w == 0.0)) open_motion_.add(v, w, next - last_time_s_, options_.motion);
    last_time_s_ = next;
    if (next >= keyframe_due_s_) {
      if (open_motion_.empty()) {
        keyframe_due_s_ = next + options_.keyframe_interval_s;
      } else {
        close_keyframe(next, std::nullopt);
      }
    }
  }
}

void MapOptimizer::close_keyframe(double t_s, const std::optional<slam::Pose2>& guess) {
  std::array<double, 3>& previous = pose_blocks_.back();
  const slam::Pose2 from(previous[0], previous[1], previous[2]);
  const double c = std::cos(from.z());
  const double s = std::sin(from.z());
  slam::Pose2 initial = open_motion_.moved_mean(from, c, s);
  // A guess from another process: finite and on a map, else dead reckoning.
  if (guess && finite(*guess) && guess->head<2>().cwiseAbs().maxCoeff() <= 1e6) initial = *guess;
  initial.z() = slam::wrap_angle(initial.z());

  const Eigen::Vector3d delta(open_motion_.displacement().x(), open_motion_.displacement().y(),
                              open_motion_.rotation());
  const Eigen::Matrix3d cov =
      open_motion_.noise(1.0, 0.0) + kOdometryCovarianceFloor * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d lower = cov.llt().matrixL();
  OdometryFactor factor;
  factor.from = pose_blocks_.size() - 1;
  factor.to = pose_blocks_.size();
  factor.delta = delta;
  factor.sqrt_information = lower.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());

  pose_blocks_.push_back({initial.x(), initial.y(), initial.z()});
  double* const before = previous.data();
  double* const after = pose_blocks_.back().data();
  if (scale_state(options_)) {
    const double rho = std::exp(-(t_s - keyframes_.back().t_s) / options_.turn_scale_correlation_s);
    factor.scale_rho = rho;
    factor.scale_step_sqrt_information =
        1.0 / (options_.turn_scale_sigma * std::sqrt(std::max(1e-12, 1.0 - rho * rho)));
    double* const scale_before = &scale_blocks_.back();
    scale_blocks_.push_back(rho * *scale_before);
    add_odometry_factor(*problem_, factor, before, after, scale_before, &scale_blocks_.back());
  } else {
    add_odometry_factor(*problem_, factor, before, after);
  }
  odometry_factors_.push_back(factor);
  keyframes_.push_back({t_s, initial});
  keyframe_due_s_ = t_s + options_.keyframe_interval_s;
  open_motion_.clear();
  newest_observations_ = 0;
  ++counters_.keyframes;
}

void MapOptimizer::add_odometry(const slam::OdometrySample& sample) {
  if (!std::isfinite(sample.t_s) || sample.t_s < last_time_s_ ||
      (sample.measured && !(std::abs(sample.v_mps) <= options_.max_speed_mps &&
                            std::abs(sample.w_radps) <= options_.max_turn_rate_radps))) {
    ++counters_.odometry_dropped;
    return;
  }
  integrate_to(sample.t_s);
  if (sample.measured) {
    held_v_ = sample.v_mps;
    held_w_ = sample.w_radps;
    last_measured_s_ = sample.t_s;
  }
  ++counters_.odometry;
}

void MapOptimizer::add_frame(const slam::ObservationFrame& frame, const std::optional<slam::Pose2>& guess) {
  if (!std::isfinite(frame.t_s) || frame.t_s < last_time_s_) {
    ++counters_.frames_dropped;
    return;
  }
  ++counters_.frames;
  integrate_to(frame.t_s);
  std::vector<const slam::RangeBearing*> valid;
  std::vector<int> new_ids;  // ids this frame adds
  for (const slam::RangeBearing& d : frame.detections) {
    const bool ok = std::isfinite(d.range_m) && std::isfinite(d.bearing_rad) && d.range_m >= options_.min_range_m &&
                    d.range_m <= options_.max_range_m && slam::plausible_sigma(d.range_sigma_m) &&
                    slam::plausible_sigma(d.bearing_sigma_rad);
    const bool known = ok && (landmarks_.count(d.landmark_id) != 0 ||
                              std::find(new_ids.begin(), new_ids.end(), d.landmark_id) != new_ids.end());
    if (!ok) {
      ++counters_.observations_invalid;
    } else if (!options_.landmark_ids.empty() && !slam::contains_id(options_.landmark_ids, d.landmark_id)) {
      ++counters_.observations_unknown_id;
    } else if (!known && landmarks_.size() + new_ids.size() >= static_cast<std::size_t>(options_.max_landmarks)) {
      ++counters_.observations_over_map_limit;
    } else {
      if (!known) new_ids.push_back(d.landmark_id);
      valid.push_back(&d);
    }
  }
  if (valid.empty()) return;
  // A keyframe at the frame time, unless the robot has not moved since the
  // newest one (it is there, or the robot stood still since).
  if (!open_motion_.empty() || newest_observations_ >= kMaxObservationsPerKeyframe) close_keyframe(frame.t_s, guess);
  const std::size_t k = keyframes_.size() - 1;
  double* const pose = pose_blocks_.back().data();
  const slam::Pose2 at(pose[0], pose[1], pose[2]);
  for (const slam::RangeBearing* d : valid) {
    auto [it, inserted] = landmarks_.try_emplace(d->landmark_id);
    LandmarkBlock& lm = it->second;
    if (inserted) {
      const auto g = landmark_guesses_.find(d->landmark_id);
      if (g != landmark_guesses_.end()) {
        lm.xy = {g->second.x(), g->second.y()};
      } else {
        const double heading = at.z() + d->bearing_rad;
        lm.xy = {at.x() + d->range_m * std::cos(heading), at.y() + d->range_m * std::sin(heading)};
      }
      problem_->AddParameterBlock(lm.xy.data(), 2);
    }
    const double range_sigma = d->range_sigma_m > 0.0
                                   ? d->range_sigma_m
                                   : options_.range_sigma_m + options_.range_sigma_per_m * d->range_m;
    const double bearing_sigma = d->bearing_sigma_rad > 0.0 ? d->bearing_sigma_rad : options_.bearing_sigma_rad;
    ObservationFactor factor;
    factor.keyframe = k;
    factor.range_m = d->range_m;
    factor.bearing_rad = d->bearing_rad;
    factor.range_sigma_m = range_sigma;
    factor.bearing_sigma_rad = bearing_sigma;
    problem_->AddResidualBlock(observation_cost(factor), loss_.get(), pose, lm.xy.data());
    observation_records_.push_back({d->landmark_id, factor});
    ++lm.observations;
    lm.last_keyframe = k;
    ++counters_.observations;
    ++newest_observations_;
  }
}

void MapOptimizer::set_landmark_guess(int id, const Eigen::Vector2d& position) {
  // A guess is a first estimate: finite, on a map, and for at most max_landmarks ids.
  if (!position.allFinite() || position.cwiseAbs().maxCoeff() > 1e6) return;
  if (landmark_guesses_.count(id) == 0 &&
      landmark_guesses_.size() >= static_cast<std::size_t>(options_.max_landmarks)) {
    return;
  }
  landmark_guesses_[id] = position;
}

bool MapOptimizer::add_landmark_prior(int id, const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov,
                                      std::size_t observations) {
  if (landmarks_.count(id) != 0 || landmarks_.size() >= static_cast<std::size_t>(options_.max_landmarks)) return false;
  if (!mean.allFinite() || mean.cwiseAbs().maxCoeff() > 1e6 || !cov.allFinite()) return false;
  const Eigen::LLT<Eigen::Matrix2d> llt(0.5 * (cov + cov.transpose()));
  if (llt.info() != Eigen::Success) return false;
  LandmarkPrior prior;
  prior.mean = mean;
  prior.sqrt_information = llt.matrixL().solve(Eigen::Matrix2d::Identity());
  if (!prior.sqrt_information.allFinite()) return false;
  LandmarkBlock& lm = landmarks_[id];
  lm.xy = {mean.x(), mean.y()};
  lm.cov = cov;
  lm.observations = observations;
  lm.last_keyframe = 0;
  problem_->AddParameterBlock(lm.xy.data(), 2);
  add_landmark_prior_factor(*problem_, prior, lm.xy.data());
  prior_records_.push_back({id, prior});
  return true;
}

SolveSummary MapOptimizer::solve(std::optional<std::size_t> window_keyframes) {
  SolveSummary out;
  const std::size_t n = pose_blocks_.size();
  std::size_t first_free = 1;
  if (window_keyframes) first_free = std::max<std::size_t>(1, n > *window_keyframes ? n - *window_keyframes : 0);
  for (std::size_t i = 1; i < first_free; ++i) problem_->SetParameterBlockConstant(pose_blocks_[i].data());
  const std::size_t held_scales = first_free > 1 ? std::min(first_free, scale_blocks_.size()) : 0;
  for (std::size_t i = 0; i < held_scales; ++i) problem_->SetParameterBlockConstant(&scale_blocks_[i]);
  for (auto& [id, lm] : landmarks_) {
    if (lm.last_keyframe < first_free) {
      problem_->SetParameterBlockConstant(lm.xy.data());
    } else {
      ++out.landmarks_free;
    }
  }
  out.keyframes_free = n - first_free;
  out.residuals = static_cast<std::size_t>(problem_->NumResidualBlocks());

  ceres::Solver::Summary summary;
  if (out.keyframes_free > 0 || out.landmarks_free > 0) ceres::Solve(solver_options(options_), problem_.get(), &summary);

  for (std::size_t i = 1; i < first_free; ++i) problem_->SetParameterBlockVariable(pose_blocks_[i].data());
  for (std::size_t i = 0; i < held_scales; ++i) problem_->SetParameterBlockVariable(&scale_blocks_[i]);
  for (auto& [id, lm] : landmarks_) problem_->SetParameterBlockVariable(lm.xy.data());
  sync_keyframes();
  ++counters_.solves;
  fill_summary(summary, out);
  return out;
}

WholeProblem MapOptimizer::snapshot() const {
  WholeProblem p;
  p.options = options_;
  p.poses.assign(pose_blocks_.begin(), pose_blocks_.end());
  p.turn_scales.assign(scale_blocks_.begin(), scale_blocks_.end());
  std::map<int, std::size_t> index;
  for (const auto& [id, lm] : landmarks_) {
    index[id] = p.landmark_ids.size();
    p.landmark_ids.push_back(id);
    p.landmarks.push_back(lm.xy);
  }
  p.odometry = odometry_factors_;
  p.observations.reserve(observation_records_.size());
  for (const ObservationRecord& r : observation_records_) {
    ObservationFactor f = r.factor;
    f.landmark = index.at(r.landmark_id);
    p.observations.push_back(f);
  }
  for (const PriorRecord& r : prior_records_) {
    LandmarkPrior prior = r.prior;
    prior.landmark = index.at(r.landmark_id);
    p.landmark_priors.push_back(prior);
  }
  return p;
}

WholeSolution solve_whole_problem(const WholeProblem& problem, bool covariances) {
  WholeSolution out;
  out.poses = problem.poses;
  out.turn_scales = problem.turn_scales;
  out.landmark_ids = problem.landmark_ids;
  out.landmarks = problem.landmarks;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem p(problem_options);
  ceres::HuberLoss loss(problem.options.huber_threshold);
  for (std::array<double, 3>& pose : out.poses) p.AddParameterBlock(pose.data(), 3);
  if (!out.poses.empty()) p.SetParameterBlockConstant(out.poses.front().data());
  for (std::array<double, 2>& l : out.landmarks) p.AddParameterBlock(l.data(), 2);
  const bool scales = !out.turn_scales.empty();
  if (scales) add_scale_prior(p, problem.options, &out.turn_scales.front());
  for (const OdometryFactor& f : problem.odometry) {
    if (scales) {
      add_odometry_factor(p, f, out.poses.at(f.from).data(), out.poses.at(f.to).data(), &out.turn_scales.at(f.from),
                          &out.turn_scales.at(f.to));
    } else {
      add_odometry_factor(p, f, out.poses.at(f.from).data(), out.poses.at(f.to).data());
    }
  }
  for (const ObservationFactor& f : problem.observations) {
    p.AddResidualBlock(observation_cost(f), &loss, out.poses.at(f.keyframe).data(), out.landmarks.at(f.landmark).data());
  }
  for (const LandmarkPrior& prior : problem.landmark_priors) {
    add_landmark_prior_factor(p, prior, out.landmarks.at(prior.landmark).data());
  }
  out.summary.keyframes_free = out.poses.empty() ? 0 : out.poses.size() - 1;
  out.summary.landmarks_free = out.landmarks.size();
  out.summary.residuals = static_cast<std::size_t>(p.NumResidualBlocks());
  ceres::Solver::Summary summary;
  if (out.summary.keyframes_free > 0 || out.summary.landmarks_free > 0) {
    ceres::Solve(solver_options(problem.options), &p, &summary);
  }
  fill_summary(summary, out.summary);
  for (std::array<double, 3>& pose : out.poses) pose[2] = slam::wrap_angle(pose[2]);
  std::vector<const double*> blocks;
  for (const std::array<double, 2>& l : out.landmarks) blocks.push_back(l.data());
  if (covariances) {
    landmark_covariances(p, blocks, out.landmark_covs);
  } else {
    out.landmark_covs.assign(out.landmarks.size(), Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  return out;
}

void MapOptimizer::adopt(const WholeSolution& solution) {
  const std::size_t n = std::min(solution.poses.size(), pose_blocks_.size());
  if (n == 0) return;
  // The rigid correction of the snapshot's newest keyframe: solved o current^-1.
  const std::array<double, 3> correction = compose(solution.poses[n - 1], inverse(pose_blocks_[n - 1]));
  for (std::size_t i = 0; i < n; ++i) pose_blocks_[i] = solution.poses[i];
  for (std::size_t i = 0; i < std::min(solution.turn_scales.size(), scale_blocks_.size()); ++i) {
    scale_blocks_[i] = solution.turn_scales[i];
  }
  for (std::size_t i = n; i < pose_blocks_.size(); ++i) pose_blocks_[i] = compose(correction, pose_blocks_[i]);
  std::map<int, std::size_t> solved;
  for (std::size_t i = 0; i < solution.landmark_ids.size(); ++i) solved[solution.landmark_ids[i]] = i;
  for (auto& [id, lm] : landmarks_) {
    const auto it = solved.find(id);
    if (it != solved.end()) {
      lm.xy = solution.landmarks[it->second];
      lm.cov = solution.landmark_covs.at(it->second);
    } else {
      const std::array<double, 3> moved = compose(correction, {lm.xy[0], lm.xy[1], 0.0});
      lm.xy = {moved[0], moved[1]};
      lm.cov.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  sync_keyframes();
  ++counters_.solves;
}

void MapOptimizer::sync_keyframes() {
  for (std::size_t i = 0; i < pose_blocks_.size(); ++i) {
    std::array<double, 3>& b = pose_blocks_[i];
    b[2] = slam::wrap_angle(b[2]);
    keyframes_[i].pose = slam::Pose2(b[0], b[1], b[2]);
  }
}

bool MapOptimizer::compute_landmark_covariances() {
  std::vector<const double*> blocks;
  for (const auto& [id, lm] : landmarks_) blocks.push_back(lm.xy.data());
  std::vector<Eigen::Matrix2d> covs;
  const bool ok = landmark_covariances(*problem_, blocks, covs);
  std::size_t i = 0;
  for (auto& [id, lm] : landmarks_) lm.cov = covs[i++];
  return ok;
}

std::vector<LandmarkSolution> MapOptimizer::landmarks() const {
  std::vector<LandmarkSolution> out;
  out.reserve(landmarks_.size());
  for (const auto& [id, lm] : landmarks_) {
    LandmarkSolution s;
    s.id = id;
    s.mean = Eigen::Vector2d(lm.xy[0], lm.xy[1]);
    s.cov = lm.cov;
    s.observations = lm.observations;
    out.push_back(s);
  }
  return out;
}

MapOptimizer::PoseAnchor MapOptimizer::anchor_now() const {
  PoseAnchor a;
  a.keyframe = keyframes_.size() - 1;
  a.relative = Eigen::Vector3d(open_motion_.displacement().x(), open_motion_.displacement().y(),
                               open_motion_.rotation());
  return a;
}

slam::Pose2 MapOptimizer::pose_of(const PoseAnchor& anchor) const {
  const std::array<double, 3> p =
      compose(pose_blocks_.at(anchor.keyframe), {anchor.relative.x(), anchor.relative.y(), anchor.relative.z()});
  return slam::Pose2(p[0], p[1], p[2]);
}

const parameters::Table<SolveScheduleOptions>& solve_schedule_parameters() {
  using O = SolveScheduleOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, std::size_t>("window_keyframes", 1, 1000000, "", "the newest keyframes a window solve frees",
                                 [](O& o) -> std::size_t& { return o.window_keyframes; }),
      P::real<O>("window_period_s", 0.01, 3600.0, "s", "data time between window solves",
                 [](O& o) -> double& { return o.window_period_s; }),
      P::real<O>("whole_period_s", 0.01, 86400.0, "s", "data time between whole-problem solves",
                 [](O& o) -> double& { return o.whole_period_s; }),
      P::real<O>("whole_max_duty", 0.0, 1.0, "", "whole solves take at most this fraction of data time (0: no bound)",
                 [](O& o) -> double& { return o.whole_max_duty; }),
  };
  return table;
}

void apply_optimizer_override(MapOptimizerOptions& options, SolveScheduleOptions& schedule,
                              const std::string& assignment) {
  parameters::apply_override_to_either(options, map_optimizer_parameters(), schedule, solve_schedule_parameters(),
                                       "optimizer", assignment);
}

SolveSchedule::SolveSchedule(const SolveScheduleOptions& options, double start_s)
    : options_(options),
      next_window_s_(start_s + options.window_period_s),
      next_whole_s_(start_s + options.whole_period_s) {}

SolveKind SolveSchedule::due(double t_s, bool whole_possible) {
  if (whole_possible && options_.whole_period_s > 0.0 && t_s >= next_whole_s_) {
    next_whole_s_ = t_s + options_.whole_period_s;
    next_window_s_ = t_s + options_.window_period_s;
    return SolveKind::kWhole;
  }
  if (options_.window_period_s > 0.0 && t_s >= next_window_s_) {
    next_window_s_ = t_s + options_.window_period_s;
    return SolveKind::kWindow;
  }
  return SolveKind::kNone;
}

void SolveSchedule::solved(SolveKind kind, double t_s, double seconds) {
  if (kind != SolveKind::kWhole || !(options_.whole_max_duty > 0.0) || !(seconds > 0.0)) return;
  next_whole_s_ = std::max(next_whole_s_, t_s + seconds / options_.whole_max_duty);
}

}  // namespace pixyslam::map_optimizer
