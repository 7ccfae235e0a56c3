#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/mrclam/mrclam_dataset.h"

namespace pixyslam::mrclam {

// Fits the MRCLAM sensor and motion corrections of the config's `mrclam:`
// section (pixyslam/offline/offline_run.h, MrclamSensorModel) against the
// ground truth of a set of robots (docs/mrclam.md, "Fitting the corrections").
// Pure: no filter, no files, no printing. Every robot of the set must have
// ground truth; all robots' samples are pooled into one fit.
//
// The ground truth is cleaned first: split into pieces at gaps longer than
// max_truth_gap_s (nothing is interpolated across them), heading unwrapped per
// piece, and x, y and the unwrapped heading each passed through a running median
// of truth_median_samples samples (removes isolated motion-capture glitches and
// keeps ramps). Commands are held (zero-order) from their time stamp until the
// next one, at most control_timeout_s (then 0), as the filter does.
//
// - Range: for each landmark detection with the truth pose (interpolated at its
//   time) and landmark known, true range r*, measured range r and bearing b:
//   log(r / r*) = log(range_scale) + exponent * log(cos b), a robust linear
//   regression (robust_linear_fit). Detections of robots (subjects 1..5) and of
//   subjects without a landmark position are not used.
// - odometry_delay_s: the lag d on the grid delay_min_s:delay_step_s:delay_max_s
//   that maximises the Pearson correlation, pooled over robots, between the
//   commanded turn rate at t - d and the truth yaw rate at t (central difference
//   of the cleaned heading over yaw_rate_window_s, i.e. finite differences
//   smoothed by a moving average), over the times t on a grid of delay_step_s
//   spacing. The same times are used for every lag.
// - speed_scale a and speed_loss_per_radps b, the commands shifted by the fitted
//   delay: over windows of speed_window_s every speed_stride_s, the truth forward
//   speed v* (increments of the cleaned position, each projected on the heading
//   at its middle, summed, over the window length) against the window means of
//   the commanded v and v |w|: v* = a mean(v) - b mean(v |w|) (the model
//   v (a - b |w|) averaged over the window), robust linear regression over the
//   windows whose mean |commanded v| exceeds min_speed_mps.
// - Residuals, for information: the range error after the fitted correction
//   r / (range_scale cos(b)^exponent) - r* and before it (r - r*), and the
//   bearing error wrap(b - b*), each as a robust sd (1.4826 MAD about the
//   median) and a plain RMS over all samples.

struct FitOptions {
  double max_truth_gap_s = 0.5;
  int truth_median_samples = 7;     // odd; 1 disables the median
  double control_timeout_s = 5.0;   // as filter.control_timeout_s of config/slam_mrclam.yaml
  double min_true_range_m = 0.1;
  double min_cos_bearing = 0.2;     // |bearing| < 1.37 rad
  double delay_min_s = 0.0;
  double delay_max_s = 0.5;
  double delay_step_s = 0.01;
  double yaw_rate_window_s = 0.2;
  double speed_window_s = 0.5;
  double speed_stride_s = 0.05;
  double min_speed_mps = 0.05;
};

// Result of robust_linear_fit: coefficients, robust residual sd (1.4826 MAD of
// the residuals about zero), samples used and the inliers of the final fit.
struct RobustLinearFit {
  Eigen::VectorXd coef;
  double sigma = 0.0;
  std::size_t samples = 0;
  std::size_t inliers = 0;
};

// y = X coef, robustly: iteratively reweighted least squares with Huber weights
// min(1, huber_k sigma / |residual|), sigma re-estimated from the MAD of the
// residuals at every iteration, until the coefficients settle; then residuals
// beyond trim_sigmas sigma are dropped and the rest refitted by least squares,
// repeated until the inlier set no longer changes. Throws std::invalid_argument
// when X and y disagree in size, there are fewer rows than 2 x columns, or the
// normal equations are singular.
RobustLinearFit robust_linear_fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, double huber_k = 1.345,
                                  double trim_sigmas = 3.0);

struct RangeFit {
  double range_scale = 1.0;
  double cos_bearing_exponent = 0.0;
  std::size_t samples = 0;          // detections used
  std::size_t inliers = 0;          // in the final regression
  double log_sigma = 0.0;           // robust sd of the log-ratio residuals
  double range_sigma_m = 0.0;       // robust sd of the corrected range error
  double range_rms_m = 0.0;         // RMS of the corrected range error, all samples
  double range_sigma_before_m = 0.0;  // robust sd of r - r*, uncorrected
  double range_rms_before_m = 0.0;
  double bearing_sigma_rad = 0.0;   // robust sd of wrap(b - b*)
  double bearing_rms_rad = 0.0;
  double bearing_median_rad = 0.0;
};

struct DelayFit {
  double delay_s = 0.0;
  double correlation = 0.0;         // at delay_s
  double correlation_at_zero = 0.0; // at the first grid lag (delay_min_s)
  std::size_t samples = 0;          // grid times, every lag
  std::vector<double> lags_s, correlations;  // the whole curve
};

struct SpeedFit {
  double speed_scale = 1.0;
  double speed_loss_per_radps = 0.0;
  std::size_t samples = 0;          // windows used
  std::size_t inliers = 0;
  double sigma_mps = 0.0;           // robust sd of the speed residuals
};

struct CorrectionFit {
  RangeFit range;
  DelayFit delay;
  SpeedFit speed;
};

// The three fits in order (the speed fit uses the fitted delay). `robots` must
// not be empty and every robot needs ground truth (std::invalid_argument
// otherwise, naming the robot); a fit without enough samples throws too.
CorrectionFit fit_corrections(const std::vector<const RobotData*>& robots, const FitOptions& options = {});

// The single fits (fit_speed with a given delay).
RangeFit fit_range(const std::vector<const RobotData*>& robots, const FitOptions& options = {});
DelayFit fit_delay(const std::vector<const RobotData*>& robots, const FitOptions& options = {});
SpeedFit fit_speed(const std::vector<const RobotData*>& robots, double delay_s, const FitOptions& options = {});

}  // namespace pixyslam::mrclam
