// map_view: covariance ellipses, view transform, rendering (pixels where the
// landmark is, 2-sigma extent, determinism), message conversion, MCAP logs.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/mcap/mcap_writer.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/map_view/image_output.h"
#include "pixyslam/map_view/map_log.h"
#include "pixyslam/map_view/map_view_options.h"
#include "pixyslam/map_view/msg_conversion.h"
#include "pixyslam/map_view/render_map.h"
#include "temp_dir.h"

namespace pixyslam::map_view {
namespace {

constexpr double kPi = 3.14159265358979323846;
namespace fs = std::filesystem;


// Covariance with principal std devs (s1, s2), major axis at `angle` (CCW from x).
LandmarkView landmark_with(double x, double y, double s1, double s2, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  LandmarkView l;
  l.id = 7;
  l.x_m = x;
  l.y_m = y;
  l.cov_xx_m2 = c * c * s1 * s1 + s * s * s2 * s2;
  l.cov_yy_m2 = s * s * s1 * s1 + c * c * s2 * s2;
  l.cov_xy_m2 = c * s * (s1 * s1 - s2 * s2);
  return l;
}

// A pixel within `tol` (per channel) of colour `c`.
bool near_colour(const cv::Vec3b& p, const cv::Scalar& c, int tol) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(static_cast<int>(p[i]) - static_cast<int>(c[i])) > tol) return false;
  }
  return true;
}

// "Reddish": the landmark colour blended with white by antialiasing.
bool landmark_like(const cv::Vec3b& p) { return p[2] > 150 && p[1] < 170 && p[0] < 170 && p[2] - p[1] > 60; }

// "Orange": the optimised colour blended with white (green above blue, unlike
// the landmarks' red blends).
bool optimised_like(const cv::Vec3b& p) { return p[2] > 200 && p[0] < 190 && p[1] - p[0] > 30 && p[2] - p[0] > 60; }

int count_like(const cv::Mat& img, bool (*pred)(const cv::Vec3b&)) {
  int n = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) n += pred(img.at<cv::Vec3b>(v, u)) ? 1 : 0;
  return n;
}

bool any_near(const cv::Mat& img, cv::Point2d at, int radius, bool (*pred)(const cv::Vec3b&)) {
  for (int dv = -radius; dv <= radius; ++dv) {
    for (int du = -radius; du <= radius; ++du) {
      const int u = static_cast<int>(std::lround(at.x)) + du, v = static_cast<int>(std::lround(at.y)) + dv;
      if (u >= 0 && v >= 0 && u < img.cols && v < img.rows && pred(img.at<cv::Vec3b>(v, u))) return true;
    }
  }
  return false;
}

RenderOptions plain_options(const WorldBox& view) {
  RenderOptions o;
  o.width_px = 400;
  o.height_px = 400;
  o.footer_px = 0;
  o.grid = false;
  o.landmark_ids = false;
  o.view = view;
  return o;
}

WorldBox box(double x0, double y0, double x1, double y1) {
  WorldBox b;
  b.extend(x0, y0);
  b.extend(x1, y1);
  return b;
}

// ---- covariance ellipse --------------------------------------------------

TEST(CovarianceEllipse, AxisAlignedXMajor) {
  const EllipseAxes e = covariance_ellipse(0.04, 0.0, 0.01, 2.0);
  EXPECT_NEAR(e.semi_major_m, 0.4, 1e-12);
  EXPECT_NEAR(e.semi_minor_m, 0.2, 1e-12);
  EXPECT_NEAR(e.angle_rad, 0.0, 1e-12);
}

TEST(CovarianceEllipse, AxisAlignedYMajorIsAtNinetyDegrees) {
  const EllipseAxes e = covariance_ellipse(0.01, 0.0, 0.09, 1.0);
  EXPECT_NEAR(e.semi_major_m, 0.3, 1e-12);
  EXPECT_NEAR(e.semi_minor_m, 0.1, 1e-12);
  EXPECT_NEAR(e.angle_rad, kPi / 2.0, 1e-12);
}

TEST(CovarianceEllipse, RotatedCovarianceGivesItsPrincipalAxes) {
  // Given covariances built from known principal axes at several angles,
  // when decomposed, then axes and angle come back (angle modulo pi).
  for (double angle : {-1.2, -kPi / 4.0, -0.3, 0.2, kPi / 4.0, 1.0, 1.5}) {
    const LandmarkView l = landmark_with(0.0, 0.0, 0.5, 0.2, angle);
    const EllipseAxes e = covariance_ellipse(l.cov_xx_m2, l.cov_xy_m2, l.cov_yy_m2, 2.0);
    EXPECT_NEAR(e.semi_major_m, 1.0, 1e-9) << angle;
    EXPECT_NEAR(e.semi_minor_m, 0.4, 1e-9) << angle;
    EXPECT_NEAR(e.angle_rad, angle, 1e-9) << angle;
  }
  const EllipseAxes e45 = covariance_ellipse(2.5, 1.5, 2.5, 1.0);  // eigenvalues 4 and 1
  EXPECT_NEAR(e45.semi_major_m, 2.0, 1e-12);
  EXPECT_NEAR(e45.semi_minor_m, 1.0, 1e-12);
  EXPECT_NEAR(e45.angle_rad, kPi / 4.0, 1e-12);
}

TEST(CovarianceEllipse, BrokenCovariancesDoNotProduceNaN) {
  const EllipseAxes indefinite = covariance_ellipse(1.0, 2.0, 1.0, 1.0);  // eigenvalues 3, -1
  EXPECT_NEAR(indefinite.semi_major_m, std::sqrt(3.0), 1e-12);
  EXPECT_EQ(indefinite.semi_minor_m, 0.0);
  const EllipseAxes nan = covariance_ellipse(std::nan(""), 0.0, 1.0, 2.0);
  EXPECT_EQ(nan.semi_major_m, 0.0);
  EXPECT_EQ(nan.semi_minor_m, 0.0);
  const EllipseAxes circle = covariance_ellipse(0.25, 0.0, 0.25, 2.0);
  EXPECT_NEAR(circle.semi_major_m, 1.0, 1e-12);
  EXPECT_NEAR(circle.semi_minor_m, 1.0, 1e-12);
}

TEST(CovarianceEllipse, BoundsAreTheExactExtent) {
  const LandmarkView l = landmark_with(1.0, -2.0, 0.5, 0.1, 0.7);
  const WorldBox b = ellipse_bounds(l, 2.0);
  // The extreme x of the ellipse, sampled densely, touches the box.
  const EllipseAxes e = covariance_ellipse(l.cov_xx_m2, l.cov_xy_m2, l.cov_yy_m2, 2.0);
  double max_x = -1e9, max_y = -1e9;
  for (int i = 0; i < 100000; ++i) {
    const double t = 2.0 * kPi * i / 100000.0;
    const double x = e.semi_major_m * std::cos(t) * std::cos(e.angle_rad) - e.semi_minor_m * std::sin(t) * std::sin(e.angle_rad);
    const double y = e.semi_major_m * std::cos(t) * std::sin(e.angle_rad) + e.semi_minor_m * std::sin(t) * std::cos(e.angle_rad);
    max_x = std::max(max_x, x);
    max_y = std::max(max_y, y);
  }
  EXPECT_NEAR(b.max_x_m - l.x_m, max_x, 1e-6);
  EXPECT_NEAR(b.max_y_m - l.y_m, max_y, 1e-6);
  EXPECT_NEAR(l.x_m - b.min_x_m, max_x, 1e-6);
}

