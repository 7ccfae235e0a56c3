#include "pixyslam/map_view/render_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace pixyslam::map_view {
namespace {

// Sub-pixel drawing: coordinates carry 4 fractional bits.
constexpr int kShift = 4;
constexpr double kSub = 16.0;
// Pixel coordinates are clamped to this before drawing (far-off points).
constexpr double kMaxPixel = 30000.0;
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kPi = 3.14159265358979323846;

bool finite(double a, double b) { return std::isfinite(a) && std::isfinite(b); }

cv::Point sub(const cv::Point2d& p) {
  const double u = std::clamp(p.x, -kMaxPixel, kMaxPixel);
  const double v = std::clamp(p.y, -kMaxPixel, kMaxPixel);
  return {static_cast<int>(std::lround(u * kSub)), static_cast<int>(std::lround(v * kSub))};
}

int sub_length(double px) { return static_cast<int>(std::lround(std::clamp(px, 0.0, kMaxPixel) * kSub)); }

void dot(cv::Mat& img, const cv::Point2d& at, double radius_px, const cv::Scalar& colour) {
  cv::circle(img, sub(at), sub_length(radius_px), colour, cv::FILLED, cv::LINE_AA, kShift);
}

void line(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& colour, int thickness) {
  cv::line(img, sub(a), sub(b), colour, thickness, cv::LINE_AA, kShift);
}

void path(cv::Mat& img, const std::vector<Point2>& points, const ViewTransform& view, const cv::Scalar& colour,
          int thickness) {
  std::vector<cv::Point> pts;
  pts.reserve(points.size());
  for (const Point2& p : points) {
    if (finite(p.x_m, p.y_m)) pts.push_back(sub(view.to_pixel(p)));
  }
  if (pts.size() == 1) pts.push_back(pts.front());
  if (!pts.empty()) cv::polylines(img, pts, false, colour, thickness, cv::LINE_AA, kShift);
}

// An arrow head for a pose, of fixed pixel size: filled, or outlined.
void pose_arrow(cv::Mat& img, const cv::Point2d& centre, double theta_rad, const cv::Scalar& colour, bool filled) {
  const double length = 20.0;
  const double half_width = 6.5;
  const cv::Point2d dir(std::cos(theta_rad), -std::sin(theta_rad));  // image y is down
  const cv::Point2d perp(-dir.y, dir.x);
  const std::vector<cv::Point> tri = {sub(centre + dir * (length * 2.0 / 3.0)),
                                      sub(centre - dir * (length / 3.0) + perp * half_width),
                                      sub(centre - dir * (length / 3.0) - perp * half_width)};
  if (filled) {
    cv::fillConvexPoly(img, tri, colour, cv::LINE_AA, kShift);
  } else {
    cv::polylines(img, tri, true, colour, 2, cv::LINE_AA, kShift);
  }
}

void cross(cv::Mat& img, const cv::Point2d& at, double half_px, const cv::Scalar& colour) {
  line(img, at + cv::Point2d(-half_px, -half_px), at + cv::Point2d(half_px, half_px), colour, 2);
  line(img, at + cv::Point2d(-half_px, half_px), at + cv::Point2d(half_px, -half_px), colour, 2);
}

// An outlined diamond (a square on its corner): the optimised landmarks' marker.
void diamond(cv::Mat& img, const cv::Point2d& at, double half_px, const cv::Scalar& colour) {
  const std::vector<cv::Point> corners = {sub(at + cv::Point2d(0.0, -half_px)), sub(at + cv::Point2d(half_px, 0.0)),
                                          sub(at + cv::Point2d(0.0, half_px)), sub(at + cv::Point2d(-half_px, 0.0))};
  cv::polylines(img, corners, true, colour, 2, cv::LINE_AA, kShift);
}

// An outlined square: the fleet map's landmarks' marker.
void square(cv::Mat& img, const cv::Point2d& at, double half_px, const cv::Scalar& colour) {
  const double h = half_px;
  line(img, {at.x - h, at.y - h}, {at.x + h, at.y - h}, colour, 2);
  line(img, {at.x + h, at.y - h}, {at.x + h, at.y + h}, colour, 2);
  line(img, {at.x + h, at.y + h}, {at.x - h, at.y + h}, colour, 2);
  line(img, {at.x - h, at.y + h}, {at.x - h, at.y - h}, colour, 2);
}

bool finite_covariance(const LandmarkView& l) {
  return std::isfinite(l.cov_xx_m2) && std::isfinite(l.cov_xy_m2) && std::isfinite(l.cov_yy_m2);
}

void landmark_ellipse(cv::Mat& img, const cv::Point2d& centre, const EllipseAxes& axes, double ppm,
                      const cv::Scalar& colour) {
  const cv::Size size(sub_length(axes.semi_major_m * ppm), sub_length(axes.semi_minor_m * ppm));
  // OpenCV's angle turns clockwise on screen; the map's counter-clockwise.
  cv::ellipse(img, sub(centre), size, -axes.angle_rad * 180.0 / kPi, 0.0, 360.0, colour, 1, cv::LINE_AA, kShift);
}

void text(cv::Mat& img, const std::string& s, cv::Point origin, double scale, const cv::Scalar& colour) {
  cv::putText(img, s, origin, kFont, scale, colour, 1, cv::LINE_AA);
}

int text_width(const std::string& s, double scale) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, 1, &baseline).width;
}

