#include "pixyslam/calibration/noise_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/observation_model.h"
#include "pixyslam/offline/segment_eval.h"

namespace pixyslam::calibration {

offline::RunInput apply_parameters(const offline::RunInput& raw, const NoiseParameters& p) {
  offline::RunInput in = raw;
  for (slam::OdometrySample& s : in.odometry) s.t_s += p.odometry_delay_s;
  for (slam::ObservationFrame& f : in.frames) {
    for (slam::RangeBearing& d : f.detections) {
      d.range_m /= p.range_scale * std::pow(std::cos(d.bearing_rad), p.range_cos_bearing_exponent);
    }
  }
  return in;
}

slam::FilterOptions with_parameters(slam::FilterOptions options, const NoiseParameters& p) {
  options.motion.v_sigma_m_per_sqrt_s = p.v_sigma_m_per_sqrt_s;
  options.motion.w_sigma_rad_per_sqrt_s = p.w_sigma_rad_per_sqrt_s;
  options.range_sigma_m = p.range_sigma_m;
  options.bearing_sigma_rad = p.bearing_sigma_rad;
  options.error_correlation_s = p.error_correlation_s;
  return options;
}

namespace {

// P <- F P F^T for a unicycle step's Jacobian F = I + u e3^T, u = (F(0,2),
// F(1,2), 0): P + u p^T + p u^T + P(2,2) u u^T with p = P e3, a dozen flops
// instead of two 3 x 3 products (the calibration's inner loop).
void move_covariance(Eigen::Matrix3d& p, const Eigen::Matrix3d& f) {
  const double u0 = f(0, 2), u1 = f(1, 2);
  const double p02 = p(0, 2), p12 = p(1, 2), p22 = p(2, 2);
  p(0, 0) += 2.0 * u0 * p02 + u0 * u0 * p22;
  p(1, 1) += 2.0 * u1 * p12 + u1 * u1 * p22;
  p(0, 1) = p(1, 0) = p(0, 1) + u0 * p12 + u1 * p02 + u0 * u1 * p22;
  p(0, 2) = p(2, 0) = p02 + u0 * p22;
  p(1, 2) = p(2, 1) = p12 + u1 * p22;
}

// Dead reckoning through time-sorted odometry (zero-order hold, stamps moved by
// `shift`), carrying the pose covariance for a unit v density and for a unit w
// density separately (from zero both are linear in the density squared), and the
// start covariance moved along. One motion step (one sin/cos) serves all three.
class Predictor {
 public:
  Predictor(const std::vector<slam::OdometrySample>& odometry, double shift, bool with_covariance)
      : odometry_(odometry), shift_(shift), with_covariance_(with_covariance) {}

  void reset(const slam::Pose2& pose, double t, const Eigen::Matrix3d& cov) {
    mean_ = pose;
    cov_v_.setZero();
    cov_w_.setZero();
    cov_start_ = cov;
    t_ = t;
    // The control held at t: last sample at or before t.
    next_ = static_cast<std::size_t>(
        std::upper_bound(odometry_.begin(), odometry_.end(), t - shift_,
                         [](double time, const slam::OdometrySample& s) { return time < s.t_s; }) -
        odometry_.begin());
  }

  void advance_to(double t) {
    static const slam::MotionNoise unit_v{1.0, 0.0, 0.0, 0.0, 0.0};
    while (t_ < t) {
      const double segment_end = next_ < odometry_.size() ? std::min(t, odometry_[next_].t_s + shift_) : t;
      const double dt = segment_end - t_;
      if (dt > 0.0) {
        double v = 0.0, w = 0.0;
        if (next_ > 0) {
          v = odometry_[next_ - 1].v_mps;
          w = odometry_[next_ - 1].w_radps;
        }
        if (with_covariance_) {
          const slam::MotionStep step = slam::motion_step(mean_, v, w, dt, unit_v);
          // V Q V^T for a unit w density: the rotation's column of V,
          // (-d/2 sin, d/2 cos, 1) = (F(0,2)/2, F(1,2)/2, 1).
          const Eigen::Vector3d v_a(0.5 * step.f(0, 2), 0.5 * step.f(1, 2), 1.0);
          move_covariance(cov_v_, step.f);
          cov_v_ += step.q;
          move_covariance(cov_w_, step.f);
          cov_w_ += dt * v_a * v_a.transpose();
          move_covariance(cov_start_, step.f);
          mean_ = step.mean;
        } else {
          mean_ = slam::move(mean_, v, w, dt);  // the same mean, without the Jacobians
        }
      }
      t_ = segment_end;
      if (next_ < odometry_.size() && odometry_[next_].t_s + shift_ <= t_) ++next_;
    }
  }

