#include "pixyslam/offline/blind_return.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pixyslam/eval/rigid_alignment.h"
#include "pixyslam/offline/segment_eval.h"

namespace pixyslam::offline {

void validate(const BlindReturnOptions& o) {
  const auto non_negative = [](double v, const char* name) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("blind return: ") + name + " must be >= 0");
  };
  non_negative(o.seen_s, "seen_s");
  non_negative(o.blind_s, "blind_s");
  non_negative(o.far_s, "far_s");
  non_negative(o.far_min_range_m, "far_min_range_m");
  if (!(o.after_s > 0.0) || !std::isfinite(o.after_s)) throw std::invalid_argument("blind return: after_s must be > 0");
  if (!std::isfinite(o.heading_bias_radps)) throw std::invalid_argument("blind return: heading_bias_radps must be finite");
}

std::optional<BlindReturnCase> make_blind_return(const RunInput& restarted, const BlindReturnOptions& o) {
  validate(o);
  BlindReturnCase c;
  const double t0 = restarted.start_time_s;
  c.blind_start_s = t0 + o.seen_s;
  c.far_start_s = c.blind_start_s + o.blind_s;
  const double far_end = c.far_start_s + o.far_s;
  const auto is_first = [&](int id) {
    return std::find(c.first_landmarks.begin(), c.first_landmarks.end(), id) != c.first_landmarks.end();
  };
  for (const slam::ObservationFrame& f : restarted.frames) {
    if (f.t_s < t0 || f.t_s >= c.blind_start_s) continue;
    for (const slam::RangeBearing& d : f.detections) {
      if (!is_first(d.landmark_id)) c.first_landmarks.push_back(d.landmark_id);
    }
  }
  if (c.first_landmarks.empty()) return std::nullopt;
  std::sort(c.first_landmarks.begin(), c.first_landmarks.end());

  std::vector<slam::ObservationFrame> frames = restarted.frames;
  std::stable_sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  bool found = false;
  for (const slam::ObservationFrame& f : frames) {
    if (f.t_s < far_end) continue;
    if (std::any_of(f.detections.begin(), f.detections.end(),
                    [&](const slam::RangeBearing& d) { return is_first(d.landmark_id); })) {
      c.return_s = f.t_s;
      found = true;
      break;
    }
  }
  if (!found || c.return_s > far_end + o.after_s) return std::nullopt;
  const double end = c.return_s + o.after_s;
  const std::vector<eval::TimedPose> truth = eval::sorted_by_time(restarted.truth);
  if (truth.empty() || truth.back().t_s < end) return std::nullopt;

  c.input = restarted;
  c.input.frames.clear();
  for (slam::ObservationFrame f : frames) {
    if (f.t_s > end) break;
    if (f.t_s >= c.blind_start_s && f.t_s < c.return_s) {
      std::vector<slam::RangeBearing> kept;
      if (f.t_s >= c.far_start_s) {
        for (const slam::RangeBearing& d : f.detections) {
          if (!is_first(d.landmark_id) && d.range_m >= o.far_min_range_m) kept.push_back(d);
        }
      }
      f.detections = std::move(kept);
    }
    c.input.frames.push_back(std::move(f));
  }
  c.input.odometry.clear();
  for (slam::OdometrySample s : restarted.odometry) {
    if (s.t_s > end) continue;
    if (s.t_s >= c.blind_start_s && s.t_s < c.far_start_s) s.w_radps += o.heading_bias_radps;
    c.input.odometry.push_back(s);
  }
  c.input.truth.clear();
  for (const eval::TimedPose& g : truth) {
    if (g.t_s > end) break;
    c.input.truth.push_back(g);
  }
  return c;
}

ReturnScore score_return(const BlindReturnCase& c, const std::vector<eval::TimedPose>& trajectory) {
  const std::vector<eval::TimedPose>& truth = c.input.truth;  // in time order (make_blind_return)
  ReturnScore s;
  double sum_h2 = 0.0, sum_p2 = 0.0, sum_end = 0.0;
  std::size_t n_end = 0;
  const double end = truth.empty() ? c.return_s : truth.back().t_s;
  for (const eval::TimedPose& x : trajectory) {
    const std::optional<eval::TimedPose> g = interpolate_pose(truth, x.t_s, kTruthMaxGapS);
    if (!g) continue;
    const double dh = std::abs(eval::wrap_angle(x.theta_rad - g->theta_rad));
    if (x.t_s < c.return_s) {
      s.heading_error_at_return_rad = dh;
      continue;
    }
    sum_h2 += dh * dh;
    sum_p2 += (x.x_m - g->x_m) * (x.x_m - g->x_m) + (x.y_m - g->y_m) * (x.y_m - g->y_m);
    ++s.steps_after;
    if (x.t_s >= end - 10.0) {
      sum_end += dh;
      ++n_end;
    }
  }
  if (s.steps_after == 0) throw std::invalid_argument("score_return: no trajectory step with truth after the return");
  const double n = static_cast<double>(s.steps_after);
  s.heading_rmse_after_rad = std::sqrt(sum_h2 / n);
  s.ate_after_m = std::sqrt(sum_p2 / n);
  s.heading_error_end_rad = n_end ? sum_end / static_cast<double>(n_end) : 0.0;
  return s;
}

}  // namespace pixyslam::offline