std::string format_metres(double value_m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", value_m + 0.0);  // + 0.0: no "-0"
  return buf;
}

void draw_grid(cv::Mat& map, const ViewTransform& view, const RenderOptions& o) {
  const double step = nice_grid_step_m(view.pixels_per_metre(), 70.0);
  const Point2 top_left = view.to_world({0.0, 0.0});
  const Point2 bottom_right = view.to_world({static_cast<double>(map.cols), static_cast<double>(map.rows)});
  const double first_x = std::ceil(top_left.x_m / step);
  const double last_x = std::floor(bottom_right.x_m / step);
  const double first_y = std::ceil(bottom_right.y_m / step);
  const double last_y = std::floor(top_left.y_m / step);
  if (last_x - first_x > 1000.0 || last_y - first_y > 1000.0) return;
  const double bottom = map.rows - 1.0;
  const double right = map.cols - 1.0;
  for (double k = first_x; k <= last_x; k += 1.0) {
    const double u = view.to_pixel(k * step, 0.0).x;
    line(map, {u, 0.0}, {u, bottom}, o.colours.grid, 1);
  }
  for (double k = first_y; k <= last_y; k += 1.0) {
    const double v = view.to_pixel(0.0, k * step).y;
    line(map, {0.0, v}, {right, v}, o.colours.grid, 1);
  }
  // Labels (metres) along the bottom and left edges.
  for (double k = first_x; k <= last_x; k += 1.0) {
    const int u = static_cast<int>(std::lround(view.to_pixel(k * step, 0.0).x));
    text(map, format_metres(k * step), {u + 3, map.rows - 5}, 0.35, o.colours.grid_text);
  }
  for (double k = first_y; k <= last_y; k += 1.0) {
    const int v = static_cast<int>(std::lround(view.to_pixel(0.0, k * step).y));
    if (v < map.rows - 20) text(map, format_metres(k * step), {3, v - 3}, 0.35, o.colours.grid_text);
  }
}