  const slam::Pose2& mean() const { return mean_; }
  const Eigen::Matrix3d& cov_v() const { return cov_v_; }
  const Eigen::Matrix3d& cov_w() const { return cov_w_; }
  const Eigen::Matrix3d& cov_start() const { return cov_start_; }

 private:
  const std::vector<slam::OdometrySample>& odometry_;
  double shift_;
  bool with_covariance_;
  slam::Pose2 mean_ = slam::Pose2::Zero();
  Eigen::Matrix3d cov_v_ = Eigen::Matrix3d::Zero(), cov_w_ = Eigen::Matrix3d::Zero(),
                  cov_start_ = Eigen::Matrix3d::Zero();
  double t_ = 0.0;
  std::size_t next_ = 0;
};

// One observation predicted from an earlier reference pose.
struct Row {
  Eigen::Vector2d e;        // innovation (range, bearing)
  Eigen::Vector2d a_v;      // diag of H A_v H^T
  Eigen::Vector2d a_w;      // diag of H A_w H^T
  Eigen::Vector2d dh_delay = Eigen::Vector2d::Zero(); // d predicted / d delay
  Eigen::Vector2d known = Eigen::Vector2d::Zero();    // diag of H P_start H^T moved to the frame
  double range_m = 0.0;     // measured range (scale applied)
  // d e_range / d c for a relative range scale change c (scale * (1 + c)).
  double de_range_dscale = 0.0;
  // d e_range / d k for a change k of the cos-bearing exponent: -range ln cos(bearing).
  double de_range_dexponent = 0.0;
  int landmark_id = 0;
};

constexpr double kDelayStep = 0.02;

// The odometry in time order (stable: equal stamps keep their input order).
std::vector<slam::OdometrySample> sorted_odometry(const offline::RunInput& in) {
  std::vector<slam::OdometrySample> odometry = in.odometry;
  std::stable_sort(odometry.begin(), odometry.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  return odometry;
}

// Log-likelihood of a (range, bearing) innovation with variances s, each
// normalised square capped at gate2 (an outlier counts as at the gate).
double capped_log_likelihood(const Eigen::Vector2d& e, const Eigen::Vector2d& s, double gate2) {
  return -0.5 * (std::min(e.x() * e.x() / s.x(), gate2) + std::min(e.y() * e.y() / s.y(), gate2) +
                 std::log(4.0 * M_PI * M_PI * s.x() * s.y()));
}

// `odometry`: in.odometry, sorted_odometry().
std::vector<Row> collect_rows(const offline::RunInput& in, const std::vector<slam::OdometrySample>& odometry,
                              const References& refs, const NoiseCalibrationOptions& o, std::size_t* start_frames,
                              std::vector<Row>* pair_rows) {
  std::vector<Row> rows;
  Predictor base(odometry, 0.0, true), shifted(odometry, kDelayStep, false);
  const std::size_t n = in.frames.size();
  // About one row per detection and lag: grown once, not by doubling (a pass's page faults).
  std::size_t detections = 0;
  for (const slam::ObservationFrame& f : in.frames) detections += f.detections.size();
  rows.reserve(detections * static_cast<std::size_t>(std::max(o.max_lags_per_frame, 1)));
  *start_frames = 0;
  std::size_t window_begin = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (j >= refs.has_pose.size() || !refs.has_pose[j]) continue;
    const double t0 = in.frames[j].t_s;
    // Target frames in (t0 + min_lag, t0 + max_lag].
    window_begin = std::max(window_begin, j + 1);
    while (window_begin < n && in.frames[window_begin].t_s < t0 + o.min_lag_s) ++window_begin;
    std::size_t window_end = window_begin;
    while (window_end < n && in.frames[window_end].t_s <= t0 + o.max_lag_s) ++window_end;
    const std::size_t count = window_end - window_begin;
    if (count == 0) continue;
    ++*start_frames;
    const std::size_t stride =
        std::max<std::size_t>(1, (count + static_cast<std::size_t>(o.max_lags_per_frame) - 1) /
                                     static_cast<std::size_t>(o.max_lags_per_frame));
    const Eigen::Matrix3d start_cov = j < refs.frame_cov.size() ? refs.frame_cov[j] : Eigen::Matrix3d::Zero();
    base.reset(refs.frame_pose[j], t0, start_cov);
    shifted.reset(refs.frame_pose[j], t0, Eigen::Matrix3d::Zero());
    for (std::size_t k = window_begin; k < window_end; k += stride) {
      const slam::ObservationFrame& f = in.frames[k];
      base.advance_to(f.t_s);
      shifted.advance_to(f.t_s);
      for (const slam::RangeBearing& d : f.detections) {
        // The same landmark seen at the start frame: its position from that
        // observation, moved by the odometry, against this observation. Ranges
        // at both ends scale, the odometry does not: the range scale without a map.
        for (const slam::RangeBearing& d0 : in.frames[j].detections) {
          if (d0.landmark_id != d.landmark_id) continue;
          const slam::Pose2& x0 = refs.frame_pose[j];
          const Eigen::Vector2d rel(d0.range_m * std::cos(x0.z() + d0.bearing_rad),
                                    d0.range_m * std::sin(x0.z() + d0.bearing_rad));
          const slam::PredictedObservation p = slam::predict_observation(base.mean(), x0.head<2>() + rel);
          Row r;
          r.e = slam::innovation(Eigen::Vector2d(d.range_m, d.bearing_rad), p.z);
          r.a_v = (p.h_pose * base.cov_v() * p.h_pose.transpose()).diagonal();
          r.a_w = (p.h_pose * base.cov_w() * p.h_pose.transpose()).diagonal();
          r.range_m = d.range_m;
          r.de_range_dscale = -d.range_m + (p.h_landmark * rel).x();
          if (std::isfinite(r.e.x())) pair_rows->push_back(r);
        }
        Eigen::Vector2d landmark;
        Eigen::Matrix2d landmark_cov = Eigen::Matrix2d::Zero();
        if (j < refs.frame_landmarks.size()) {
          const auto it = refs.frame_landmarks[j].find(d.landmark_id);
          if (it == refs.frame_landmarks[j].end()) continue;
          landmark = it->second.mean;
          landmark_cov = it->second.cov;
        } else {
          const auto it = refs.landmarks.find(d.landmark_id);
          if (it == refs.landmarks.end()) continue;
          landmark = it->second;
        }
        const slam::PredictedObservation p = slam::predict_observation(base.mean(), landmark);
        const slam::PredictedObservation q = slam::predict_observation(shifted.mean(), landmark);
        Row r;
        r.e = slam::innovation(Eigen::Vector2d(d.range_m, d.bearing_rad), p.z);
        r.a_v = (p.h_pose * base.cov_v() * p.h_pose.transpose()).diagonal();
        r.a_w = (p.h_pose * base.cov_w() * p.h_pose.transpose()).diagonal();
        r.known = (p.h_pose * base.cov_start() * p.h_pose.transpose() +
                   p.h_landmark * landmark_cov * p.h_landmark.transpose())
                      .diagonal();
        r.dh_delay = Eigen::Vector2d(q.z.x() - p.z.x(), slam::wrap_angle(q.z.y() - p.z.y())) / kDelayStep;
        r.range_m = d.range_m;
        r.de_range_dscale = -d.range_m;
        r.de_range_dexponent = -d.range_m * std::log(std::cos(d.bearing_rad));
        r.landmark_id = d.landmark_id;
        if (std::isfinite(r.e.x()) && std::isfinite(r.e.y()) && std::isfinite(r.de_range_dexponent)) rows.push_back(r);
      }
    }
  }
  return rows;
}

// A pair of sightings of one landmark: the second predicted from the first
// moved by the odometry over `lag_s` (no map, no reference pose: the pair's
// geometry is the same wherever the first frame was).
struct PairRow {
  Eigen::Vector2d e;
  Eigen::Vector2d a_v, a_w;  // diag of H A H^T for unit odometry densities
  double lag_s = 0.0;
};

std::vector<PairRow> collect_correlation_pairs(const offline::RunInput& in,
                                               const std::vector<slam::OdometrySample>& odometry,
                                               const NoiseCalibrationOptions& o) {
  std::vector<PairRow> pairs;
  Predictor predictor(odometry, 0.0, true);
  const std::size_t n = in.frames.size();
  for (std::size_t j = 0; j < n; ++j) {
    const slam::ObservationFrame& start = in.frames[j];
    predictor.reset(slam::Pose2::Zero(), start.t_s, Eigen::Matrix3d::Zero());
    double next_lag = o.min_lag_s;
    for (std::size_t k = j + 1; k < n && in.frames[k].t_s - start.t_s <= o.max_lag_s; ++k) {
      const slam::ObservationFrame& f = in.frames[k];
      const double lag = f.t_s - start.t_s;
      if (lag < next_lag) continue;
      while (next_lag <= lag) next_lag *= 1.5;
      predictor.advance_to(f.t_s);
      for (const slam::RangeBearing& d : f.detections) {
        for (const slam::RangeBearing& d0 : start.detections) {
          if (d0.landmark_id != d.landmark_id) continue;
          const Eigen::Vector2d landmark(d0.range_m * std::cos(d0.bearing_rad), d0.range_m * std::sin(d0.bearing_rad));
          const slam::PredictedObservation p = slam::predict_observation(predictor.mean(), landmark);
          PairRow r;
          r.e = slam::innovation(Eigen::Vector2d(d.range_m, d.bearing_rad), p.z);
          r.a_v = (p.h_pose * predictor.cov_v() * p.h_pose.transpose()).diagonal();
          r.a_w = (p.h_pose * predictor.cov_w() * p.h_pose.transpose()).diagonal();
          r.lag_s = lag;
          if (r.e.allFinite()) pairs.push_back(r);
        }
      }
    }
  }
  return pairs;
}

struct CorrelationFit {
  double tau_s = 0.0;
  double range_var = 0.0, bearing_var = 0.0;
  double log_likelihood = -std::numeric_limits<double>::infinity();
};

// Fits (range variance, bearing variance, v and w densities squared) to the
// pairs' squared innovations for one time constant (iteratively reweighted
// least squares, as fit_noise) and scores it by the mean log-likelihood
// (normalised innovations capped at the outlier gate).
CorrelationFit fit_pairs(const std::vector<PairRow>& pairs, double tau_s, const NoiseParameters& start,
                         const NoiseCalibrationOptions& o) {
  using Vector4d = Eigen::Vector4d;
  // Twice the share of the error variance that has changed after each pair's lag.
  std::vector<double> two_g(pairs.size(), 2.0);
  if (tau_s > 0.0) {
    for (std::size_t i = 0; i < pairs.size(); ++i) two_g[i] = 2.0 * (1.0 - std::exp(-pairs[i].lag_s / tau_s));
  }
  Vector4d u(start.range_sigma_m * start.range_sigma_m, start.bearing_sigma_rad * start.bearing_sigma_rad,
             start.v_sigma_m_per_sqrt_s * start.v_sigma_m_per_sqrt_s,
             start.w_sigma_rad_per_sqrt_s * start.w_sigma_rad_per_sqrt_s);
  const Vector4d floor(o.min_range_sigma_m * o.min_range_sigma_m, o.min_bearing_sigma_rad * o.min_bearing_sigma_rad,
                       o.min_odometry_sigma * o.min_odometry_sigma, o.min_odometry_sigma * o.min_odometry_sigma);
  const double gate2 = o.outlier_sigmas * o.outlier_sigmas;
  const auto variances = [&](std::size_t i) {
    const PairRow& r = pairs[i];
    return Eigen::Vector2d(two_g[i] * u(0) + u(2) * r.a_v.x() + u(3) * r.a_w.x() + 1e-12,
                           two_g[i] * u(1) + u(2) * r.a_v.y() + u(3) * r.a_w.y() + 1e-12);
  };
  for (int pass = 0; pass < 6; ++pass) {
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    Vector4d rhs = Vector4d::Zero();
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const PairRow& r = pairs[i];
      const Eigen::Vector2d s = variances(i);
      if (r.e.x() * r.e.x() > gate2 * s.x() || r.e.y() * r.e.y() > gate2 * s.y()) continue;
      const Vector4d range_row(two_g[i], 0.0, r.a_v.x(), r.a_w.x());
      const Vector4d bearing_row(0.0, two_g[i], r.a_v.y(), r.a_w.y());
      normal += range_row * range_row.transpose() / (s.x() * s.x());
      rhs += range_row * (r.e.x() * r.e.x()) / (s.x() * s.x());
      normal += bearing_row * bearing_row.transpose() / (s.y() * s.y());
      rhs += bearing_row * (r.e.y() * r.e.y()) / (s.y() * s.y());
    }
    const Vector4d next = normal.ldlt().solve(rhs);
    if (!next.allFinite()) break;
    u = next.cwiseMax(floor);
  }
  CorrelationFit fit;
  fit.tau_s = tau_s;
  fit.range_var = u(0);
  fit.bearing_var = u(1);
  double log_likelihood = 0.0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const PairRow& r = pairs[i];
    const Eigen::Vector2d s = variances(i);
    log_likelihood += capped_log_likelihood(r.e, s, gate2);
  }
  fit.log_likelihood = log_likelihood / static_cast<double>(pairs.size());
  return fit;
}

