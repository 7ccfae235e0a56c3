#include "pixyslam/map_view/map_view_state.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pixyslam::map_view {

void append_point(std::vector<Point2>& path, Point2 p, double min_step_m, std::size_t max_points) {
  if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) return;
  if (!path.empty() && min_step_m > 0.0) {
    const Point2& last = path.back();
    if (std::hypot(p.x_m - last.x_m, p.y_m - last.y_m) < min_step_m) return;
  }
  path.push_back(p);
  if (path.size() > std::max<std::size_t>(max_points, 2)) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i + 1 < path.size(); i += 2) path[kept++] = path[i];
    path[kept++] = path.back();
    path.resize(kept);
  }
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