void draw_content(cv::Mat& map, const MapViewState& s, const ViewTransform& view, const RenderOptions& o) {
  const MapColours& c = o.colours;
  if (o.ground_truth) {
    path(map, s.true_trajectory, view, c.truth, 1);
    for (const TrueLandmarkView& l : s.true_landmarks) {
      if (finite(l.x_m, l.y_m)) cross(map, view.to_pixel(l.x_m, l.y_m), 5.0, c.truth);
    }
  }
  for (const Pose2& p : s.particles) {
    if (finite(p.x_m, p.y_m)) dot(map, view.to_pixel(p.x_m, p.y_m), 1.6, c.particle);
  }
  path(map, s.mean_trajectory, view, c.trajectory, 2);

  const double ppm = view.pixels_per_metre();
  for (const LandmarkView& l : s.landmarks) {
    if (!finite(l.x_m, l.y_m)) continue;
    const cv::Point2d at = view.to_pixel(l.x_m, l.y_m);
    landmark_ellipse(map, at, covariance_ellipse(l.cov_xx_m2, l.cov_xy_m2, l.cov_yy_m2, o.sigma_scale), ppm,
                     c.landmark);
    dot(map, at, 3.0, c.landmark);
  }
  if (o.landmark_ids) {
    for (const LandmarkView& l : s.landmarks) {
      if (!finite(l.x_m, l.y_m)) continue;
      const cv::Point2d at = view.to_pixel(l.x_m, l.y_m);
      if (std::abs(at.x) > kMaxPixel || std::abs(at.y) > kMaxPixel) continue;
      text(map, std::to_string(l.id), {static_cast<int>(at.x) + 6, static_cast<int>(at.y) - 6}, 0.42, c.landmark);
    }
  }
  // The map optimiser's solution over the filter's map (no ids: they are the filter's).
  path(map, s.optimised_trajectory, view, c.optimised, 2);
  for (const LandmarkView& l : s.optimised_landmarks) {
    if (!finite(l.x_m, l.y_m)) continue;
    const cv::Point2d at = view.to_pixel(l.x_m, l.y_m);
    if (finite_covariance(l)) {
      landmark_ellipse(map, at, covariance_ellipse(l.cov_xx_m2, l.cov_xy_m2, l.cov_yy_m2, o.sigma_scale), ppm,
                       c.optimised);
    }
    diamond(map, at, 6.0, c.optimised);
  }
  if (o.ground_truth && s.true_pose && finite(s.true_pose->x_m, s.true_pose->y_m) &&
      std::isfinite(s.true_pose->theta_rad)) {
    pose_arrow(map, view.to_pixel(s.true_pose->x_m, s.true_pose->y_m), s.true_pose->theta_rad, c.truth, false);
  }
  if (s.current_pose && finite(s.current_pose->x_m, s.current_pose->y_m) &&
      std::isfinite(s.current_pose->theta_rad)) {
    pose_arrow(map, view.to_pixel(s.current_pose->x_m, s.current_pose->y_m), s.current_pose->theta_rad, c.pose,
               true);
  }
}

// The fleet map: squares with their n-sigma ellipses, over everything else.
void draw_fleet(cv::Mat& map, const MapViewState& s, const ViewTransform& view, const RenderOptions& o) {
  const double ppm = view.pixels_per_metre();
  for (const LandmarkView& l : s.fleet_landmarks) {
    if (!finite(l.x_m, l.y_m)) continue;
    const cv::Point2d at = view.to_pixel(l.x_m, l.y_m);
    if (finite_covariance(l)) {
      landmark_ellipse(map, at, covariance_ellipse(l.cov_xx_m2, l.cov_xy_m2, l.cov_yy_m2, o.sigma_scale), ppm,
                       o.colours.fleet);
    }
    square(map, at, 4.0, o.colours.fleet);
  }
}

// `o` with every colour of an estimate (trajectory, pose, particles,
// landmarks, optimised map) set from `colour`: another robot's.
RenderOptions with_robot_colour(const RenderOptions& o, const cv::Scalar& colour) {
  RenderOptions r = o;
  const cv::Scalar light = (colour + cv::Scalar(255, 255, 255)) * 0.5;
  r.colours.trajectory = colour;
  r.colours.pose = colour * 0.6;
  r.colours.landmark = colour;
  r.colours.particle = light;
  r.colours.optimised = colour;
  return r;
}