// The most likely time constant on a grid (0: white errors).
CorrelationFit fit_error_correlation(const std::vector<PairRow>& pairs, const NoiseParameters& start,
                                     const NoiseCalibrationOptions& o) {
  static constexpr double kGrid[] = {0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0};
  CorrelationFit best;
  for (double tau : kGrid) {
    const CorrelationFit fit = fit_pairs(pairs, tau, start, o);
    if (fit.log_likelihood > best.log_likelihood) best = fit;
  }
  return best;
}

}  // namespace

NoiseParameters fit_noise(const offline::RunInput& raw, const References& references, const NoiseParameters& current,
                          const NoiseCalibrationOptions& options, FitStatistics* statistics) {
  const offline::RunInput in = apply_parameters(raw, current);
  FitStatistics stats;
  std::vector<Row> pair_rows;
  const std::vector<slam::OdometrySample> odometry = sorted_odometry(in);
  const std::vector<Row> rows = collect_rows(in, odometry, references, options, &stats.start_frames, &pair_rows);
  if (rows.size() < 20) {
    throw std::invalid_argument("noise calibration: only " + std::to_string(rows.size()) +
                                " innovations (needs landmarks seen at frames less than max_lag_s apart)");
  }
  // u = (range var, bearing var, v density^2, w density^2, alpha): alpha scales
  // the reference's own part of the variance (the filter's covariances hold the
  // map frame's uncertainty, which cancels between pose and map).
  using Vector5d = Eigen::Matrix<double, 5, 1>;
  using Matrix5d = Eigen::Matrix<double, 5, 5>;
  Vector5d u;
  u << current.range_sigma_m * current.range_sigma_m, current.bearing_sigma_rad * current.bearing_sigma_rad,
      current.v_sigma_m_per_sqrt_s * current.v_sigma_m_per_sqrt_s,
      current.w_sigma_rad_per_sqrt_s * current.w_sigma_rad_per_sqrt_s, 1.0;
  // A pass moves no sigma by more than a factor 3, nor below a floor (a fit on
  // a few hundred innovations can drive one variance to zero, and the next
  // filter pass, trusting that sensor completely, diverges).
  Vector5d floor, ceiling;
  floor.head<4>() = (u.head<4>() / 9.0).cwiseMax(Eigen::Vector4d(options.min_range_sigma_m * options.min_range_sigma_m,
                                         options.min_bearing_sigma_rad * options.min_bearing_sigma_rad,
                                         options.min_odometry_sigma * options.min_odometry_sigma,
                                         options.min_odometry_sigma * options.min_odometry_sigma));
  ceiling.head<4>() = (u.head<4>() * 9.0).cwiseMax(floor.head<4>());
  floor(4) = 0.0;
  ceiling(4) = 1.0;
  const double gate2 = options.outlier_sigmas * options.outlier_sigmas;
  std::vector<bool> inlier(rows.size(), true);
  const auto variances = [&](const Row& r) {
    return Eigen::Vector2d(u(4) * r.known.x() + u(0) + u(2) * r.a_v.x() + u(3) * r.a_w.x(),
                           u(4) * r.known.y() + u(1) + u(2) * r.a_v.y() + u(3) * r.a_w.y());
  };
  // Iteratively reweighted least squares: weights 1 / S^2 (the variance of e^2
  // is 2 S^2), the outlier gate re-drawn with every new estimate.
  for (int pass = 0; pass < 6; ++pass) {
    Matrix5d normal = Matrix5d::Zero();
    Vector5d rhs = Vector5d::Zero();
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      const Eigen::Vector2d s = variances(r);
      inlier[i] = r.e.x() * r.e.x() <= gate2 * s.x() && r.e.y() * r.e.y() <= gate2 * s.y();
      if (!inlier[i]) continue;
      Vector5d range_row, bearing_row;
      range_row << 1.0, 0.0, r.a_v.x(), r.a_w.x(), r.known.x();
      bearing_row << 0.0, 1.0, r.a_v.y(), r.a_w.y(), r.known.y();
      normal += range_row * range_row.transpose() / (s.x() * s.x());
      rhs += range_row * (r.e.x() * r.e.x()) / (s.x() * s.x());
      normal += bearing_row * bearing_row.transpose() / (s.y() * s.y());
      rhs += bearing_row * (r.e.y() * r.e.y()) / (s.y() * s.y());
    }
    if (normal(4, 4) <= 0.0) {  // exact references (ground truth): no known part
      normal.row(4).setZero();
      normal.col(4).setZero();
      normal(4, 4) = 1.0;
      rhs(4) = u(4);
    }
    const Vector5d next = normal.ldlt().solve(rhs);
    if (!next.allFinite()) break;
    u = next.cwiseMax(floor).cwiseMin(ceiling);
  }
  NoiseParameters out = current;
  out.range_sigma_m = std::sqrt(u(0));
  out.bearing_sigma_rad = std::sqrt(u(1));
  out.v_sigma_m_per_sqrt_s = std::sqrt(u(2));
  out.w_sigma_rad_per_sqrt_s = std::sqrt(u(3));

  // Range scale and delay: a Gauss-Newton step on the innovations, weights 1 / S.
  // A relative range scale change c moves the measured range by -c * range; a
  // delay change moves the prediction by dh_delay. Rows are -d e / d(c, d).
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  // The exponent from the range innovations' change with the bearing within each
  // landmark (a fixed-effects fit): the map, built with the current exponent,
  // absorbs a landmark's mean range error, which a plain fit would then miss.
  struct ExponentSums {
    double w = 0.0, x = 0.0, e = 0.0, xx = 0.0, xe = 0.0;
  };
  std::unordered_map<int, ExponentSums> exponent_sums;
  double nis = 0.0, bias = 0.0, bias_weight = 0.0, log_likelihood = 0.0;
  const bool scale_here = options.fit_range_scale && !options.range_scale_from_pairs;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const Eigen::Vector2d s = variances(r);
    log_likelihood += capped_log_likelihood(r.e, s, gate2);
    if (r.e.x() * r.e.x() > gate2 * s.x() || r.e.y() * r.e.y() > gate2 * s.y()) {
      ++stats.outliers;
      continue;
    }
    ++stats.innovations;
    nis += r.e.x() * r.e.x() / s.x() + r.e.y() * r.e.y() / s.y();
    bias += r.e.x() / s.x();
    bias_weight += 1.0 / s.x();
    const Eigen::Vector2d range_row(scale_here ? -r.de_range_dscale : 0.0,
                                    options.fit_odometry_delay ? r.dh_delay.x() : 0.0);
    const Eigen::Vector2d bearing_row(0.0, options.fit_odometry_delay ? r.dh_delay.y() : 0.0);
    normal += range_row * range_row.transpose() / s.x() + bearing_row * bearing_row.transpose() / s.y();
    rhs += range_row * r.e.x() / s.x() + bearing_row * r.e.y() / s.y();
    ExponentSums& k = exponent_sums[r.landmark_id];
    const double w = 1.0 / s.x(), x = -r.de_range_dexponent;
    k.w += w;
    k.x += w * x;
    k.e += w * r.e.x();
    k.xx += w * x * x;
    k.xe += w * x * r.e.x();
  }
  if (options.fit_range_scale && options.range_scale_from_pairs) {
    // Both observations carry range noise.
    for (const Row& r : pair_rows) {
      const double s = 2.0 * u(0) + u(2) * r.a_v.x() + u(3) * r.a_w.x();
      if (r.e.x() * r.e.x() > gate2 * s) continue;
      normal(0, 0) += r.de_range_dscale * r.de_range_dscale / s;
      rhs(0) += -r.de_range_dscale * r.e.x() / s;
    }
  }
  if (!options.fit_range_scale || normal(0, 0) <= 0.0) normal(0, 0) = 1.0;
  if (!options.fit_odometry_delay || normal(1, 1) <= 0.0) normal(1, 1) = 1.0;
  const Eigen::Vector2d step = normal.ldlt().solve(rhs);
  if (step.allFinite()) {
    // measured = scale * true; the corrected range raw / scale has error c * range:
    // the new scale is scale * (1 + c).
    const double c = std::clamp(step.x(), -0.2, 0.2);
    out.range_scale = current.range_scale * (1.0 + c);
    out.odometry_delay_s = current.odometry_delay_s + std::clamp(step.y(), -0.2, 0.2);
  }
  if (options.fit_range_cos_bearing_exponent) {
    // Sum over landmarks of the weighted (co)variances about each one's means.
    double sxx = 0.0, sxe = 0.0;
    for (const auto& [id, k] : exponent_sums) {
      if (k.w <= 0.0) continue;
      sxx += k.xx - k.x * k.x / k.w;
      sxe += k.xe - k.x * k.e / k.w;
    }
    if (sxx > 0.0 && std::isfinite(sxe / sxx)) {
      // mrclam.range_cos_bearing_exponent is read in [0, 3].
      out.range_cos_bearing_exponent =
          std::clamp(current.range_cos_bearing_exponent + std::clamp(sxe / sxx, -1.0, 1.0), 0.0, 3.0);
    }
  }
  if (options.fit_error_correlation) {
    const std::vector<PairRow> pairs = collect_correlation_pairs(in, odometry, options);
    stats.correlation_pairs = pairs.size();
    if (pairs.size() >= 20) {
      const CorrelationFit fit = fit_error_correlation(pairs, current, options);
      out.error_correlation_s = fit.tau_s;
      stats.pair_range_sigma_m = std::sqrt(fit.range_var);
      stats.pair_bearing_sigma_rad = std::sqrt(fit.bearing_var);
    }
  }
  stats.mean_nis = stats.innovations > 0 ? nis / static_cast<double>(stats.innovations) : 0.0;
  stats.range_bias_m = bias_weight > 0.0 ? bias / bias_weight : 0.0;
  stats.mean_log_likelihood = log_likelihood / static_cast<double>(rows.size());
  if (statistics) *statistics = stats;
  return out;
}