// ---- view transform --------------------------------------------------------

TEST(ViewTransform, PixelWorldRoundTrip) {
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> d(-50.0, 50.0);
  const ViewTransform t(37.5, 120.25, 480.5);
  for (int i = 0; i < 1000; ++i) {
    const Point2 p{d(prng), d(prng)};
    const Point2 q = t.to_world(t.to_pixel(p));
    EXPECT_NEAR(q.x_m, p.x_m, 1e-9);
    EXPECT_NEAR(q.y_m, p.y_m, 1e-9);
  }
  // y up in the map is up (smaller row) in the image.
  EXPECT_LT(t.to_pixel(0.0, 1.0).y, t.to_pixel(0.0, 0.0).y);
  EXPECT_GT(t.to_pixel(1.0, 0.0).x, t.to_pixel(0.0, 0.0).x);
  EXPECT_THROW(ViewTransform(0.0, 0.0, 0.0), std::invalid_argument);
}

TEST(ViewTransform, FitCentresTheBoxWithTheMargin) {
  const cv::Rect2d area(0.0, 0.0, 800.0, 600.0);
  const ViewTransform t = ViewTransform::fit(box(0.0, 0.0, 4.0, 2.0), area, 50.0, 1.0);
  EXPECT_NEAR(t.pixels_per_metre(), std::min(700.0 / 4.0, 500.0 / 2.0), 1e-9);
  const cv::Point2d centre = t.to_pixel(2.0, 1.0);
  EXPECT_NEAR(centre.x, 400.0, 1e-9);
  EXPECT_NEAR(centre.y, 300.0, 1e-9);
  for (const cv::Point2d p : {t.to_pixel(0.0, 0.0), t.to_pixel(4.0, 2.0)}) {
    EXPECT_GE(p.x, 50.0 - 1e-9);
    EXPECT_LE(p.x, 750.0 + 1e-9);
    EXPECT_GE(p.y, 50.0 - 1e-9);
    EXPECT_LE(p.y, 550.0 + 1e-9);
  }
  // A thin box is widened to min_span about its centre; an empty one is centred on the origin.
  const ViewTransform thin = ViewTransform::fit(box(5.0, 5.0, 5.0, 5.0), area, 0.0, 2.0);
  EXPECT_NEAR(thin.pixels_per_metre(), 300.0, 1e-9);
  EXPECT_NEAR(thin.to_pixel(5.0, 5.0).x, 400.0, 1e-9);
  const ViewTransform empty = ViewTransform::fit(WorldBox{}, area, 0.0, 3.0);
  EXPECT_NEAR(empty.to_pixel(0.0, 0.0).x, 400.0, 1e-9);
  EXPECT_NEAR(empty.to_pixel(0.0, 0.0).y, 300.0, 1e-9);
  EXPECT_NEAR(empty.pixels_per_metre(), 200.0, 1e-9);
}

// A MapState with particles at +-1e308 (well-formed, hostile or broken) would
// make the box infinitely wide and the scale 0: such points are not a map.
TEST(ViewTransform, PointsFarBeyondAnyMapDoNotShrinkTheView) {
  WorldBox b = box(0.0, 0.0, 4.0, 2.0);
  b.extend(1e308, 0.0);
  b.extend(-1e308, -1e308);
  b.extend(2e6, 0.0);
  EXPECT_DOUBLE_EQ(b.width_m(), 4.0);
  EXPECT_DOUBLE_EQ(b.height_m(), 2.0);
  const ViewTransform t = ViewTransform::fit(b, cv::Rect2d(0.0, 0.0, 800.0, 600.0), 50.0, 1.0);
  EXPECT_NEAR(t.pixels_per_metre(), 175.0, 1e-9);
}

TEST(ViewTransform, ContentBoundsCoverEverythingDrawn) {
  MapViewState s;
  s.particles = {{-1.0, 0.0, 0.0}, {0.5, 3.0, 0.0}};
  s.landmarks = {landmark_with(4.0, 0.0, 0.1, 0.1, 0.0)};
  s.true_landmarks = {{1, -3.0, -4.0}};
  s.particles.push_back({std::nan(""), 1e9, 0.0});  // ignored
  const WorldBox with = content_bounds(s, 2.0, true);
  EXPECT_DOUBLE_EQ(with.min_x_m, -3.0);
  EXPECT_DOUBLE_EQ(with.min_y_m, -4.0);
  EXPECT_NEAR(with.max_x_m, 4.2, 1e-12);
  EXPECT_DOUBLE_EQ(with.max_y_m, 3.0);
  const WorldBox without = content_bounds(s, 2.0, false);
  EXPECT_DOUBLE_EQ(without.min_x_m, -1.0);
  EXPECT_NEAR(without.min_y_m, -0.2, 1e-12);
}