// Legend entries left to right from x; an entry that does not fit before
// `limit_x` is left out. Returns the end.
int draw_legend(cv::Mat& img, const MapViewState& s, const RenderOptions& o, int x, int baseline, int limit_x) {
  const MapColours& c = o.colours;
  const double scale = 0.42;
  const int sample_w = 22;
  const double mid = baseline - 4.0;
  auto entry = [&](const std::string& label, auto&& draw_sample) {
    const int width = sample_w + 6 + text_width(label, scale) + 16;
    if (x + width > limit_x) return;
    draw_sample(static_cast<double>(x));
    text(img, label, {x + sample_w + 6, baseline}, scale, c.text);
    x += width;
  };
  if (!s.mean_trajectory.empty() || s.current_pose) {
    entry("mean trajectory", [&](double x0) { line(img, {x0, mid}, {x0 + sample_w, mid}, c.trajectory, 2); });
  }
  if (!s.particles.empty()) {
    entry("particles", [&](double x0) {
      for (double dx : {4.0, 11.0, 18.0}) dot(img, {x0 + dx, mid + (dx == 11.0 ? -2.0 : 2.0)}, 1.6, c.particle);
    });
  }
  if (!s.landmarks.empty()) {
    char label[48];
    std::snprintf(label, sizeof label, "landmark, %g-sigma", o.sigma_scale);
    entry(label, [&](double x0) {
      const cv::Point2d centre(x0 + sample_w / 2.0, mid);
      cv::ellipse(img, sub(centre), cv::Size(sub_length(10.0), sub_length(5.0)), -20.0, 0.0, 360.0, c.landmark, 1,
                  cv::LINE_AA, kShift);
      dot(img, centre, 3.0, c.landmark);
    });
  }
  const bool truth = o.ground_truth && (!s.true_trajectory.empty() || s.true_pose || !s.true_landmarks.empty());
  if (truth) {
    entry("ground truth", [&](double x0) {
      line(img, {x0, mid}, {x0 + sample_w, mid}, c.truth, 1);
      cross(img, {x0 + sample_w / 2.0, mid}, 4.0, c.truth);
    });
  }
  if (!s.optimised_trajectory.empty() || !s.optimised_landmarks.empty()) {
    entry("optimised", [&](double x0) {
      line(img, {x0, mid}, {x0 + sample_w, mid}, c.optimised, 2);
      diamond(img, {x0 + sample_w / 2.0, mid}, 5.0, c.optimised);
    });
  }
  if (!s.fleet_landmarks.empty()) {
    entry("fleet map", [&](double x0) { square(img, {x0 + sample_w / 2.0, mid}, 4.0, c.fleet); });
  }
  if (!s.other_robots.empty() && !s.robot_id.empty()) {
    entry(s.robot_id, [&](double x0) { line(img, {x0, mid}, {x0 + sample_w, mid}, c.trajectory, 3); });
  }
  for (std::size_t k = 0; k < s.other_robots.size(); ++k) {
    const std::string& id = s.other_robots[k].robot_id;
    entry(id.empty() ? "robot " + std::to_string(k + 2) : id,
          [&](double x0) { line(img, {x0, mid}, {x0 + sample_w, mid}, robot_colour(k), 3); });
  }
  return x;
}

// A bar of a nice length ending at right_x; returns its left end (label included).
int draw_scale_bar(cv::Mat& img, const ViewTransform& view, const RenderOptions& o, int right_x, int baseline) {
  const double ppm = view.pixels_per_metre();
  const double length_m = nice_grid_step_m(ppm, 60.0);
  const double length_px = length_m * ppm;
  const double y = baseline - 4.0;
  const double x1 = right_x;
  const double x0 = x1 - length_px;
  line(img, {x0, y}, {x1, y}, o.colours.text, 2);
  line(img, {x0, y - 5.0}, {x0, y + 5.0}, o.colours.text, 1);
  line(img, {x1, y - 5.0}, {x1, y + 5.0}, o.colours.text, 1);
  const std::string label = format_metres(length_m) + " m";
  const int label_x = static_cast<int>(x0) - 8 - text_width(label, 0.42);
  text(img, label, {label_x, baseline}, 0.42, o.colours.text);
  return label_x;
}

std::string fit_text(const std::string& s, double scale, int max_width) {
  if (text_width(s, scale) <= max_width) return s;
  std::string cut = s;
  while (!cut.empty() && text_width(cut + "...", scale) > max_width) cut.pop_back();
  return cut + "...";
}

// Row 1: the legend. Row 2: the caption, and the scale bar on the right.
void draw_footer(cv::Mat& img, const MapViewState& s, const ViewTransform& view, const RenderOptions& o) {
  const int top = o.height_px - o.footer_px;
  line(img, {0.0, static_cast<double>(top)}, {o.width_px - 1.0, static_cast<double>(top)}, o.colours.grid, 1);
  const int pad = 12;
  const bool two_rows = o.footer_px >= 40;
  if (two_rows && o.legend) draw_legend(img, s, o, pad, top + 20, o.width_px - pad);
  if (o.footer_px < 16) return;
  const int baseline = two_rows ? o.height_px - 12 : o.height_px - (o.footer_px - 10) / 2;
  int caption_end = o.width_px - pad;
  if (o.scale_bar) caption_end = draw_scale_bar(img, view, o, o.width_px - pad, baseline) - pad;
  if (!s.caption.empty() && caption_end > pad + 20) {
    text(img, fit_text(s.caption, 0.45, caption_end - pad), {pad, baseline}, 0.45, o.colours.text);
  }
}

}  // namespace