References truth_references(const offline::RunInput& raw) {
  if (raw.truth.empty() || raw.landmarks.empty()) {
    throw std::invalid_argument("noise calibration with ground truth: needs robot and landmark ground truth");
  }
  const std::vector<eval::TimedPose> truth = eval::sorted_by_time(raw.truth);
  References refs;
  refs.frame_pose.resize(raw.frames.size(), slam::Pose2::Zero());
  refs.has_pose.resize(raw.frames.size(), false);
  for (std::size_t k = 0; k < raw.frames.size(); ++k) {
    const std::optional<eval::TimedPose> g = offline::interpolate_pose(truth, raw.frames[k].t_s, 0.5);
    if (!g) continue;
    refs.frame_pose[k] = slam::Pose2(g->x_m, g->y_m, g->theta_rad);
    refs.has_pose[k] = true;
  }
  for (const eval::LandmarkPoint& l : raw.landmarks) refs.landmarks[l.id] = Eigen::Vector2d(l.x_m, l.y_m);
  return refs;
}

References filter_references(const offline::RunInput& raw, const slam::FilterOptions& base, const NoiseParameters& p) {
  const offline::RunInput in = apply_parameters(raw, p);
  slam::FilterOptions options = with_parameters(base, p);
  options.frame_uncertainty = false;  // the pose covariance relative to the map
  options.landmark_uncertainty = false;
  slam::FastSlam2 filter(options, in.initial_pose);
  References refs;
  refs.frame_pose.resize(in.frames.size(), slam::Pose2::Zero());
  refs.has_pose.resize(in.frames.size(), false);
  refs.frame_cov.resize(in.frames.size(), Eigen::Matrix3d::Zero());
  // Time order as offline::run_filter: odometry first on equal stamps.
  const std::vector<slam::OdometrySample> odometry = sorted_odometry(in);
  refs.frame_landmarks.resize(in.frames.size());
  slam::OdometrySample control{in.start_time_s, 0.0, 0.0};
  filter.add_odometry(control);
  std::size_t i = 0, k = 0;
  while (i < odometry.size() || k < in.frames.size()) {
    if (k == in.frames.size() || (i < odometry.size() && odometry[i].t_s <= in.frames[k].t_s)) {
      slam::OdometrySample s = odometry[i++];
      if (s.t_s < in.start_time_s) s.t_s = in.start_time_s;
      filter.add_odometry(s);
      control = s;
    } else {
      const slam::ObservationFrame& f = in.frames[k];
      if (f.t_s >= in.start_time_s) {
        // Before the update: the predictive pose and map.
        const slam::PoseEstimate e = filter.pose_estimate();
        refs.frame_pose[k] = slam::move(e.mean, control.v_mps, control.w_radps, std::max(0.0, f.t_s - filter.time_s()));
        refs.frame_cov[k] = e.cov;
        refs.has_pose[k] = true;
        for (const slam::LandmarkEstimate& l : filter.landmarks_of_best()) {
          refs.frame_landmarks[k][l.id] = References::Landmark{l.mean, l.cov};
        }
        filter.add_observations(f);
      }
      ++k;
    }
  }
  for (const slam::LandmarkEstimate& l : filter.landmarks_mixture()) refs.landmarks[l.id] = l.mean;
  return refs;
}

