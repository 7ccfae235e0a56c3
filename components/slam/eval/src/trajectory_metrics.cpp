#include "pixyslam/eval/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace pixyslam::eval {
namespace {

// Root mean square of |aligned(est_i) - truth_i| after fitting est onto truth;
// falls back to the raw RMSE (passed in) when fewer than 2 pairs exist.
double aligned_rmse(const std::vector<Eigen::Vector2d>& est, const std::vector<Eigen::Vector2d>& truth,
                    double raw_rmse) {
  if (est.size() < 2) return raw_rmse;
  const Rigid2 fit = fit_rigid_2d(est, truth);
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) sum_sq += (fit.apply(est[i]) - truth[i]).squaredNorm();
  return std::sqrt(sum_sq / static_cast<double>(est.size()));
}

// The estimate with strictly increasing times: of equal times the last pose wins.
std::vector<TimedPose> strictly_increasing(const std::vector<TimedPose>& estimate) {
  std::vector<TimedPose> knots;
  knots.reserve(estimate.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const TimedPose& p = estimate[i];
    if (!std::isfinite(p.t_s)) {
      throw std::invalid_argument("compare_trajectory: estimate time at index " + std::to_string(i) +
                                  " is not finite");
    }
    if (!knots.empty() && p.t_s < knots.back().t_s) {
      throw std::invalid_argument("compare_trajectory: estimate not sorted by time at index " + std::to_string(i));
    }
    if (!knots.empty() && p.t_s == knots.back().t_s) {
      knots.back() = p;
    } else {
      knots.push_back(p);
    }
  }
  return knots;
}

// Estimate pose at time t, which must lie within [knots.front(), knots.back()].
TimedPose interpolate(const std::vector<TimedPose>& knots, double t) {
  auto upper = std::upper_bound(knots.begin(), knots.end(), t,
                                [](double time, const TimedPose& k) { return time < k.t_s; });
  const TimedPose& a = *(upper - 1);  // last knot with time <= t
  if (upper == knots.end() || a.t_s == t) return a;
  const TimedPose& b = *upper;
  const double alpha = (t - a.t_s) / (b.t_s - a.t_s);
  return TimedPose{t, a.x_m + alpha * (b.x_m - a.x_m), a.y_m + alpha * (b.y_m - a.y_m),
                   wrap_angle(a.theta_rad + alpha * wrap_angle(b.theta_rad - a.theta_rad))};
}

}  // namespace

namespace {

// Each truth pose within the estimate's span with the estimate interpolated at its time.
template <class Visit>
void for_each_pair(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth, const Visit& visit) {
  if (estimate.empty()) throw std::invalid_argument("compare_trajectory: estimate is empty");
  const std::vector<TimedPose> knots = strictly_increasing(estimate);
  const double t_begin = knots.front().t_s;
  const double t_end = knots.back().t_s;
  bool any = false;
  for (const TimedPose& g : truth) {
    if (!(g.t_s >= t_begin && g.t_s <= t_end)) continue;
    visit(interpolate(knots, g.t_s), g);
    any = true;
  }
  if (!any) {
    throw std::invalid_argument("compare_trajectory: no truth pose lies within the estimate's time span [" +
                                std::to_string(t_begin) + ", " + std::to_string(t_end) + "] s");
  }
}

}  // namespace

std::vector<PoseError> pose_errors(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth) {
  std::vector<PoseError> out;
  for_each_pair(estimate, truth, [&](const TimedPose& e, const TimedPose& g) {
    out.push_back({g.t_s, std::hypot(e.x_m - g.x_m, e.y_m - g.y_m), wrap_angle(e.theta_rad - g.theta_rad)});
  });
  return out;
}

TrajectoryErrors compare_trajectory(const std::vector<TimedPose>& estimate, const std::vector<TimedPose>& truth) {
  std::vector<Eigen::Vector2d> est_xy;
  std::vector<Eigen::Vector2d> truth_xy;
  double pos_sum_sq = 0.0;
  double heading_sum_sq = 0.0;
  TrajectoryErrors errors;
  for_each_pair(estimate, truth, [&](const TimedPose& e, const TimedPose& g) {
    const Eigen::Vector2d pe(e.x_m, e.y_m);
    const Eigen::Vector2d pg(g.x_m, g.y_m);
    const double pos_err = (pe - pg).norm();
    const double heading_err = wrap_angle(e.theta_rad - g.theta_rad);
    pos_sum_sq += pos_err * pos_err;
    heading_sum_sq += heading_err * heading_err;
    if (est_xy.empty() || pos_err > errors.max_position_error_m) {
      errors.max_position_error_m = pos_err;
      errors.max_position_error_t_s = g.t_s;
    }
    est_xy.push_back(pe);
    truth_xy.push_back(pg);
  });
  errors.samples = est_xy.size();
  const double n = static_cast<double>(errors.samples);
  errors.ate_rmse_m = std::sqrt(pos_sum_sq / n);
  errors.heading_rmse_rad = std::sqrt(heading_sum_sq / n);
  errors.ate_rmse_aligned_m = aligned_rmse(est_xy, truth_xy, errors.ate_rmse_m);
  return errors;
}

LandmarkErrors compare_landmarks(const std::vector<LandmarkPoint>& estimate, const std::vector<LandmarkPoint>& truth) {
  const auto by_id = [](const std::vector<LandmarkPoint>& points, const char* which) {
    std::map<int, Eigen::Vector2d> m;
    for (const LandmarkPoint& p : points) {
      if (!m.emplace(p.id, Eigen::Vector2d(p.x_m, p.y_m)).second) {
        throw std::invalid_argument(std::string("compare_landmarks: landmark id ") + std::to_string(p.id) +
                                    " appears twice in the " + which);
      }
    }
    return m;
  };
  const std::map<int, Eigen::Vector2d> est = by_id(estimate, "estimate");
  const std::map<int, Eigen::Vector2d> ref = by_id(truth, "truth");

  LandmarkErrors errors;
  std::vector<Eigen::Vector2d> est_xy;
  std::vector<Eigen::Vector2d> truth_xy;
  double sum_sq = 0.0;
  for (const auto& [id, p_truth] : ref) {
    const auto it = est.find(id);
    if (it == est.end()) {
      ++errors.missing;
      continue;
    }
    sum_sq += (it->second - p_truth).squaredNorm();
    est_xy.push_back(it->second);
    truth_xy.push_back(p_truth);
  }
  errors.matched = est_xy.size();
  errors.extra = est.size() - errors.matched;
  if (errors.matched == 0) return errors;
  errors.rmse_m = std::sqrt(sum_sq / static_cast<double>(errors.matched));
  errors.rmse_aligned_m = aligned_rmse(est_xy, truth_xy, errors.rmse_m);
  return errors;
}

std::vector<TimedPose> sorted_by_time(std::vector<TimedPose> poses) {
  std::stable_sort(poses.begin(), poses.end(), [](const TimedPose& a, const TimedPose& b) { return a.t_s < b.t_s; });
  return poses;
}

}  // namespace pixyslam::eval
