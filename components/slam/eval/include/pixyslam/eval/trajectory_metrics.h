#pragma once

#include <cstddef>
#include <vector>

#include "pixyslam/eval/rigid_alignment.h"

namespace pixyslam::eval {

// A planar pose at a time: t_s in seconds (any epoch, e.g. unix time), position
// in metres and heading theta_rad counter-clockwise from the x axis, all in one
// world frame.
struct TimedPose {
  double t_s;
  double x_m;
  double y_m;
  double theta_rad;
};

// A point landmark with its identifier, position in metres in the world frame.
struct LandmarkPoint {
  int id;
  double x_m;
  double y_m;
};

// The poses in time order (equal times keep their order).
std::vector<TimedPose> sorted_by_time(std::vector<TimedPose> poses);

// Trajectory error statistics over `samples` truth poses: RMSE and maximum of
// the position error (m) and the truth time of that maximum (s), RMSE of the
// wrapped heading error (rad), and the
// position RMSE after the best rigid 2-D alignment of estimate onto truth (m;
// equals ate_rmse_m when fewer than 2 samples).
struct TrajectoryErrors {
  std::size_t samples = 0;
  double ate_rmse_m = 0;
  double heading_rmse_rad = 0;
  double max_position_error_m = 0;
  double max_position_error_t_s = 0;
  double ate_rmse_aligned_m = 0;
};

// Compares an estimated trajectory with ground truth. `estimate` must be sorted
// by time (non-decreasing, finite times); of several estimate poses with equal
// time the last one is used. Every truth pose whose time lies in
// [estimate.front().t_s, estimate.back().t_s] is compared with the estimate
// linearly interpolated at that time (x, y linearly; heading along the shortest
// angular difference). `truth` need not be sorted. Throws std::invalid_argument
// if the estimate is empty or unsorted, or if no truth pose falls in its span.
TrajectoryErrors compare_trajectory(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth);

// The error at one truth pose: estimate (interpolated as above) minus truth.
struct PoseError {
  double t_s = 0.0;
  double position_m = 0.0;   // |estimate - truth|
  double heading_rad = 0.0;  // wrapped estimate - truth
};

// The errors compare_trajectory() aggregates, one per truth pose within the
// estimate's span, in the order of `truth` (e.g. the error over time of a run).
// Same requirements and exceptions as compare_trajectory().
std::vector<PoseError> pose_errors(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth);

// Landmark map error statistics: ids found in both (matched), truth ids absent
// from the estimate (missing), estimate ids absent from the truth (extra); RMSE
// of the position error over matched landmarks, raw and after the best rigid
// 2-D alignment of estimate onto truth (m). Both RMSEs are 0 when nothing is
// matched; the aligned one equals the raw one when fewer than 2 are matched.
struct LandmarkErrors {
  std::size_t matched = 0;
  std::size_t missing = 0;
  std::size_t extra = 0;
  double rmse_m = 0;
  double rmse_aligned_m = 0;
};

// Matches landmarks by id and computes LandmarkErrors. Throws
// std::invalid_argument if an id appears twice in either list.
LandmarkErrors compare_landmarks(const std::vector<LandmarkPoint>& estimate, const std::vector<LandmarkPoint>& truth);

}  // namespace pixyslam::eval
