#include "pixyslam/map_view/map_view_state.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pixyslam::map_view {

void append_point(std::vector<Point2>& path, Point2 p, double min_step_m) {
  if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) return;
  if (!path.empty() && min_step_m > 0.0) {
    const Point2& last = path.back();
    if (std::hypot(p.x_m - last.x_m, p.y_m - last.y_m) < min_step_m) return;
  }
  path.push_back(p);
}

PathThinning::PathThinning(double min_step_m, std::size_t max_points)
    : min_step_m_(min_step_m), max_points_(std::max<std::size_t>(max_points, 4)) {}

void PathThinning::reset() {
  stride_ = 1;
  appended_ = 0;
  provisional_ = false;
}

void PathThinning::append(std::vector<Point2>& path, Point2 p) {
  if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) return;
  if (provisional_) path.pop_back();  // the newest only stood in at the end
  provisional_ = false;
  const bool far_enough = path.empty() || !(min_step_m_ > 0.0) ||
                          std::hypot(p.x_m - path.back().x_m, p.y_m - path.back().y_m) >= min_step_m_;
  // One in stride_ stays; a point too close to the last one that stays only stands in.
  provisional_ = far_enough ? ++appended_ % stride_ != 0 : true;
  path.push_back(p);
  const std::size_t kept_points = path.size() - (provisional_ ? 1 : 0);
  if (kept_points <= max_points_) return;
  // Every other kept point goes (the first stays); from now on one in twice as many.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < kept_points; i += 2) path[kept++] = path[i];
  if (kept_points % 2 == 0 || provisional_) {
    path[kept++] = path.back();  // the newest stays the last
    provisional_ = true;
  }
  path.resize(kept);
  stride_ *= 2;
  appended_ = 0;
}

std::string format_caption(const CaptionInfo& info) {
  char text[160];
  std::snprintf(text, sizeof text, "t = %.1f s   %u particles   ESS %.1f   %zu landmarks", info.time_s,
                info.particle_count, info.effective_sample_size, info.landmark_count);
  std::string caption(text);
  if (!info.robot_id.empty()) caption += "   " + info.robot_id;
  return caption;
}

}  // namespace pixyslam::map_view
