#pragma once

#include <cstddef>
#include <functional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/offline/offline_run.h"
#include "pixyslam/slam/slam_options.h"

namespace pixyslam::calibration {

// Sensor description of a robot as the filter and the MRCLAM input use it:
// odometry white-noise densities (filter.motion), observation sigmas
// (filter.observation), the camera's range scale (measured range = scale * true
// range, mrclam.range_scale) and the command-to-motion lag (mrclam.odometry_delay_s).
struct NoiseParameters {
  double v_sigma_m_per_sqrt_s = 0.01;
  double w_sigma_rad_per_sqrt_s = 0.03;
  double range_sigma_m = 0.1;
  double bearing_sigma_rad = 0.05;
  double range_scale = 1.0;
  double range_cos_bearing_exponent = 0.0;
  double odometry_delay_s = 0.0;
  // Time constant of the measurement errors (filter.observation.error_correlation_s; 0: white).
  double error_correlation_s = 0.0;
};

struct NoiseCalibrationOptions {
  int max_iterations = 8;           // filter passes (expectation-maximisation)
  double relative_tolerance = 0.02; // stop when no value moves more than this (sigmas, scale)
  double delay_tolerance_s = 0.01;
  double exponent_tolerance = 0.05;
  // Innovations are predicted from a reference pose at an earlier frame through
  // the odometry, from min_lag_s to max_lag_s before the observation: the
  // growth of their variance with the lag is the odometry noise, the rest the
  // observation noise.
  double min_lag_s = 0.05;
  double max_lag_s = 6.0;
  int max_lags_per_frame = 12;      // earlier frames used per start frame (spread over the window)
  double outlier_sigmas = 4.0;      // innovations beyond this many predicted sd are left out
  // Lower bounds of the fitted sigmas (odometry: both densities).
  double min_range_sigma_m = 0.005;
  double min_bearing_sigma_rad = 0.002;
  double min_odometry_sigma = 0.0005;
  bool fit_range_scale = true;
  bool fit_odometry_delay = true;
  // The exponent from how the range innovations against the map vary with the
  // bearing: the map absorbs a landmark's mean range error, not its change
  // between the bearings it is seen at.
  bool fit_range_cos_bearing_exponent = true;
  // The range scale from pairs of observations of one landmark at two frames
  // (its position from the first, moved by the odometry, against the second):
  // independent of the map, which a filter pass builds with the ranges it is
  // given and so absorbs a range scale. calibrate_noise sets it.
  bool range_scale_from_pairs = false;
  // The measurement errors' time constant from the same pairs at lags spaced
  // by factors of 1.5 from min_lag_s: the variance of a pair's innovation is
  // 2 R (1 - exp(-lag / tau)) plus the odometry's part; tau is the grid value
  // under which the pairs are most likely (0 when white errors explain them
  // best). Off: the start value is kept (and used by the filter passes).
  bool fit_error_correlation = false;
};

// Where the robot was at each frame and where the landmarks are: from the
// filter (blind calibration) or from the ground truth (the comparison).
struct References {
  // One per input frame (same order); has_pose false where unknown.
  std::vector<slam::Pose2> frame_pose;
  std::vector<bool> has_pose;
  // The reference pose's covariance (the filter's; empty: exact poses). Its
  // part of the innovation variance, moved through the odometry, is known.
  std::vector<Eigen::Matrix3d> frame_cov;
  // Per frame, the landmarks as known at that frame (the filter's map before
  // the frame's update, with covariances); empty: `landmarks` for every frame.
  struct Landmark {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  };
  std::vector<std::unordered_map<int, Landmark>> frame_landmarks;
  std::unordered_map<int, Eigen::Vector2d> landmarks;
};

// Statistics of the innovations under the fitted values.
struct FitStatistics {
  std::size_t innovations = 0;       // (observation, lag) pairs used
  std::size_t outliers = 0;          // left out (beyond outlier_sigmas)
  std::size_t start_frames = 0;
  double mean_nis = 0.0;             // mean normalised innovation squared (2 dof: ideal 2)
  double range_bias_m = 0.0;         // mean range innovation at the fitted values (reported only)
  // Mean log-likelihood of every innovation (outliers too, their NIS capped at
  // the gate) under the fitted values: how well the values and the pass's
  // references explain the data. A filter pass that diverged gives references
  // that explain little, whatever values are fitted to them.
  double mean_log_likelihood = 0.0;
  std::size_t correlation_pairs = 0;  // pairs the error correlation was fitted on
  // The pairs' marginal sigmas under the fitted time constant (reported only).
  double pair_range_sigma_m = 0.0;
  double pair_bearing_sigma_rad = 0.0;
};

struct NoiseIteration {
  NoiseParameters parameters;  // after this pass
  FitStatistics statistics;
};

struct NoiseCalibration {
  // The mean over the passes from the third up to the one with the highest
  // mean_log_likelihood (that pass alone when it is the first or second).
  NoiseParameters parameters;
  std::size_t best_iteration = 0;    // its index in `iterations`
  std::vector<NoiseIteration> iterations;
  bool converged = false;            // the values settled (the last pass moved none beyond the tolerances)
};

// The raw input (range scale 1, exponent 0, no delay) with the parameters'
// range model and delay applied: ranges divided by range_scale *
// cos(bearing)^exponent, odometry stamps moved by +delay.
offline::RunInput apply_parameters(const offline::RunInput& raw, const NoiseParameters& p);

// The filter options with the parameters' sigmas and error correlation.
slam::FilterOptions with_parameters(slam::FilterOptions options, const NoiseParameters& p);

// One maximisation step: given references, re-estimates every value from the
// innovations of the raw input's observations predicted from the reference pose
// at earlier frames (current.range_scale and delay applied). The variances come
// from a weighted least-squares fit of the squared range and bearing innovations
// against their predicted variance R + v_sigma^2 A_v + w_sigma^2 A_w +
// alpha (H P H^T + G M G^T) (A from propagating the pose through the odometry
// over the lag; P, M the references' pose and landmark covariances, alpha in
// [0, 1] fitted: they hold the map frame's uncertainty, which cancels); range
// scale (from the map, or from landmark pairs), the range's cos-bearing
// exponent and the delay from a Gauss-Newton step on the innovations. Throws std::invalid_argument when there are too few
// innovations.
NoiseParameters fit_noise(const offline::RunInput& raw, const References& references, const NoiseParameters& current,
                          const NoiseCalibrationOptions& options, FitStatistics* statistics = nullptr);

// References from the ground truth (truth poses interpolated at the frames, the
// true landmarks); throws std::invalid_argument without them.
References truth_references(const offline::RunInput& raw);

// References from one filter pass over the input with these parameters,
// predictive: at every frame the pose before the frame's update (the mean moved
// to the frame's time) with its covariance, and the best particle's map then;
// later observations are independent of them.
References filter_references(const offline::RunInput& raw, const slam::FilterOptions& base,
                             const NoiseParameters& p);

// Blind calibration (never reads raw.truth or raw.landmarks): repeated filter
// passes, each followed by fit_noise on its references, until the values settle
// or max_iterations; the result is the mean of the passes up to the one whose
// values explain the data best (FitStatistics::mean_log_likelihood), so a pass
// whose filter diverged (too small sigmas, the next pass trusting them) does
// not end the calibration, and the pass-to-pass scatter averages out.
NoiseCalibration calibrate_noise(const offline::RunInput& raw, const slam::FilterOptions& base,
                                 const NoiseParameters& start, const NoiseCalibrationOptions& options,
                                 const std::function<void(const NoiseIteration&)>& on_iteration = {});

// The same fit against the ground truth (iterated for scale and delay; no filter).
NoiseCalibration calibrate_noise_with_truth(const offline::RunInput& raw, const NoiseParameters& start,
                                            const NoiseCalibrationOptions& options);

}  // namespace pixyslam::calibration
