#include "pixyslam/offline/segment_eval.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "pixyslam/eval/rigid_alignment.h"

namespace pixyslam::offline {

Summary summarize(std::vector<double> values) {
  Summary s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double rank = q * static_cast<double>(values.size() - 1);
    const std::size_t lo = static_cast<std::size_t>(std::floor(rank));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (rank - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  s.count = values.size();
  double sum = 0.0;
  for (double v : values) sum += v;
  s.mean = sum / static_cast<double>(values.size());
  s.median = quantile(0.5);
  s.p90 = quantile(0.9);
  s.max = values.back();
  return s;
}

std::optional<eval::TimedPose> interpolate_pose(const std::vector<eval::TimedPose>& truth, double t,
                                                double max_gap_s) {
  if (truth.empty() || !(t >= truth.front().t_s && t <= truth.back().t_s)) return std::nullopt;
  const auto upper = std::upper_bound(truth.begin(), truth.end(), t,
                                      [](double time, const eval::TimedPose& p) { return time < p.t_s; });
  const eval::TimedPose& a = *std::prev(upper);  // last pose with time <= t
  if (a.t_s == t || upper == truth.end()) return eval::TimedPose{t, a.x_m, a.y_m, a.theta_rad};
  const eval::TimedPose& b = *upper;
  if (b.t_s - a.t_s > max_gap_s) return std::nullopt;
  const double alpha = (t - a.t_s) / (b.t_s - a.t_s);
  return eval::TimedPose{t, a.x_m + alpha * (b.x_m - a.x_m), a.y_m + alpha * (b.y_m - a.y_m),
                         eval::wrap_angle(a.theta_rad + alpha * eval::wrap_angle(b.theta_rad - a.theta_rad))};
}

std::vector<double> segment_starts(const std::vector<eval::TimedPose>& truth, double every_s) {
  if (!(every_s > 0.0)) throw std::invalid_argument("segment_starts: the period must be positive");
  std::vector<double> starts;
  if (truth.empty()) return starts;
  const double span = truth.back().t_s - truth.front().t_s;
  constexpr double kSlackS = 1e-3;  // unix times: 900 s may come out as 899.9999999
  for (int k = 0; (k + 1) * every_s <= span + kSlackS; ++k) starts.push_back(truth.front().t_s + k * every_s);
  return starts;
}

std::optional<double> pose_nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& cov) {
  if (!cov.allFinite() || !error.allFinite()) return std::nullopt;
  const Eigen::Matrix3d sym = 0.5 * (cov + cov.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sym);
  if (eig.info() != Eigen::Success || eig.eigenvalues().minCoeff() <= 1e-12) return std::nullopt;
  Eigen::Vector3d e = error;
  e.z() = eval::wrap_angle(e.z());
  // e^T V diag(1/lambda) V^T e
  const Eigen::Vector3d in_eigenbasis = eig.eigenvectors().transpose() * e;
  return in_eigenbasis.cwiseAbs2().cwiseQuotient(eig.eigenvalues()).sum();
}

void NeesStats::add(double nees) {
  ++steps;
  sum += nees;
  if (nees >= kNees3Lower95 && nees <= kNees3Upper95) ++inside_95;
  if (nees <= kNees3Upper95) ++below_upper;
}

void NeesStats::merge(const NeesStats& o) {
  steps += o.steps;
  singular += o.singular;
  inside_95 += o.inside_95;
  below_upper += o.below_upper;
  sum += o.sum;
}

NeesStats trajectory_nees(const std::vector<eval::TimedPose>& trajectory,
                          const std::vector<Eigen::Matrix3d>& covariance,
                          const std::vector<eval::TimedPose>& truth) {
  if (trajectory.size() != covariance.size()) {
    throw std::invalid_argument("trajectory_nees: one covariance per trajectory step needed");
  }
  NeesStats stats;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const eval::TimedPose& x = trajectory[i];
    const std::optional<eval::TimedPose> g = interpolate_pose(truth, x.t_s, kTruthMaxGapS);
    if (!g) continue;
    const Eigen::Vector3d e(x.x_m - g->x_m, x.y_m - g->y_m, x.theta_rad - g->theta_rad);
    const std::optional<double> nees = pose_nees(e, covariance[i]);
    if (nees) {
      stats.add(*nees);
    } else {
      ++stats.singular;
    }
  }
  return stats;
}

}  // namespace pixyslam::offline
