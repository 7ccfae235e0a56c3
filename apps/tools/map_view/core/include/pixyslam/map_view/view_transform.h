#pragma once

#include <opencv2/core/types.hpp>

#include "pixyslam/map_view/map_view_state.h"

namespace pixyslam::map_view {

// An axis-aligned box of the map frame, metres. Empty until extended;
// non-finite coordinates, and any beyond 1e6 m (no robot's map), are ignored.
struct WorldBox {
  double min_x_m = 0.0;
  double min_y_m = 0.0;
  double max_x_m = 0.0;
  double max_y_m = 0.0;
  bool empty = true;

  void extend(double x_m, double y_m);
  void extend(const WorldBox& other);
  double width_m() const { return max_x_m - min_x_m; }
  double height_m() const { return max_y_m - min_y_m; }
};

// Map frame (metres, y up) -> image pixels (x right, y down) with the same
// scale on both axes: u = origin_u + s * x, v = origin_v - s * y. Pixel
// coordinates are continuous: the centre of pixel (c, r) is (c, r).
// A value type; thread-safe for const use.
class ViewTransform {
 public:
  ViewTransform() = default;
  // Throws std::invalid_argument unless pixels_per_metre > 0 and everything is finite.
  ViewTransform(double pixels_per_metre, double origin_u_px, double origin_v_px);

  // Fits `box` centred into `area` (pixels) leaving at least `margin_px` on every
  // side (less if the area is too small for it). A box narrower than `min_span_m`
  // in x or y (or empty) is widened about its centre; an empty box is centred on
  // the origin. min_span_m <= 0 counts as 1e-3 m.
  static ViewTransform fit(const WorldBox& box, const cv::Rect2d& area, double margin_px, double min_span_m);

  cv::Point2d to_pixel(double x_m, double y_m) const;
  cv::Point2d to_pixel(const Point2& p) const { return to_pixel(p.x_m, p.y_m); }
  Point2 to_world(const cv::Point2d& pixel) const;
  double pixels_per_metre() const { return scale_; }
  double origin_u_px() const { return origin_u_; }
  double origin_v_px() const { return origin_v_; }

 private:
  double scale_ = 1.0;
  double origin_u_ = 0.0;
  double origin_v_ = 0.0;
};

// Semi-axes and orientation of the n-sigma ellipse of a 2x2 covariance:
// eigenvalues l1 >= l2 of [[xx, xy], [xy, yy]], semi-axes n*sqrt(l), and the
// major axis' angle counter-clockwise from the map x axis (in (-pi/2, pi/2]).
// Negative eigenvalues (a numerically broken covariance) count as 0; a
// non-finite input gives all zeros.
struct EllipseAxes {
  double semi_major_m = 0.0;
  double semi_minor_m = 0.0;
  double angle_rad = 0.0;
};
EllipseAxes covariance_ellipse(double cov_xx_m2, double cov_xy_m2, double cov_yy_m2, double sigma_scale);

// Bounding box of the n-sigma ellipse (exact: +/- n*sqrt(cov_xx), n*sqrt(cov_yy)).
WorldBox ellipse_bounds(const LandmarkView& landmark, double sigma_scale);

// Bounding box of everything drawn: particles, every trajectory and pose,
// landmark means with their n-sigma ellipses (the optimised ones too), true
// landmarks. With `include_truth` false the ground truth is left out.
WorldBox content_bounds(const MapViewState& state, double sigma_scale, bool include_truth = true);

}  // namespace pixyslam::map_view