TEST(ViewTransform, NiceGridStep) {
  EXPECT_DOUBLE_EQ(nice_grid_step_m(100.0, 70.0), 1.0);
  EXPECT_DOUBLE_EQ(nice_grid_step_m(100.0, 30.0), 0.5);
  EXPECT_DOUBLE_EQ(nice_grid_step_m(100.0, 110.0), 2.0);
  EXPECT_NEAR(nice_grid_step_m(1000.0, 70.0), 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(nice_grid_step_m(7.0, 70.0), 10.0);
  EXPECT_DOUBLE_EQ(nice_grid_step_m(0.0, 70.0), 1.0);
}

// ---- rendering -----------------------------------------------------------

TEST(RenderMap, LandmarkDrawnAtItsPixelWithTwoSigmaEllipse) {
  // Given one landmark with sigma_x = 0.2 m, sigma_y = 0.1 m under a fixed view,
  MapViewState s;
  s.landmarks = {landmark_with(1.0, 1.0, 0.2, 0.1, 0.0)};
  const RenderOptions o = plain_options(box(-1.0, -1.0, 3.0, 3.0));
  // when rendered,
  const cv::Mat img = render_map(s, o);
  ASSERT_EQ(img.type(), CV_8UC3);
  ASSERT_EQ(img.cols, 400);
  ASSERT_EQ(img.rows, 400);
  const ViewTransform t = view_for(s, o);
  const cv::Point2d c = t.to_pixel(1.0, 1.0);
  const double ppm = t.pixels_per_metre();
  // then the landmark's own pixel has the landmark colour,
  EXPECT_TRUE(near_colour(img.at<cv::Vec3b>(static_cast<int>(std::lround(c.y)), static_cast<int>(std::lround(c.x))),
                          o.colours.landmark, 2));
  // and the ellipse reaches 2 sigma along x (0.4 m) and y (0.2 m), no further.
  const int row = static_cast<int>(std::lround(c.y));
  double extent_u = 0.0;
  for (int u = 0; u < img.cols; ++u) {
    if (landmark_like(img.at<cv::Vec3b>(row, u))) extent_u = std::max(extent_u, std::abs(u - c.x));
  }
  const int col = static_cast<int>(std::lround(c.x));
  double extent_v = 0.0;
  for (int v = 0; v < img.rows; ++v) {
    if (landmark_like(img.at<cv::Vec3b>(v, col))) extent_v = std::max(extent_v, std::abs(v - c.y));
  }
  EXPECT_NEAR(extent_u, 0.4 * ppm, 1.5);
  EXPECT_NEAR(extent_v, 0.2 * ppm, 1.5);
  // Nothing red far from the landmark.
  EXPECT_FALSE(any_near(img, t.to_pixel(2.5, 2.5), 10, landmark_like));
}

TEST(RenderMap, RotatedEllipseReachesItsMajorAxisTips) {
  const double angle = 0.6;
  MapViewState s;
  s.landmarks = {landmark_with(0.0, 0.0, 0.3, 0.05, angle)};
  const RenderOptions o = plain_options(box(-1.0, -1.0, 1.0, 1.0));
  const cv::Mat img = render_map(s, o);
  const ViewTransform t = view_for(s, o);
  const double r = 2.0 * 0.3;
  // On the major axis at +/- 2 sigma: red; 25 % beyond: white.
  EXPECT_TRUE(any_near(img, t.to_pixel(r * std::cos(angle), r * std::sin(angle)), 1, landmark_like));
  EXPECT_TRUE(any_near(img, t.to_pixel(-r * std::cos(angle), -r * std::sin(angle)), 1, landmark_like));
  EXPECT_FALSE(any_near(img, t.to_pixel(1.25 * r * std::cos(angle), 1.25 * r * std::sin(angle)), 2, landmark_like));
  // The mirrored direction (the wrong sign of the angle) is not where the ellipse is.
  EXPECT_FALSE(any_near(img, t.to_pixel(r * std::cos(-angle), r * std::sin(-angle)), 2, landmark_like));
}

MapViewState full_state() {
  MapViewState s;
  for (int i = 0; i < 50; ++i) {
    const double a = 2.0 * kPi * i / 50.0;
    s.mean_trajectory.push_back({2.0 * std::cos(a), 1.5 * std::sin(a)});
    s.true_trajectory.push_back({2.05 * std::cos(a), 1.45 * std::sin(a)});
    s.particles.push_back({2.0 + 0.02 * std::cos(7.0 * i), 0.02 * std::sin(5.0 * i), kPi / 2});
  }
  s.current_pose = Pose2{2.0, 0.0, kPi / 2};
  s.true_pose = Pose2{2.05, 0.0, kPi / 2};
  for (int k = 0; k < 6; ++k) {
    const double a = 2.0 * kPi * k / 6.0;
    LandmarkView l = landmark_with(3.0 * std::cos(a), 2.5 * std::sin(a), 0.05 + 0.01 * k, 0.03, a);
    l.id = 10 + k;
    s.landmarks.push_back(l);
    s.true_landmarks.push_back({10 + k, 3.0 * std::cos(a) + 0.03, 2.5 * std::sin(a)});
  }
  s.caption = format_caption({12.34, 100, 87.5, 6, "robot1"});
  return s;
}

TEST(RenderMap, SameInputSamePixels) {
  const MapViewState s = full_state();
  const RenderOptions o;
  const cv::Mat a = render_map(s, o);
  const cv::Mat b = render_map(s, o);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  MapViewState moved = s;
  moved.landmarks[0].x_m += 0.05;
  EXPECT_GT(cv::norm(a, render_map(moved, o), cv::NORM_INF), 0.0);
}

TEST(RenderMap, DrawsParticlesTrajectoryPoseAndTruth) {
  const MapViewState s = full_state();
  RenderOptions o;
  const cv::Mat img = render_map(s, o);
  EXPECT_EQ(img.cols, 800);
  EXPECT_EQ(img.rows, 800);
  const ViewTransform t = view_for(s, o);
  auto colour = [&](const cv::Scalar& c) {
    return [c](const cv::Mat& m, cv::Point2d at, int radius) {
      for (int dv = -radius; dv <= radius; ++dv)
        for (int du = -radius; du <= radius; ++du) {
          const int u = static_cast<int>(std::lround(at.x)) + du, v = static_cast<int>(std::lround(at.y)) + dv;
          if (near_colour(m.at<cv::Vec3b>(v, u), c, 30)) return true;
        }
      return false;
    };
  };
  // The mean trajectory (blue) on its path, away from the pose arrow.
  EXPECT_TRUE(colour(o.colours.trajectory)(img, t.to_pixel(s.mean_trajectory[12]), 1));
  // The current pose arrow.
  EXPECT_TRUE(colour(o.colours.pose)(img, t.to_pixel(2.0, 0.0), 1));
  // A true landmark cross (green).
  EXPECT_TRUE(colour(o.colours.truth)(img, t.to_pixel(s.true_landmarks[3].x_m, s.true_landmarks[3].y_m), 2));
  // Without ground truth: no green anywhere in the map area.
  o.ground_truth = false;
  const cv::Mat no_truth = render_map(s, o);
  cv::Mat green;
  cv::inRange(no_truth, cv::Scalar(20, 130, 20), cv::Scalar(60, 170, 60), green);
  EXPECT_EQ(cv::countNonZero(green), 0);
  cv::inRange(img, cv::Scalar(20, 130, 20), cv::Scalar(60, 170, 60), green);
  EXPECT_GT(cv::countNonZero(green), 50);
}

TEST(RenderMap, ParticlesAreDrawnWhereTheyAre) {
  MapViewState s;
  s.particles = {{0.5, 0.5, 0.0}};
  const RenderOptions o = plain_options(box(0.0, 0.0, 1.0, 1.0));
  const cv::Mat img = render_map(s, o);
  const cv::Point2d p = view_for(s, o).to_pixel(0.5, 0.5);
  EXPECT_TRUE(near_colour(img.at<cv::Vec3b>(static_cast<int>(std::lround(p.y)), static_cast<int>(std::lround(p.x))),
                          o.colours.particle, 40));
}

TEST(RenderMap, RejectsBadSizesAndSurvivesOddInput) {
  RenderOptions o;
  o.width_px = 10;
  EXPECT_THROW(render_map(MapViewState{}, o), std::invalid_argument);
  o = RenderOptions{};
  o.footer_px = 760;
  EXPECT_THROW(render_map(MapViewState{}, o), std::invalid_argument);
  o = RenderOptions{};
  o.width_px = 640;
  o.height_px = 480;
  // Empty state, NaNs, a huge covariance and a far-off particle: an image, no crash.
  EXPECT_EQ(render_map(MapViewState{}, o).size(), cv::Size(640, 480));
  MapViewState odd;
  odd.particles = {{std::nan(""), 0.0, 0.0}, {1e12, -1e12, 0.0}};
  odd.landmarks = {landmark_with(0.0, 0.0, 1e4, 1e-9, 0.3)};
  odd.landmarks.push_back(landmark_with(std::nan(""), 1.0, 0.1, 0.1, 0.0));
  odd.current_pose = Pose2{0.0, 0.0, std::nan("")};
  odd.caption = std::string(400, 'x');
  EXPECT_EQ(render_map(odd, o).size(), cv::Size(640, 480));
}

// Pixels within `tol` of colour `c` in `img` (whole image, footer included).
int count_colour(const cv::Mat& img, const cv::Scalar& c, int tol) {
  cv::Mat mask;
  cv::inRange(img, c - cv::Scalar::all(tol), c + cv::Scalar::all(tol), mask);
  return cv::countNonZero(mask);
}

TEST(RenderMap, OptimisedSolutionDrawnInItsOwnColourBesideTheFiltersMap) {
  // Given the filter's map and trajectory, and the optimiser's keyframes along
  // y = -1 and one landmark with sigma_x = 0.2 m, sigma_y = 0.1 m at (1, 1),
  MapViewState s;
  s.landmarks = {landmark_with(-1.0, 1.0, 0.1, 0.1, 0.0)};
  s.mean_trajectory = {{-1.5, -1.5}, {1.5, -1.5}};
  s.optimised_trajectory = {{-1.5, -1.0}, {0.0, -1.0}, {1.5, -1.0}};
  s.optimised_landmarks = {landmark_with(1.0, 1.0, 0.2, 0.1, 0.0)};
  RenderOptions o = plain_options(box(-2.0, -2.0, 2.0, 2.0));
  const cv::Mat img = render_map(s, o);
  const ViewTransform t = view_for(s, o);
  const double ppm = t.pixels_per_metre();
  auto optimised_near = [&](cv::Point2d at, int radius) { return any_near(img, at, radius, optimised_like); };
  // then the optimised colour is on the keyframe line and on the diamond around its landmark,
  EXPECT_TRUE(optimised_near(t.to_pixel(0.75, -1.0), 1));
  EXPECT_TRUE(optimised_near(t.to_pixel(1.0, 1.0), 7));
  EXPECT_FALSE(optimised_near(t.to_pixel(1.0, 1.0), 1));  // outlined: the centre stays free
  // its ellipse reaches 2 sigma (0.4 m along x, 0.2 m along y), not 25 % further,
  EXPECT_TRUE(optimised_near(t.to_pixel(1.4, 1.0), 1));
  EXPECT_TRUE(optimised_near(t.to_pixel(1.0, 1.2), 1));
  EXPECT_FALSE(optimised_near(t.to_pixel(1.5, 1.0), 2));
  EXPECT_FALSE(optimised_near(t.to_pixel(1.0, 1.25), 2));
  // and not on the filter's landmark, trajectory or empty space.
  EXPECT_FALSE(optimised_near(t.to_pixel(-1.0, 1.0), 8));
  EXPECT_FALSE(optimised_near(t.to_pixel(0.0, -1.5), 3));
  EXPECT_FALSE(optimised_near(t.to_pixel(0.0, 0.5), 10));
  EXPECT_TRUE(any_near(img, t.to_pixel(-1.0, 1.0), 1, landmark_like));  // the filter's map is still drawn
  EXPECT_GT(0.4 * ppm, 20.0);  // the ellipse is well outside the diamond

  // Without the optimised solution: not one pixel of its colour, and the same
  // image as a state that never had one.
  MapViewState without = s;
  without.optimised_trajectory.clear();
  without.optimised_landmarks.clear();
  const cv::Mat plain = render_map(without, o);
  EXPECT_EQ(count_like(plain, optimised_like), 0);
  EXPECT_GT(count_colour(img, o.colours.optimised, 40), 50);
  MapViewState never;
  never.landmarks = s.landmarks;
  never.mean_trajectory = s.mean_trajectory;
  EXPECT_EQ(cv::norm(plain, render_map(never, o), cv::NORM_INF), 0.0);
}

TEST(RenderMap, OptimisedLandmarkWithoutCovarianceHasNoEllipse) {
  MapViewState s;
  LandmarkView l = landmark_with(0.0, 0.0, 0.3, 0.3, 0.0);
  s.optimised_landmarks = {l};
  RenderOptions o = plain_options(box(-1.0, -1.0, 1.0, 1.0));
  const ViewTransform t = view_for(s, o);
  const auto orange_at = [&](const cv::Mat& img, cv::Point2d at) { return any_near(img, at, 2, optimised_like); };
  // A finite covariance: the 2-sigma circle (0.6 m) is drawn.
  EXPECT_TRUE(orange_at(render_map(s, o), t.to_pixel(0.6, 0.0)));
  // NaN (before the first whole-problem solve): only the marker.
  s.optimised_landmarks[0].cov_xx_m2 = std::nan("");
  s.optimised_landmarks[0].cov_xy_m2 = std::nan("");
  s.optimised_landmarks[0].cov_yy_m2 = std::nan("");
  const cv::Mat img = render_map(s, o);
  EXPECT_FALSE(orange_at(img, t.to_pixel(0.6, 0.0)));
  EXPECT_FALSE(orange_at(img, t.to_pixel(0.0, -0.6)));
  EXPECT_TRUE(orange_at(img, t.to_pixel(0.0, 0.0) + cv::Point2d(6.0, 0.0)));
}

TEST(RenderMap, LegendNamesTheOptimisedSolutionOnlyWhenPresent) {
  MapViewState s = full_state();
  const RenderOptions o;  // footer with the legend
  const cv::Rect footer(0, o.height_px - o.footer_px, o.width_px, o.footer_px);
  const cv::Mat without = render_map(s, o);
  EXPECT_EQ(count_like(without, optimised_like), 0);
  s.optimised_trajectory = s.mean_trajectory;
  s.optimised_landmarks = s.landmarks;
  const cv::Mat with = render_map(s, o);
  EXPECT_GT(count_colour(with(footer), o.colours.optimised, 40), 10);
  // The view fits the optimised solution too: a landmark far out moves the view.
  MapViewState far = s;
  far.optimised_landmarks.push_back(landmark_with(30.0, 0.0, 0.1, 0.1, 0.0));
  EXPECT_NEAR(content_bounds(far, 2.0, true).max_x_m, 30.2, 1e-9);
}

// ---- conversion ----------------------------------------------------------

msg::MapState map_state(std::uint64_t stamp_ns, double x, int landmarks) {
  msg::MapState m;
  m.header().stamp_ns(stamp_ns);
  m.header().robot_id("robot1");
  m.header().frame_id("map");
  m.mean_pose().x_m(x);
  m.mean_pose().y_m(0.5 * x);
  m.mean_pose().theta_rad(0.25);
  m.particle_count(100);
  m.effective_sample_size(87.5);
  for (int i = 0; i < 5; ++i) {
    msg::Pose2D p;
    p.x_m(x + 0.01 * i);
    p.y_m(0.5 * x);
    m.particle_poses().push_back(p);
  }
  for (int i = 0; i < landmarks; ++i) {
    msg::LandmarkEstimate l;
    l.landmark_id(20 + i);
    l.x_m(1.0 + i);
    l.y_m(2.0);
    l.cov_xx_m2(0.01);
    l.cov_xy_m2(0.002);
    l.cov_yy_m2(0.02);
    l.times_observed(3 + i);
    m.landmarks().push_back(l);
  }
  return m;
}

msg::GroundTruth ground_truth(std::uint64_t stamp_ns, double x) {
  msg::GroundTruth g;
  g.header().stamp_ns(stamp_ns);
  g.header().robot_id("robot1");
  g.pose().x_m(x);
  g.pose().y_m(0.5 * x + 0.01);
  g.pose().theta_rad(0.2);
  for (int i = 0; i < 3; ++i) {
    msg::TrueLandmark l;
    l.landmark_id(20 + i);
    l.x_m(1.0 + i);
    l.y_m(2.05);
    g.landmarks().push_back(l);
  }
  return g;
}

TEST(MsgConversion, MapStateBecomesTheViewState) {
  MapViewBuilder builder(0.0);
  const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
  builder.add(ground_truth(t0, 0.0));
  ASSERT_TRUE(builder.add(map_state(t0 + 500'000'000ULL, 0.1, 2)));
  ASSERT_TRUE(builder.add(map_state(t0 + 1'500'000'000ULL, 0.3, 3)));
  const MapViewState& s = builder.state();
  ASSERT_EQ(s.particles.size(), 5u);
  EXPECT_DOUBLE_EQ(s.particles[2].x_m, 0.32);
  ASSERT_TRUE(s.current_pose.has_value());
  EXPECT_DOUBLE_EQ(s.current_pose->x_m, 0.3);
  EXPECT_DOUBLE_EQ(s.current_pose->theta_rad, 0.25);
  ASSERT_EQ(s.mean_trajectory.size(), 2u);
  EXPECT_DOUBLE_EQ(s.mean_trajectory[0].x_m, 0.1);
  ASSERT_EQ(s.landmarks.size(), 3u);
  EXPECT_EQ(s.landmarks[1].id, 21);
  EXPECT_DOUBLE_EQ(s.landmarks[1].x_m, 2.0);
  EXPECT_DOUBLE_EQ(s.landmarks[1].cov_xy_m2, 0.002);
  EXPECT_DOUBLE_EQ(s.landmarks[1].cov_yy_m2, 0.02);
  EXPECT_EQ(s.landmarks[1].times_observed, 4u);
  EXPECT_EQ(s.caption, "t = 1.5 s   100 particles   ESS 87.5   3 landmarks   robot1");
  ASSERT_EQ(s.true_landmarks.size(), 3u);
  ASSERT_TRUE(s.true_pose.has_value());
  EXPECT_DOUBLE_EQ(s.true_pose->y_m, 0.01);
  // A stale state (a late joiner's history) is ignored.
  EXPECT_FALSE(builder.add(map_state(t0 + 1'000'000'000ULL, 9.0, 1)));
  EXPECT_EQ(builder.state().landmarks.size(), 3u);
  EXPECT_EQ(builder.state().mean_trajectory.size(), 2u);
}

msg::OptimisedMap optimised_map(std::uint64_t stamp_ns, int keyframes, double shift) {
  msg::OptimisedMap m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("map");
  m.keyframe_count(static_cast<std::uint32_t>(keyframes));
  for (int i = 0; i < keyframes; ++i) {
    msg::OptimisedKeyframe k;
    k.stamp_ns(stamp_ns - static_cast<std::uint64_t>(keyframes - i) * 1000u);
    k.pose().x_m(0.1 * i + shift);
    k.pose().y_m(-0.2 * i);
    m.keyframes().push_back(k);
  }
  msg::OptimisedLandmark l;
  l.landmark_id(20);
  l.x_m(1.0 + shift);
  l.y_m(2.0);
  l.cov_xx_m2(0.004);
  l.cov_xy_m2(0.001);
  l.cov_yy_m2(0.009);
  l.observations(11);
  m.landmarks().push_back(l);
  return m;
}

TEST(MsgConversion, OptimisedMapReplacesTheOptimisedSolution) {
  MapViewBuilder builder(0.0);
  const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
  ASSERT_TRUE(builder.add(map_state(t0 + 100'000'000ULL, 0.1, 2)));
  const MapViewState before = builder.state();
  // The first solution: its keyframes and landmarks, the filter's state untouched.
  ASSERT_TRUE(builder.add(optimised_map(t0 + 200'000'000ULL, 4, 0.0)));
  const MapViewState& s = builder.state();
  ASSERT_EQ(s.optimised_trajectory.size(), 4u);
  EXPECT_DOUBLE_EQ(s.optimised_trajectory[3].x_m, 0.3);
  EXPECT_DOUBLE_EQ(s.optimised_trajectory[3].y_m, -0.6);
  ASSERT_EQ(s.optimised_landmarks.size(), 1u);
  EXPECT_EQ(s.optimised_landmarks[0].id, 20);
  EXPECT_DOUBLE_EQ(s.optimised_landmarks[0].cov_xy_m2, 0.001);
  EXPECT_DOUBLE_EQ(s.optimised_landmarks[0].cov_yy_m2, 0.009);
  EXPECT_EQ(s.optimised_landmarks[0].times_observed, 11u);
  EXPECT_EQ(s.landmarks.size(), before.landmarks.size());
  EXPECT_EQ(s.mean_trajectory.size(), before.mean_trajectory.size());
  EXPECT_EQ(s.caption, before.caption);
  EXPECT_EQ(builder.optimised_maps(), 1u);
  // A later solution replaces it (not appended: each holds the whole trajectory).
  ASSERT_TRUE(builder.add(optimised_map(t0 + 300'000'000ULL, 6, 5.0)));
  ASSERT_EQ(builder.state().optimised_trajectory.size(), 6u);
  EXPECT_DOUBLE_EQ(builder.state().optimised_trajectory[0].x_m, 5.0);
  EXPECT_DOUBLE_EQ(builder.state().optimised_landmarks[0].x_m, 6.0);
  // A stale one is ignored.
  EXPECT_FALSE(builder.add(optimised_map(t0 + 250'000'000ULL, 2, 9.0)));
  EXPECT_EQ(builder.state().optimised_trajectory.size(), 6u);
  EXPECT_EQ(builder.optimised_maps(), 2u);
}

// Any participant can stamp a sample 2^64 - 1 ns: after it, the robot's own
// states (far behind it) are drawn again instead of being ignored as stale for
// ever; a state a little older than the newest is still stale.
TEST(MsgConversion, OneStampFarAheadDoesNotFreezeTheView) {
  MapViewBuilder builder(0.0);
  const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
  ASSERT_TRUE(builder.add(map_state(t0, 0.1, 2)));
  ASSERT_TRUE(builder.add(map_state(~std::uint64_t{0}, 5.0, 1)));
  ASSERT_TRUE(builder.add(map_state(t0 + 100'000'000ULL, 0.2, 2)));
  ASSERT_TRUE(builder.add(map_state(t0 + 200'000'000ULL, 0.3, 3)));
  EXPECT_DOUBLE_EQ(builder.state().current_pose->x_m, 0.3);
  EXPECT_EQ(builder.state().landmarks.size(), 3u);
  EXPECT_FALSE(builder.add(map_state(t0 + 150'000'000ULL, 9.0, 1)));
  EXPECT_EQ(builder.map_states(), 4u);
  ASSERT_TRUE(builder.add(optimised_map(~std::uint64_t{0}, 2, 9.0)));
  ASSERT_TRUE(builder.add(optimised_map(t0 + 300'000'000ULL, 3, 0.0)));
  EXPECT_EQ(builder.state().optimised_trajectory.size(), 3u);
}

// Any participant can invent robot ids: past kMaxRobots a new id takes the
// place of the robot heard from least recently (counted), so a robot that keeps
// sending is still drawn after a flood of ids sent once, and ids sent once
// cannot keep a later robot out.
TEST(FleetView, InventedRobotsPastTheLimitTakeTheLeastRecentlyHeardPlaces) {
  FleetViewBuilder fleet;
  const auto from = [](const std::string& id, std::uint64_t stamp) {
    msg::MapState m = map_state(stamp, 0.0, 1);
    m.header().robot_id(id);
    return m;
  };
  ASSERT_TRUE(fleet.add(from("real", 1000)));
  const std::size_t extra = 10;
  for (std::size_t r = 0; r < FleetViewBuilder::kMaxRobots + extra; ++r) {
    EXPECT_TRUE(fleet.add(from("ghost" + std::to_string(r), 1000))) << r;
    if (r % 8 == 0) {
      EXPECT_TRUE(fleet.add(from("real", 2000 + r)));  // it keeps sending
    }
  }
  EXPECT_EQ(fleet.robots(), FleetViewBuilder::kMaxRobots);
  EXPECT_EQ(fleet.robots_evicted(), extra + 1);
  EXPECT_EQ(fleet.map_states(), 11u + 63u);  // "real"'s 11, one of each of the 63 ghosts kept
  const MapViewState state = fleet.state();
  bool real_drawn = state.robot_id == "real";
  for (const MapViewState& other : state.other_robots) real_drawn = real_drawn || other.robot_id == "real";
  EXPECT_TRUE(real_drawn);
  EXPECT_TRUE(fleet.add(from("late", 5000)));  // a robot that comes after the flood is drawn
  EXPECT_EQ(fleet.robots(), FleetViewBuilder::kMaxRobots);
}

TEST(FleetView, EveryRobotIsDrawnInOnePictureInItsOwnColour) {
  // Given two robots' states and ground truth on one domain,
  FleetViewBuilder fleet;
  for (int i = 0; i < 10; ++i) {
    msg::MapState a = map_state(1000 + 100000000ULL * i, 0.1 * i, 2);
    msg::MapState b = map_state(1000 + 100000000ULL * i, -0.1 * i, 3);
    b.header().robot_id("robot2");
    msg::GroundTruth tb = ground_truth(1000 + 100000000ULL * i, -0.1 * i);
    tb.header().robot_id("robot2");
    EXPECT_TRUE(fleet.add(b));
    EXPECT_TRUE(fleet.add(a));
    fleet.add(tb);
  }
  // then the view is robot1's with robot2 beside it, each with its own path,
  EXPECT_EQ(fleet.robots(), 2u);
  EXPECT_EQ(fleet.map_states(), 20u);
  EXPECT_EQ(fleet.ground_truths(), 10u);
  const MapViewState s = fleet.state();
  EXPECT_EQ(s.robot_id, "robot1");
  EXPECT_EQ(s.mean_trajectory.size(), 10u);
  EXPECT_EQ(s.landmarks.size(), 2u);
  EXPECT_TRUE(s.true_trajectory.empty());
  ASSERT_EQ(s.other_robots.size(), 1u);
  const MapViewState& b = s.other_robots[0];
  EXPECT_EQ(b.robot_id, "robot2");
  EXPECT_EQ(b.landmarks.size(), 3u);
  EXPECT_EQ(b.true_trajectory.size(), 10u);
  EXPECT_NEAR(b.current_pose->x_m, -0.9, 1e-12);
  // the view holds both,
  const WorldBox box = content_bounds(s, 2.0, true);
  EXPECT_LE(box.min_x_m, -0.9);
  EXPECT_GE(box.max_x_m, 0.9);
  // and robot2 is drawn (and named in the legend) in robot_colour(0), robot1 in the usual colours.
  RenderOptions o;
  const cv::Mat both = render_map(s, o);
  MapViewState alone = s;
  alone.other_robots.clear();
  const cv::Mat one = render_map(alone, o);
  EXPECT_GT(count_colour(both, robot_colour(0), 10), 100);
  EXPECT_EQ(count_colour(one, robot_colour(0), 10), 0);
  EXPECT_GT(count_colour(both, o.colours.trajectory, 10), 50);
  EXPECT_NE(robot_colour(0), robot_colour(1));

  // A fleet map goes on top, in its own colour, and only its newest counts.
  msg::FleetMap fleet_map;
  fleet_map.header().stamp_ns(5000);
  msg::FleetLandmark l;
  l.landmark_id(20);
  l.x_m(0.3);
  l.y_m(1.0);
  l.cov_xx_m2(0.01);
  l.cov_yy_m2(0.01);
  l.robots(2);
  fleet_map.landmarks().push_back(l);
  EXPECT_TRUE(fleet.add(fleet_map));
  fleet_map.header().stamp_ns(4000);
  EXPECT_FALSE(fleet.add(fleet_map));
  EXPECT_EQ(fleet.fleet_maps(), 1u);
  const MapViewState with_fleet = fleet.state();
  ASSERT_EQ(with_fleet.fleet_landmarks.size(), 1u);
  EXPECT_EQ(with_fleet.fleet_landmarks[0].times_observed, 2u);
  EXPECT_GT(count_colour(render_map(with_fleet, o), o.colours.fleet, 10), count_colour(both, o.colours.fleet, 10) + 20);
}

TEST(MsgConversion, TrajectoryDecimation) {
  std::vector<Point2> path;
  append_point(path, {0.0, 0.0}, 0.1);
  append_point(path, {0.05, 0.0}, 0.1);
  append_point(path, {0.11, 0.0}, 0.1);
  append_point(path, {std::nan(""), 0.0}, 0.0);
  ASSERT_EQ(path.size(), 2u);
  EXPECT_DOUBLE_EQ(path[1].x_m, 0.11);
}

// A live view that runs for days: the path never holds more than its limit,
// keeps its start and its newest point, and old and new parts are thinned
// alike (appending halves the whole run, not again and again its old part).
TEST(MsgConversion, AThinnedPathKeepsItsLimitItsEndsAndAnEvenDensity) {
  std::vector<Point2> path;
  PathThinning thinning(0.0, 100);
  for (int i = 0; i < 100000; ++i) {
    thinning.append(path, {0.01 * i, 0.0});
    ASSERT_LE(path.size(), 101u) << i;  // the limit, and the newest point standing in
  }
  EXPECT_GE(path.size(), 50u);
  EXPECT_DOUBLE_EQ(path.front().x_m, 0.0);
  EXPECT_DOUBLE_EQ(path.back().x_m, 999.99);
  double min_gap = 1e9, max_gap = 0.0;
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {  // the last gap ends at the newest point
    const double gap = path[i].x_m - path[i - 1].x_m;
    min_gap = std::min(min_gap, gap);
    max_gap = std::max(max_gap, gap);
  }
  EXPECT_GT(min_gap, 0.0);
  EXPECT_LE(max_gap, 2.0 * min_gap + 1e-9) << "gaps from " << min_gap << " to " << max_gap;
}

// ---- MCAP logs -----------------------------------------------------------

// Writes a log like the logger's: map_state and ground_truth channels (CDR,
// omgidl schemas), interleaved by time; with `optimised_every` > 0 an
// optimised_map channel too, one solution every that many steps.
void write_log(const std::string& path, int steps, bool with_map_channel, int optimised_every = 0) {
  mcap::McapWriter writer(path, {});
  std::uint16_t optimised_channel = 0;
  if (optimised_every > 0) {
    const std::uint16_t schema =
        writer.add_schema("pixyslam::msg::OptimisedMap", "omgidl", msg::idl_text("optimised_map"));
    optimised_channel = writer.add_channel("pixyslam/optimised_map", "cdr", schema);
  }
  std::uint16_t map_channel = 0;
  if (with_map_channel) {
    const std::uint16_t schema = writer.add_schema("pixyslam::msg::MapState", "omgidl", msg::idl_text("map_state"));
    map_channel = writer.add_channel("pixyslam/map_state", "cdr", schema);
  }
  const std::uint16_t truth_schema =
      writer.add_schema("pixyslam::msg::GroundTruth", "omgidl", msg::idl_text("ground_truth"));
  const std::uint16_t truth_channel = writer.add_channel("pixyslam/ground_truth", "cdr", truth_schema);
  const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
  for (int i = 0; i < steps; ++i) {
    const std::uint64_t t = t0 + static_cast<std::uint64_t>(i) * 100'000'000ULL;
    const double x = 0.05 * i;
    writer.write_message(truth_channel, static_cast<std::uint32_t>(i + 1), t, t,
                         dds::to_cdr(ground_truth(t, x)));
    if (with_map_channel) {
      writer.write_message(map_channel, static_cast<std::uint32_t>(i + 1), t + 1000, t + 1000,
                           dds::to_cdr(map_state(t, x, 1 + i / 10)));
    }
    if (optimised_every > 0 && (i + 1) % optimised_every == 0) {
      writer.write_message(optimised_channel, static_cast<std::uint32_t>((i + 1) / optimised_every), t + 2000,
                           t + 2000, dds::to_cdr(optimised_map(t, i + 1, 0.01 * i)));
    }
  }
  writer.close();
}

TEST(MapViewLog, RendersLogWrittenWithMcapWriter) {
  // PIXYSLAM_MAP_VIEW_FIXTURE_DIR (set by ctest): also leave the logs there for the CLI test.
  const char* fixture = std::getenv("PIXYSLAM_MAP_VIEW_FIXTURE_DIR");
  const test::TempDir temp("pixyslam_test_map_view");
  const fs::path dir = fixture != nullptr ? fs::path(fixture) : fs::path(temp.path());
  fs::create_directories(dir);
  const std::string log_path = (dir / "with_map.mcap").string();
  write_log(log_path, 40, true);
  write_log((dir / "no_map.mcap").string(), 5, false);

  const MapLog log = MapLog::read(log_path);
  EXPECT_EQ(log.map_states().size(), 40u);
  EXPECT_EQ(log.ground_truths().size(), 40u);
  EXPECT_EQ(log.undecodable(), 0u);
  EXPECT_TRUE(log.recovery_note().empty());
  EXPECT_EQ(log.end_ns() - log.start_ns(), 39u * 100'000'000ULL + 1000u);

  const MapViewState final = final_state(log, 0.0);
  EXPECT_EQ(final.mean_trajectory.size(), 40u);
  EXPECT_EQ(final.true_trajectory.size(), 40u);
  EXPECT_EQ(final.landmarks.size(), 4u);
  EXPECT_NEAR(final.current_pose->x_m, 0.05 * 39, 1e-12);

  // Halfway through, the player has exactly the first half.
  LogPlayer player(log, 0.0);
  player.advance_to(log.start_ns() + 19u * 100'000'000ULL + 1000u);
  EXPECT_EQ(player.state().mean_trajectory.size(), 20u);

  const WorldBox bounds = run_bounds(log, 2.0, true);
  const WorldBox final_bounds = content_bounds(final, 2.0, true);
  EXPECT_LE(bounds.min_x_m, final_bounds.min_x_m + 1e-12);
  EXPECT_GE(bounds.max_x_m, final_bounds.max_x_m - 1e-12);

  RenderOptions o;
  o.width_px = 640;
  o.height_px = 480;
  const std::string png = (dir / "final.png").string();
  write_png(png, render_map(final, o));
  const cv::Mat back = cv::imread(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(back.cols, 640);
  EXPECT_EQ(back.rows, 480);
  EXPECT_EQ(cv::norm(back, render_map(final, o), cv::NORM_INF), 0.0);
}

TEST(MapViewLog, ReplaysTheOptimisedMapsOfALog) {
  const test::TempDir temp("pixyslam_test_map_view");
  const fs::path dir = temp.path();
  const std::string path = (dir / "optimised.mcap").string();
  write_log(path, 40, true, 10);
  const MapLog log = MapLog::read(path);
  EXPECT_EQ(log.map_states().size(), 40u);
  ASSERT_EQ(log.optimised_maps().size(), 4u);
  EXPECT_EQ(log.undecodable(), 0u);

  // Halfway: the second solution (20 keyframes); at the end the fourth (40).
  LogPlayer player(log, 0.0);
  player.advance_to(log.start_ns() + 19u * 100'000'000ULL + 2000u);
  EXPECT_EQ(player.state().optimised_trajectory.size(), 20u);
  EXPECT_EQ(player.builder().optimised_maps(), 2u);
  const MapViewState final = final_state(log, 0.0);
  ASSERT_EQ(final.optimised_trajectory.size(), 40u);
  EXPECT_NEAR(final.optimised_trajectory.back().x_m, 0.1 * 39 + 0.01 * 39, 1e-12);
  ASSERT_EQ(final.optimised_landmarks.size(), 1u);
  EXPECT_NEAR(final.optimised_landmarks[0].x_m, 1.0 + 0.01 * 39, 1e-12);
  // The video's fixed view covers every solution (the keyframes reach y = -7.8).
  EXPECT_LE(run_bounds(log, 2.0, false).min_y_m, -0.2 * 39 + 1e-9);

  // Drawn in the optimised colour; the same log without the channel is not.
  RenderOptions o;
  cv::Mat mask;
  cv::inRange(render_map(final, o), o.colours.optimised - cv::Scalar::all(40),
              o.colours.optimised + cv::Scalar::all(40), mask);
  EXPECT_GT(cv::countNonZero(mask), 100);
  const std::string plain_path = (dir / "plain.mcap").string();
  write_log(plain_path, 40, true);
  const MapLog plain = MapLog::read(plain_path);
  EXPECT_TRUE(plain.optimised_maps().empty());
  cv::inRange(render_map(final_state(plain, 0.0), o), o.colours.optimised - cv::Scalar::all(40),
              o.colours.optimised + cv::Scalar::all(40), mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
  EXPECT_EQ(count_like(render_map(final_state(plain, 0.0), o), optimised_like), 0);
}

TEST(MapViewLog, BadLogsAreLogErrorsNamingTheFile) {
  const test::TempDir temp("pixyslam_test_map_view");
  const fs::path dir = temp.path();
  const std::string missing = (dir / "missing.mcap").string();
  try {
    MapLog::read(missing);
    FAIL() << "no exception";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string text = (dir / "text.mcap").string();
  std::ofstream(text) << "not an mcap file at all\n";
  EXPECT_THROW(MapLog::read(text), LogError);

  const std::string no_map = (dir / "no_map.mcap").string();
  write_log(no_map, 3, false);
  try {
    MapLog::read(no_map);
    FAIL() << "no exception";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("pixyslam/map_state"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(no_map), std::string::npos) << e.what();
  }

  // A map_state channel whose payloads are not MapState.
  const std::string garbage = (dir / "garbage.mcap").string();
  {
    mcap::McapWriter writer(garbage, {});
    const std::uint16_t channel = writer.add_channel("pixyslam/map_state", "cdr", 0);
    const std::vector<std::uint8_t> junk = {0x00, 0x01, 0x00, 0x00, 0xff, 0xff, 0xff, 0x7f};
    writer.write_message(channel, 1, 1, 1, junk);
    writer.close();
  }
  try {
    MapLog::read(garbage);
    FAIL() << "no exception";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("decodes"), std::string::npos) << e.what();
  }
}

TEST(MapViewLog, FrameTimes) {
  const std::vector<std::uint64_t> t = frame_times(0, 10'000'000'000ULL, 10.0, 2.0);
  ASSERT_EQ(t.size(), 51u);
  EXPECT_EQ(t[1], 200'000'000ULL);
  EXPECT_EQ(t.back(), 10'000'000'000ULL);
  EXPECT_EQ(frame_times(5, 5, 10.0, 1.0).size(), 1u);
  EXPECT_THROW(frame_times(0, 1, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(frame_times(0, 1, 10.0, -1.0), std::invalid_argument);
}

TEST(FrameSink, WritesPngSequenceAndMjpgVideo) {
  const test::TempDir temp("pixyslam_test_map_view");
  const fs::path dir = temp.path();
  const cv::Size size(160, 120);
  cv::Mat frame(size, CV_8UC3, cv::Scalar(255, 255, 255));
  {
    FrameSink folder((dir / "frames").string(), 10.0, size);
    EXPECT_FALSE(folder.is_video());
    for (int i = 0; i < 3; ++i) folder.write(frame);
  }
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_00000.png"));
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_00002.png"));
  EXPECT_FALSE(fs::exists(dir / "frames" / "frame_00003.png"));
  const std::string avi = (dir / "video.AVI").string();
  {
    FrameSink video(avi, 10.0, size);
    EXPECT_TRUE(video.is_video());
    for (int i = 0; i < 4; ++i) video.write(frame);
    video.close();
  }
  ASSERT_TRUE(fs::exists(avi));
  cv::VideoCapture capture(avi);
  ASSERT_TRUE(capture.isOpened());
  int frames = 0;
  cv::Mat got;
  while (capture.read(got)) {
    EXPECT_EQ(got.size(), size);
    ++frames;
  }
  EXPECT_EQ(frames, 4);
  EXPECT_THROW(FrameSink("/proc/no_such_dir/x.avi", 10.0, size), InputError);
}

// ---- options -------------------------------------------------------------

TEST(MapViewOptions, ReadsValidatesAndRejectsUnknownKeys) {
  config::YamlReader ok = config::YamlReader::from_string(
      "map_view:\n  width_px: 640\n  height_px: 500\n  sigma_scale: 3\n  ground_truth: false\n"
      "  snapshot_period_s: 0.5\ndds:\n  domain_id: 7\n  profiles_file: dds/profiles.xml\n",
      "test.yaml");
  const MapViewOptions o = read_map_view_options(ok, "/cfg", "/default.xml");
  EXPECT_EQ(o.render.width_px, 640);
  EXPECT_EQ(o.render.height_px, 500);
  EXPECT_DOUBLE_EQ(o.render.sigma_scale, 3.0);
  EXPECT_FALSE(o.render.ground_truth);
  EXPECT_DOUBLE_EQ(o.snapshot_period_s, 0.5);
  EXPECT_EQ(o.dds.domain_id, 7);
  EXPECT_EQ(o.dds.profiles_file, "/cfg/dds/profiles.xml");

  config::YamlReader empty = config::YamlReader::from_string("{}", "empty.yaml");
  EXPECT_EQ(read_map_view_options(empty, "/cfg", "/default.xml").dds.profiles_file, "/default.xml");

  auto error_of = [](const std::string& text) {
    config::YamlReader r = config::YamlReader::from_string(text, "bad.yaml");
    try {
      read_map_view_options(r, ".", "");
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("map_view:\n  widht_px: 640\n").find("widht_px"), std::string::npos);
  EXPECT_NE(error_of("map_view:\n  width_px: 10\n").find("map_view.width_px"), std::string::npos);
  EXPECT_NE(error_of("map_view:\n  height_px: 100\n  footer_px: 90\n").find("map_view"), std::string::npos);
  EXPECT_NE(error_of("viewer: {}\n").find("viewer"), std::string::npos);
}

#ifdef PIXYSLAM_CONFIG_DIR
TEST(MapViewOptions, ShippedConfigIsValid) {
  const MapViewOptions o = read_map_view_options_file(PIXYSLAM_CONFIG_DIR "/map_view.yaml", "");
  EXPECT_EQ(o.render.width_px, 800);
  EXPECT_EQ(o.dds.profiles_file, PIXYSLAM_CONFIG_DIR "/dds/profiles.xml");
}
#endif

}  // namespace
}  // namespace pixyslam::map_view