const parameters::Table<RenderOptions>& render_parameters() {
  using O = RenderOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, int>("width_px", kMinMapSidePx, 16384, "px", "image width", [](O& o) -> int& { return o.width_px; }),
      P::integer<O, int>("height_px", kMinMapSidePx, 16384, "px", "image height, footer included",
                         [](O& o) -> int& { return o.height_px; }),
      P::integer<O, int>("footer_px", 0, 16384, "px", "legend, scale bar and caption below the map (0: none)",
                         [](O& o) -> int& { return o.footer_px; }),
      P::real<O>("sigma_scale", 0.1, 10.0, "", "landmark ellipses at this many sigma",
                 [](O& o) -> double& { return o.sigma_scale; }),
      P::real<O>("min_span_m", 0.01, 1e6, "m", "the view never shows less than this",
                 [](O& o) -> double& { return o.min_span_m; }),
      P::boolean<O>("ground_truth", "draw the ground truth when the log has it",
                    [](O& o) -> bool& { return o.ground_truth; }),
      P::boolean<O>("landmark_ids", "label the landmarks", [](O& o) -> bool& { return o.landmark_ids; }),
      P::boolean<O>("grid", "metre grid", [](O& o) -> bool& { return o.grid; }),
      P::boolean<O>("legend", "legend in the footer", [](O& o) -> bool& { return o.legend; }),
      P::boolean<O>("scale_bar", "scale bar in the footer", [](O& o) -> bool& { return o.scale_bar; }),
  };
  return table;
}

void validate(const RenderOptions& o) {
  parameters::check_ranges(o, render_parameters(), "map_view");
  if (o.height_px - o.footer_px < kMinMapSidePx) {
    throw parameters::RuleError("map_view", "height_px",
                                "value " + std::to_string(o.height_px) + " leaves less than " +
                                    std::to_string(kMinMapSidePx) + " px for the map (footer " +
                                    std::to_string(o.footer_px) + " px)");
  }
  if (!(o.margin_px >= 0.0) || !std::isfinite(o.margin_px)) throw std::invalid_argument("margin_px must be >= 0");
}

cv::Rect2d map_area(const RenderOptions& options) {
  return {0.0, 0.0, static_cast<double>(options.width_px), static_cast<double>(options.height_px - options.footer_px)};
}

ViewTransform view_for(const MapViewState& state, const RenderOptions& options) {
  const WorldBox box = options.view ? *options.view : content_bounds(state, options.sigma_scale, options.ground_truth);
  return ViewTransform::fit(box, map_area(options), options.margin_px, options.min_span_m);
}

double nice_grid_step_m(double pixels_per_metre, double min_px) {
  if (!(pixels_per_metre > 0.0) || !std::isfinite(pixels_per_metre) || !std::isfinite(min_px)) return 1.0;
  const double min_m = std::max(min_px, 1e-9) / pixels_per_metre;
  const double decade = std::pow(10.0, std::floor(std::log10(min_m)));
  for (double f : {1.0, 2.0, 5.0, 10.0}) {
    // A relative tolerance so that e.g. exactly 2 m at 1 px/m with min 2 px is accepted.
    if (f * decade >= min_m * (1.0 - 1e-12)) return f * decade;
  }
  return 10.0 * decade;
}

cv::Mat render_map(const MapViewState& state, const RenderOptions& options) {
  validate(options);
  cv::Mat image(options.height_px, options.width_px, CV_8UC3, options.colours.background);
  const ViewTransform view = view_for(state, options);
  // Drawing into the map's own region clips everything to it.
  cv::Mat map = image(cv::Rect(0, 0, options.width_px, options.height_px - options.footer_px));
  if (options.grid) draw_grid(map, view, options);
  for (std::size_t k = 0; k < state.other_robots.size(); ++k) {
    draw_content(map, state.other_robots[k], view, with_robot_colour(options, robot_colour(k)));
  }
  draw_content(map, state, view, options);
  draw_fleet(map, state, view, options);
  if (options.footer_px > 0) draw_footer(image, state, view, options);
  return image;
}

cv::Scalar robot_colour(std::size_t index) {
  static const cv::Scalar kPalette[] = {
      {160, 30, 150},  // purple
      {140, 140, 0},   // teal
      {20, 90, 160},   // brown
      {200, 0, 220},   // magenta
      {0, 130, 130},   // olive
      {90, 90, 90},    // grey
      {220, 150, 0},   // sky blue
      {60, 60, 180},   // brick
      {120, 0, 80},    // indigo
      {0, 200, 200},   // dark yellow
      {150, 80, 230},  // pink
      {100, 160, 60},  // sage
  };
  return kPalette[index % (sizeof kPalette / sizeof kPalette[0])];
}

}  // namespace pixyslam::map_view
