#include "pixyslam/map_view/view_transform.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pixyslam::map_view {

namespace {
// Coordinates beyond this are no robot's map (a hostile or broken sample):
// they would shrink the view to nothing.
constexpr double kMaxWorldM = 1e6;
}  // namespace

void WorldBox::extend(double x_m, double y_m) {
  if (!(std::abs(x_m) <= kMaxWorldM) || !(std::abs(y_m) <= kMaxWorldM)) return;
  if (empty) {
    min_x_m = max_x_m = x_m;
    min_y_m = max_y_m = y_m;
    empty = false;
    return;
  }
  min_x_m = std::min(min_x_m, x_m);
  max_x_m = std::max(max_x_m, x_m);
  min_y_m = std::min(min_y_m, y_m);
  max_y_m = std::max(max_y_m, y_m);
}

void WorldBox::extend(const WorldBox& other) {
  if (other.empty) return;
  extend(other.min_x_m, other.min_y_m);
  extend(other.max_x_m, other.max_y_m);
}

ViewTransform::ViewTransform(double pixels_per_metre, double origin_u_px, double origin_v_px)
    : scale_(pixels_per_metre), origin_u_(origin_u_px), origin_v_(origin_v_px) {
  if (!(pixels_per_metre > 0.0) || !std::isfinite(pixels_per_metre) || !std::isfinite(origin_u_px) ||
      !std::isfinite(origin_v_px)) {
    throw std::invalid_argument("ViewTransform: scale must be > 0 and every value finite");
  }
}

ViewTransform ViewTransform::fit(const WorldBox& box, const cv::Rect2d& area, double margin_px, double min_span_m) {
  const double min_span = min_span_m > 1e-3 ? min_span_m : 1e-3;
  const double cx = box.empty ? 0.0 : 0.5 * (box.min_x_m + box.max_x_m);
  const double cy = box.empty ? 0.0 : 0.5 * (box.min_y_m + box.max_y_m);
  const double span_x = box.empty ? min_span : std::max(box.width_m(), min_span);
  const double span_y = box.empty ? min_span : std::max(box.height_m(), min_span);
  // The margin never takes more than a quarter of the area on each side.
  const double margin = std::clamp(margin_px, 0.0, 0.25 * std::min(area.width, area.height));
  const double free_w = std::max(area.width - 2.0 * margin, 1.0);
  const double free_h = std::max(area.height - 2.0 * margin, 1.0);
  const double scale = std::min(free_w / span_x, free_h / span_y);
  const double centre_u = area.x + 0.5 * area.width;
  const double centre_v = area.y + 0.5 * area.height;
  return ViewTransform(scale, centre_u - scale * cx, centre_v + scale * cy);
}

cv::Point2d ViewTransform::to_pixel(double x_m, double y_m) const {
  return {origin_u_ + scale_ * x_m, origin_v_ - scale_ * y_m};
}

Point2 ViewTransform::to_world(const cv::Point2d& pixel) const {
  return {(pixel.x - origin_u_) / scale_, (origin_v_ - pixel.y) / scale_};
}

EllipseAxes covariance_ellipse(double cov_xx_m2, double cov_xy_m2, double cov_yy_m2, double sigma_scale) {
  if (!std::isfinite(cov_xx_m2) || !std::isfinite(cov_xy_m2) || !std::isfinite(cov_yy_m2) ||
      !std::isfinite(sigma_scale)) {
    return {};
  }
  // Closed-form eigen-decomposition of a symmetric 2x2 matrix.
  const double mean = 0.5 * (cov_xx_m2 + cov_yy_m2);
  const double half_diff = 0.5 * (cov_xx_m2 - cov_yy_m2);
  const double radius = std::hypot(half_diff, cov_xy_m2);
  const double l1 = std::max(mean + radius, 0.0);
  const double l2 = std::max(mean - radius, 0.0);
  EllipseAxes axes;
  axes.semi_major_m = sigma_scale * std::sqrt(l1);
  axes.semi_minor_m = sigma_scale * std::sqrt(l2);
  axes.angle_rad = 0.5 * std::atan2(2.0 * cov_xy_m2, cov_xx_m2 - cov_yy_m2);
  return axes;
}

WorldBox ellipse_bounds(const LandmarkView& landmark, double sigma_scale) {
  WorldBox box;
  if (!std::isfinite(landmark.cov_xx_m2) || !std::isfinite(landmark.cov_yy_m2)) {
    box.extend(landmark.x_m, landmark.y_m);
    return box;
  }
  const double hx = sigma_scale * std::sqrt(std::max(landmark.cov_xx_m2, 0.0));
  const double hy = sigma_scale * std::sqrt(std::max(landmark.cov_yy_m2, 0.0));
  box.extend(landmark.x_m - hx, landmark.y_m - hy);
  box.extend(landmark.x_m + hx, landmark.y_m + hy);
  return box;
}

WorldBox content_bounds(const MapViewState& state, double sigma_scale, bool include_truth) {
  WorldBox box;
  for (const Pose2& p : state.particles) box.extend(p.x_m, p.y_m);
  for (const Point2& p : state.mean_trajectory) box.extend(p.x_m, p.y_m);
  if (state.current_pose) box.extend(state.current_pose->x_m, state.current_pose->y_m);
  for (const LandmarkView& l : state.landmarks) {
    if (std::isfinite(l.x_m) && std::isfinite(l.y_m)) box.extend(ellipse_bounds(l, sigma_scale));
  }
  for (const Point2& p : state.optimised_trajectory) box.extend(p.x_m, p.y_m);
  for (const LandmarkView& l : state.optimised_landmarks) {
    if (std::isfinite(l.x_m) && std::isfinite(l.y_m)) box.extend(ellipse_bounds(l, sigma_scale));
  }
  for (const LandmarkView& l : state.fleet_landmarks) {
    if (std::isfinite(l.x_m) && std::isfinite(l.y_m)) box.extend(ellipse_bounds(l, sigma_scale));
  }
  if (include_truth) {
    for (const Point2& p : state.true_trajectory) box.extend(p.x_m, p.y_m);
    if (state.true_pose) box.extend(state.true_pose->x_m, state.true_pose->y_m);
    for (const TrueLandmarkView& l : state.true_landmarks) box.extend(l.x_m, l.y_m);
  }
  for (const MapViewState& other : state.other_robots) {
    MapViewState alone = other;
    alone.other_robots.clear();
    box.extend(content_bounds(alone, sigma_scale, include_truth));
  }
  return box;
}

}  // namespace pixyslam::map_view
