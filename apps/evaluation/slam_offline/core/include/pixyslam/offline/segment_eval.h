#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::offline {

// Pure helpers of mrclam_eval's segment starts and consistency check
// (docs/mrclam.md, "Segment starts and consistency"); no filter, no printing.

// count, mean, median, 90th percentile and maximum of a sample. Percentiles
// interpolate linearly between order statistics (value at rank q (n - 1), as
// numpy's default). All zero when the sample is empty.
struct Summary {
  std::size_t count = 0;
  double mean = 0.0;
  double median = 0.0;
  double p90 = 0.0;
  double max = 0.0;
};
Summary summarize(std::vector<double> values);


// The pose at time t interpolated between the two truth poses around it (x, y
// linearly, heading along the shorter arc), or nullopt when t lies outside the
// truth or the two poses are more than max_gap_s apart. `truth` sorted by time.
std::optional<eval::TimedPose> interpolate_pose(const std::vector<eval::TimedPose>& truth, double t,
                                                double max_gap_s);

// Segment start times every `every_s` seconds from the first truth pose, each
// with at least `every_s` seconds of truth after it (a 900-s run and 60 s give
// 15 starts: 0, 60, ..., 840 s). `truth` sorted by time; empty without truth.
std::vector<double> segment_starts(const std::vector<eval::TimedPose>& truth, double every_s);

// Chi-square bounds for 3 dof: the two-sided 95 % interval of one sample.
constexpr double kNees3Lower95 = 0.2158;
constexpr double kNees3Upper95 = 9.3484;

// Normalised estimation error squared e^T P^-1 e of a pose error e = (dx, dy,
// dtheta) (dtheta wrapped to (-pi, pi]) under covariance P, or nullopt when P
// is not positive definite (an eigenvalue at or below 1e-12, or not finite).
std::optional<double> pose_nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& cov);

// NEES of an estimated trajectory against the truth, pooled over steps.
struct NeesStats {
  std::size_t steps = 0;          // with truth and a positive-definite covariance
  std::size_t singular = 0;       // with truth, covariance not positive definite (skipped)
  std::size_t inside_95 = 0;      // NEES in [kNees3Lower95, kNees3Upper95]
  std::size_t below_upper = 0;    // NEES <= kNees3Upper95
  double sum = 0.0;

  double mean() const { return steps ? sum / static_cast<double>(steps) : 0.0; }
  double fraction_inside() const { return steps ? static_cast<double>(inside_95) / static_cast<double>(steps) : 0.0; }
  double fraction_below_upper() const {
    return steps ? static_cast<double>(below_upper) / static_cast<double>(steps) : 0.0;
  }
  void add(double nees);
  void merge(const NeesStats& other);
};

// Truth further than this from its neighbours is not interpolated (Vicon gaps).
constexpr double kTruthMaxGapS = 0.5;

// NEES at every trajectory step whose time the truth covers (interpolated,
// kTruthMaxGapS); covariance[i] belongs to trajectory[i] (sizes must match,
// else std::invalid_argument). `truth` sorted by time.
NeesStats trajectory_nees(const std::vector<eval::TimedPose>& trajectory,
                          const std::vector<Eigen::Matrix3d>& covariance,
                          const std::vector<eval::TimedPose>& truth);

}  // namespace pixyslam::offline
