#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace pixyslam::slam {

// Robot pose in the map frame: (x [m], y [m], theta [rad]), x forward at theta = 0,
// theta counter-clockwise from the map x axis. The seed paper's Eq. 2
// (x' = v sin(th_p), y' = v cos(th_p)) measures heading th_p clockwise from the y
// axis: theta = pi/2 - th_p.
using Pose2 = Eigen::Vector3d;

// Velocity command/measurement (v [m/s], w [rad/s]) stamped at t_s. The filter
// applies it as a zero-order hold from t_s until the next sample's time.
struct OdometrySample {
  double t_s = 0.0;
  double v_mps = 0.0;
  double w_radps = 0.0;
  // false: no wheel data for the period (an unplugged or stalled encoder), so
  // the motion is unknown, not zero; the filter keeps the control it holds
  // (until control_timeout_s after the last measured sample).
  bool measured = true;
};

// One detection of an identified landmark, in the robot frame. Sigmas <= 0 mean
// "use the filter's configured observation noise".
struct RangeBearing {
  int landmark_id = 0;
  double range_m = 0.0;
  double bearing_rad = 0.0;  // counter-clockwise from the robot's x (forward) axis
  double range_sigma_m = 0.0;
  double bearing_sigma_rad = 0.0;
};

// A detection's own sigma: 0 (or less) = use the configured noise; otherwise it
// must be a usable number (1 um .. 1 km, or rad).
inline bool plausible_sigma(double sigma) {
  return std::isfinite(sigma) && (sigma <= 0.0 || (sigma >= 1e-6 && sigma <= 1e3));
}

// All detections of one camera frame (one timestamp).
struct ObservationFrame {
  double t_s = 0.0;
  std::vector<RangeBearing> detections;
};

// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  if (a > -M_PI && a <= M_PI) return a;  // the common case, without a libm call
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

}  // namespace pixyslam::slam