namespace {

bool settled(const NoiseParameters& a, const NoiseParameters& b, const NoiseCalibrationOptions& o) {
  const auto close = [&](double x, double y) { return std::abs(x - y) <= o.relative_tolerance * std::abs(y); };
  return close(a.v_sigma_m_per_sqrt_s, b.v_sigma_m_per_sqrt_s) && close(a.w_sigma_rad_per_sqrt_s, b.w_sigma_rad_per_sqrt_s) &&
         close(a.range_sigma_m, b.range_sigma_m) && close(a.bearing_sigma_rad, b.bearing_sigma_rad) &&
         close(a.range_scale, b.range_scale) && std::abs(a.odometry_delay_s - b.odometry_delay_s) <= o.delay_tolerance_s &&
         std::abs(a.range_cos_bearing_exponent - b.range_cos_bearing_exponent) <= o.exponent_tolerance;
}

// Each pass draws its own particles, so its values scatter about the fixed point
// (w_sigma by +-15 % from pass to pass): the mean of the passes from the third
// (the first two move away from the start values) up to the best one (after it
// the passes explained the data less well, or diverged). Just the best pass
// when it is one of the first two.
NoiseParameters average_of_passes(const std::vector<NoiseIteration>& passes, std::size_t best) {
  const std::size_t first = best >= 2 ? 2 : best;
  NoiseParameters sum;
  sum.v_sigma_m_per_sqrt_s = sum.w_sigma_rad_per_sqrt_s = sum.range_sigma_m = sum.bearing_sigma_rad = 0.0;
  sum.range_scale = sum.range_cos_bearing_exponent = sum.odometry_delay_s = sum.error_correlation_s = 0.0;
  for (std::size_t i = first; i <= best; ++i) {
    const NoiseParameters& p = passes[i].parameters;
    sum.v_sigma_m_per_sqrt_s += p.v_sigma_m_per_sqrt_s;
    sum.w_sigma_rad_per_sqrt_s += p.w_sigma_rad_per_sqrt_s;
    sum.range_sigma_m += p.range_sigma_m;
    sum.bearing_sigma_rad += p.bearing_sigma_rad;
    sum.range_scale += p.range_scale;
    sum.range_cos_bearing_exponent += p.range_cos_bearing_exponent;
    sum.odometry_delay_s += p.odometry_delay_s;
    sum.error_correlation_s += p.error_correlation_s;
  }
  const double n = static_cast<double>(best - first + 1);
  sum.v_sigma_m_per_sqrt_s /= n;
  sum.w_sigma_rad_per_sqrt_s /= n;
  sum.range_sigma_m /= n;
  sum.bearing_sigma_rad /= n;
  sum.range_scale /= n;
  sum.range_cos_bearing_exponent /= n;
  sum.odometry_delay_s /= n;
  sum.error_correlation_s /= n;
  return sum;
}

template <typename Refs>
NoiseCalibration iterate(const offline::RunInput& raw, const NoiseParameters& start, const NoiseCalibrationOptions& o,
                         const Refs& references, const std::function<void(const NoiseIteration&)>& on_iteration) {
  NoiseCalibration result;
  NoiseParameters p = start;
  for (int it = 0; it < o.max_iterations; ++it) {
    NoiseIteration step;
    step.parameters = fit_noise(raw, references(p), p, o, &step.statistics);
    result.iterations.push_back(step);
    if (on_iteration) on_iteration(step);
    const bool done = settled(step.parameters, p, o);
    p = step.parameters;
    if (done) {
      result.converged = true;
      break;
    }
  }
  for (std::size_t i = 0; i < result.iterations.size(); ++i) {
    if (result.iterations[i].statistics.mean_log_likelihood >=
        result.iterations[result.best_iteration].statistics.mean_log_likelihood) {
      result.best_iteration = i;
    }
  }
  result.parameters = result.iterations.empty() ? p : average_of_passes(result.iterations, result.best_iteration);
  return result;
}

}  // namespace

NoiseCalibration calibrate_noise(const offline::RunInput& raw, const slam::FilterOptions& base,
                                 const NoiseParameters& start, const NoiseCalibrationOptions& options,
                                 const std::function<void(const NoiseIteration&)>& on_iteration) {
  offline::RunInput blind = raw;
  blind.truth.clear();
  blind.landmarks.clear();
  NoiseCalibrationOptions o = options;
  o.range_scale_from_pairs = true;
  return iterate(blind, start, o,
                 [&](const NoiseParameters& p) { return filter_references(blind, base, p); }, on_iteration);
}

NoiseCalibration calibrate_noise_with_truth(const offline::RunInput& raw, const NoiseParameters& start,
                                            const NoiseCalibrationOptions& options) {
  const References refs = truth_references(raw);
  NoiseCalibrationOptions o = options;
  o.max_iterations = std::max(o.max_iterations, 12);
  return iterate(raw, start, o, [&](const NoiseParameters&) -> const References& { return refs; }, {});
}

}  // namespace pixyslam::calibration
