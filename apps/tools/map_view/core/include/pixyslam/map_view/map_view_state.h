#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pixyslam::map_view {

// A point of the map frame, metres (x forward at theta = 0, y to the left).
struct Point2 {
  double x_m = 0.0;
  double y_m = 0.0;
};

// A pose of the map frame: theta counter-clockwise from the map x axis.
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

// An estimated landmark: mean and 2x2 covariance (m^2) in the map frame.
struct LandmarkView {
  int id = 0;
  double x_m = 0.0;
  double y_m = 0.0;
  double cov_xx_m2 = 0.0;
  double cov_xy_m2 = 0.0;
  double cov_yy_m2 = 0.0;
  unsigned times_observed = 0;
};

// A landmark's true position (simulation only).
struct TrueLandmarkView {
  int id = 0;
  double x_m = 0.0;
  double y_m = 0.0;
};

// Everything the map view draws, as plain values: what the estimator's
// MapState, the map optimiser's OptimisedMap and the simulator's GroundTruth
// say, plus the trajectories accumulated so far. Empty vectors / unset
// optionals are simply not drawn; non-finite values are skipped.
struct MapViewState {
  std::vector<Pose2> particles;           // the (subsampled) particle poses
  std::vector<Point2> mean_trajectory;    // the weighted mean position after every update so far
  std::optional<Pose2> current_pose;      // the mean pose now (drawn as an arrow)
  std::vector<LandmarkView> landmarks;    // the map
  std::vector<Point2> true_trajectory;    // ground truth path (optional)
  std::optional<Pose2> true_pose;         // ground truth pose now (optional)
  std::vector<TrueLandmarkView> true_landmarks;
  std::vector<Point2> optimised_trajectory;       // the map optimiser's keyframes (optional)
  std::vector<LandmarkView> optimised_landmarks;  // its landmarks; non-finite covariance: no ellipse
  std::string caption;                    // one line under the map, e.g. "t = 12.3 s  ..."
  std::string robot_id;                   // whose state this is ("" : one robot, not named)
  std::vector<LandmarkView> fleet_landmarks;  // the robots' maps fused (fleet_map), optional
  // More robots on the same map (several on one domain, or a fleet log): each
  // drawn like this one in a colour of its own, under it; their own
  // other_robots are ignored.
  std::vector<MapViewState> other_robots;
};

// Appends `p` to `path` unless it is closer than `min_step_m` to the last point
// kept (a cheap decimation for long runs; 0 keeps every point). Non-finite
// points are dropped.
void append_point(std::vector<Point2>& path, Point2 p, double min_step_m);

// Most points a drawn path keeps (320 KB): a live view runs for days.
inline constexpr std::size_t kMaxPathPoints = 20000;

// A path that grows for days at an even density: append_point(), and past
// max_points every other point is dropped and from then on only every second
// new point stays (the stride doubles each time), so old and new parts of the
// run are thinned alike. The newest point is always the path's last.
class PathThinning {
 public:
  explicit PathThinning(double min_step_m = 0.0, std::size_t max_points = kMaxPathPoints);
  void append(std::vector<Point2>& path, Point2 p);
  // For a path built again from its start (the optimiser's whole solution).
  void reset();

 private:
  double min_step_m_;
  std::size_t max_points_;
  std::size_t stride_ = 1;    // one point kept in this many
  std::size_t appended_ = 0;  // points taken since the stride last changed
  bool provisional_ = false;  // the last point is the newest, not one that stays
};

// What the caption reports about one estimator state.
struct CaptionInfo {
  double time_s = 0.0;             // since the start of the run
  unsigned particle_count = 0;
  double effective_sample_size = 0.0;
  std::size_t landmark_count = 0;
  std::string robot_id;            // "" : left out
};

// "t = 12.3 s   100 particles   ESS 87.2   20 landmarks   robot1"
std::string format_caption(const CaptionInfo& info);

}  // namespace pixyslam::map_view
