#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "map_state.h"
#include "fleet_map.h"
#include "ground_truth.h"
#include "optimised_map.h"
#include "pixyslam/dds/newest_stamp.h"
#include "pixyslam/map_view/map_view_state.h"

namespace pixyslam::map_view {

// Flat conversions from the DDS messages to the map view's plain structs.
Pose2 to_pose(const msg::Pose2D& pose);
LandmarkView to_landmark(const msg::LandmarkEstimate& landmark);
std::vector<LandmarkView> to_landmarks(const msg::MapState& state);
std::vector<TrueLandmarkView> to_true_landmarks(const msg::GroundTruth& truth);
LandmarkView to_landmark(const msg::OptimisedLandmark& landmark);  // times_observed = observations
std::vector<LandmarkView> to_landmarks(const msg::OptimisedMap& map);
std::vector<Point2> to_trajectory(const msg::OptimisedMap& map);    // the keyframes' positions
std::vector<LandmarkView> to_landmarks(const msg::FleetMap& map);   // times_observed = robots fused

// Builds the MapViewState from a stream of MapState, OptimisedMap and
// GroundTruth messages: the latest map, particles and poses, and the mean and
// true trajectories accumulated so far (decimated by `trajectory_min_step_m`);
// the latest optimised solution (its keyframes, decimated alike, and
// landmarks) replaces the one before. A MapState or OptimisedMap stamped
// up to 10 s before the last one of its kind taken (a late joiner's stale
// state) is ignored; further behind, the time went back (dds::NewestStamp:
// one stamp far ahead cannot freeze the view). Caption times are relative to
// the first stamp of any kind.
// Thread-compatible (the live view guards it with a mutex).
class MapViewBuilder {
 public:
  explicit MapViewBuilder(double trajectory_min_step_m = 0.0)
      : min_step_m_(trajectory_min_step_m), mean_path_(min_step_m_), true_path_(min_step_m_) {}

  // False if the message was ignored (older than the last MapState).
  bool add(const msg::MapState& state);
  void add(const msg::GroundTruth& truth);
  // False if the message was ignored (older than the last OptimisedMap).
  bool add(const msg::OptimisedMap& map);

  const MapViewState& state() const { return state_; }
  std::size_t map_states() const { return map_order_.taken(); }
  std::size_t ground_truths() const { return ground_truths_; }
  std::size_t optimised_maps() const { return optimised_order_.taken(); }

 private:
  void note_stamp(std::uint64_t stamp_ns);

  double min_step_m_;
  PathThinning mean_path_, true_path_;
  MapViewState state_;
  dds::NewestStamp map_order_, optimised_order_;
  std::size_t ground_truths_ = 0;
  bool have_start_ = false;
  std::uint64_t start_ns_ = 0;
};

// One MapViewBuilder per robot (header.robot_id): several robots on one
// domain or in one log are drawn in one picture. state() is the first robot's
// (by id) with the others in other_robots; each robot's times count from its
// own first stamp. At most kMaxRobots robots: a sample of a further robot id
// (any participant can invent them) takes the place of the robot heard from
// least recently, which is counted, so that ids invented once cannot keep a
// real robot out for good. Thread-compatible.
class FleetViewBuilder {
 public:
  static constexpr std::size_t kMaxRobots = 64;  // as fleet_map.max_robots

  explicit FleetViewBuilder(double trajectory_min_step_m = 0.0) : min_step_m_(trajectory_min_step_m) {}

  bool add(const msg::MapState& state) {
    MapViewBuilder* b = robot(state.header().robot_id());
    return b != nullptr && b->add(state);
  }
  void add(const msg::GroundTruth& truth) {
    if (MapViewBuilder* b = robot(truth.header().robot_id())) b->add(truth);
  }
  bool add(const msg::OptimisedMap& map) {
    MapViewBuilder* b = robot(map.header().robot_id());
    return b != nullptr && b->add(map);
  }
  // The newest fleet map (older ones are ignored as MapState's: false).
  bool add(const msg::FleetMap& map);

  MapViewState state() const;
  std::size_t robots() const { return robots_.size(); }
  // Robots dropped to make room for a new robot id past kMaxRobots.
  std::size_t robots_evicted() const { return robots_evicted_; }
  // Totals over the robots.
  std::size_t map_states() const { return total(&MapViewBuilder::map_states); }
  std::size_t ground_truths() const { return total(&MapViewBuilder::ground_truths); }
  std::size_t optimised_maps() const { return total(&MapViewBuilder::optimised_maps); }
  std::size_t fleet_maps() const { return fleet_order_.taken(); }

 private:
  // The robot's builder; past kMaxRobots a new one in the place of the robot
  // heard from least recently.
  MapViewBuilder* robot(const std::string& robot_id);
  std::size_t total(std::size_t (MapViewBuilder::*count)() const) const;

  struct Robot {
    MapViewBuilder builder;
    std::uint64_t last_heard = 0;  // the sample count when its last sample came
  };
  double min_step_m_;
  std::uint64_t samples_ = 0;
  std::map<std::string, Robot> robots_;
  std::vector<LandmarkView> fleet_landmarks_;
  dds::NewestStamp fleet_order_;
  std::size_t robots_evicted_ = 0;
};

}  // namespace pixyslam::map_view
