#include "pixyslam/map_view/msg_conversion.h"

#include <algorithm>

namespace pixyslam::map_view {

Pose2 to_pose(const msg::Pose2D& pose) { return {pose.x_m(), pose.y_m(), pose.theta_rad()}; }

namespace {
// The fields a filter's and an optimiser's landmark share.
template <class Landmark>
LandmarkView landmark_view(const Landmark& l, unsigned times_observed) {
  LandmarkView v;
  v.id = l.landmark_id();
  v.x_m = l.x_m();
  v.y_m = l.y_m();
  v.cov_xx_m2 = l.cov_xx_m2();
  v.cov_xy_m2 = l.cov_xy_m2();
  v.cov_yy_m2 = l.cov_yy_m2();
  v.times_observed = times_observed;
  return v;
}
}  // namespace

LandmarkView to_landmark(const msg::LandmarkEstimate& l) { return landmark_view(l, l.times_observed()); }

std::vector<LandmarkView> to_landmarks(const msg::MapState& state) {
  std::vector<LandmarkView> out;
  out.reserve(state.landmarks().size());
  for (const msg::LandmarkEstimate& l : state.landmarks()) out.push_back(to_landmark(l));
  return out;
}

std::vector<TrueLandmarkView> to_true_landmarks(const msg::GroundTruth& truth) {
  std::vector<TrueLandmarkView> out;
  out.reserve(truth.landmarks().size());
  for (const msg::TrueLandmark& l : truth.landmarks()) out.push_back({l.landmark_id(), l.x_m(), l.y_m()});
  return out;
}

LandmarkView to_landmark(const msg::OptimisedLandmark& l) { return landmark_view(l, l.observations()); }

std::vector<LandmarkView> to_landmarks(const msg::OptimisedMap& map) {
  std::vector<LandmarkView> out;
  out.reserve(map.landmarks().size());
  for (const msg::OptimisedLandmark& l : map.landmarks()) out.push_back(to_landmark(l));
  return out;
}

std::vector<Point2> to_trajectory(const msg::OptimisedMap& map) {
  std::vector<Point2> out;
  out.reserve(map.keyframes().size());
  for (const msg::OptimisedKeyframe& k : map.keyframes()) out.push_back({k.pose().x_m(), k.pose().y_m()});
  return out;
}

void MapViewBuilder::note_stamp(std::uint64_t stamp_ns) {
  if (!have_start_ || stamp_ns < start_ns_) {
    start_ns_ = stamp_ns;
    have_start_ = true;
  }
}

bool MapViewBuilder::add(const msg::MapState& m) {
  const std::uint64_t stamp = m.header().stamp_ns();
  if (!map_order_.take(stamp)) return false;
  note_stamp(stamp);

  state_.particles.clear();
  for (const msg::Pose2D& p : m.particle_poses()) state_.particles.push_back(to_pose(p));
  state_.current_pose = to_pose(m.mean_pose());
  mean_path_.append(state_.mean_trajectory, {m.mean_pose().x_m(), m.mean_pose().y_m()});
  state_.landmarks = to_landmarks(m);

  CaptionInfo info;
  info.time_s = static_cast<double>(stamp - start_ns_) * 1e-9;
  info.particle_count = m.particle_count();
  info.effective_sample_size = m.effective_sample_size();
  info.landmark_count = m.landmarks().size();
  info.robot_id = m.header().robot_id();
  state_.caption = format_caption(info);
  return true;
}

void MapViewBuilder::add(const msg::GroundTruth& g) {
  note_stamp(g.header().stamp_ns());
  ++ground_truths_;
  state_.true_pose = to_pose(g.pose());
  true_path_.append(state_.true_trajectory, {g.pose().x_m(), g.pose().y_m()});
  if (!g.landmarks().empty() || state_.true_landmarks.empty()) state_.true_landmarks = to_true_landmarks(g);
}

bool MapViewBuilder::add(const msg::OptimisedMap& m) {
  const std::uint64_t stamp = m.header().stamp_ns();
  if (!optimised_order_.take(stamp)) return false;
  note_stamp(stamp);
  // Each solution holds the whole trajectory: it replaces the one before.
  state_.optimised_trajectory.clear();
  for (const Point2& p : to_trajectory(m)) append_point(state_.optimised_trajectory, p, min_step_m_);
  state_.optimised_landmarks = to_landmarks(m);
  return true;
}

std::vector<LandmarkView> to_landmarks(const msg::FleetMap& map) {
  std::vector<LandmarkView> out;
  out.reserve(map.landmarks().size());
  for (const msg::FleetLandmark& l : map.landmarks()) {
    out.push_back({l.landmark_id(), l.x_m(), l.y_m(), l.cov_xx_m2(), l.cov_xy_m2(), l.cov_yy_m2(), l.robots()});
  }
  return out;
}

bool FleetViewBuilder::add(const msg::FleetMap& map) {
  if (!fleet_order_.take(map.header().stamp_ns())) return false;
  fleet_landmarks_ = to_landmarks(map);
  return true;
}

MapViewBuilder* FleetViewBuilder::robot(const std::string& robot_id) {
  ++samples_;
  if (const auto it = robots_.find(robot_id); it != robots_.end()) {
    it->second.last_heard = samples_;
    return &it->second.builder;
  }
  if (robots_.size() >= kMaxRobots) {
    const auto oldest = std::min_element(robots_.begin(), robots_.end(), [](const auto& a, const auto& b) {
      return a.second.last_heard < b.second.last_heard;
    });
    robots_.erase(oldest);
    ++robots_evicted_;
  }
  return &robots_.try_emplace(robot_id, Robot{MapViewBuilder(min_step_m_), samples_}).first->second.builder;
}

MapViewState FleetViewBuilder::state() const {
  MapViewState out;
  bool first = true;
  for (const auto& [id, robot] : robots_) {
    MapViewState one = robot.builder.state();
    one.robot_id = id;
    if (first) {
      out = std::move(one);
    } else {
      out.other_robots.push_back(std::move(one));
    }
    first = false;
  }
  out.fleet_landmarks = fleet_landmarks_;
  return out;
}

std::size_t FleetViewBuilder::total(std::size_t (MapViewBuilder::*count)() const) const {
  std::size_t n = 0;
  for (const auto& entry : robots_) n += (entry.second.builder.*count)();
  return n;
}

}  // namespace pixyslam::map_view
