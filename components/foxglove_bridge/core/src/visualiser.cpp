#include "pixyslam/foxglove/visualiser.h"

#include <cmath>

#include "foxglove_framesPubSubTypes.h"
#include "foxglove_scenePubSubTypes.h"
#include "pixyslam/dds/cdr_payload.h"

namespace pixyslam::foxglove {

namespace fg = ::foxglove;

const std::vector<VisualChannelInfo>& visual_channels() {
  static const std::vector<VisualChannelInfo> channels = {
      {"pixyslam/viz/landmarks", "foxglove::SceneUpdate", "foxglove_scene"},
      {"pixyslam/viz/estimate", "foxglove::SceneUpdate", "foxglove_scene"},
      {"pixyslam/viz/path", "foxglove::PosesInFrame", "foxglove_frames"},
      {"pixyslam/viz/tf", "foxglove::FrameTransform", "foxglove_frames"},
      {"pixyslam/viz/true_path", "foxglove::PosesInFrame", "foxglove_frames"},
      {"pixyslam/viz/true_landmarks", "foxglove::SceneUpdate", "foxglove_scene"},
  };
  return channels;
}

Ellipse covariance_ellipse(double cov_xx, double cov_xy, double cov_yy, double sigma) {
  // Eigenvalues of the symmetric 2x2 matrix; a negative one (numerical) counts as 0.
  const double mean = 0.5 * (cov_xx + cov_yy);
  const double spread = std::hypot(0.5 * (cov_xx - cov_yy), cov_xy);
  Ellipse e;
  e.major_m = 2.0 * sigma * std::sqrt(std::max(0.0, mean + spread));
  e.minor_m = 2.0 * sigma * std::sqrt(std::max(0.0, mean - spread));
  e.angle_rad = 0.5 * std::atan2(2.0 * cov_xy, cov_xx - cov_yy);
  return e;
}

namespace {

fg::Time to_time(std::uint64_t stamp_ns) {
  fg::Time t;
  t.sec(static_cast<std::uint32_t>(stamp_ns / 1000000000ULL));
  t.nsec(static_cast<std::uint32_t>(stamp_ns % 1000000000ULL));
  return t;
}

fg::Quaternion yaw_quaternion(double yaw) {
  fg::Quaternion q;
  q.z(std::sin(0.5 * yaw));
  q.w(std::cos(0.5 * yaw));
  return q;
}

fg::PoseData pose_at(double x, double y, double z, double yaw) {
  fg::PoseData p;
  p.position().x(x);
  p.position().y(y);
  p.position().z(z);
  p.orientation(yaw_quaternion(yaw));
  return p;
}

fg::ColorRgba rgba(double r, double g, double b, double a) {
  fg::ColorRgba c;
  c.r(r);
  c.g(g);
  c.b(b);
  c.a(a);
  return c;
}

fg::SceneEntity entity(const std::string& frame, const std::string& id, std::uint64_t stamp_ns,
                       const std::string& robot_id) {
  fg::SceneEntity e;
  e.timestamp(to_time(stamp_ns));
  e.frame_id(frame);
  e.id(id);
  fg::KeyValuePair robot;
  robot.key("robot_id");
  robot.value(robot_id);
  e.metadata().push_back(robot);
  return e;
}

// A flat disc (cylinder) of the ellipse's axes lying on the map plane.
fg::CylinderPrimitive ellipse_disc(double x, double y, const Ellipse& ellipse, const fg::ColorRgba& colour) {
  fg::CylinderPrimitive c;
  c.pose(pose_at(x, y, 0.0, ellipse.angle_rad));
  c.size().x(std::max(ellipse.major_m, 1e-3));
  c.size().y(std::max(ellipse.minor_m, 1e-3));
  c.size().z(0.005);
  c.bottom_scale(1.0);
  c.top_scale(1.0);
  c.color(colour);
  return c;
}

// Every previous entity goes first, so a landmark the new best particle lacks disappears.
fg::SceneUpdate replacing_all(std::uint64_t stamp_ns) {
  fg::SceneUpdate update;
  fg::SceneEntityDeletion all;
  all.timestamp(to_time(stamp_ns));
  all.type(fg::SceneEntityDeletionType::ALL);
  update.deletions().push_back(all);
  return update;
}

template <class PubSubType, class Foxglove>
VisualMessage serialized(PubSubType& type, VisualChannel channel, std::uint64_t stamp_ns, const Foxglove& message) {
  return {channel, stamp_ns, dds::serialize_payload(type, &message)};
}

}  // namespace

struct Visualiser::Serializers {
  fg::SceneUpdatePubSubType scene;
  fg::PosesInFramePubSubType poses;
  fg::FrameTransformPubSubType transform;
};

Visualiser::Visualiser(VisualOptions options)
    : serializers_(std::make_unique<Serializers>()), options_(std::move(options)) {}

Visualiser::~Visualiser() = default;

fg::SceneUpdate Visualiser::landmark_scene(const msg::MapState& state) const {
  const std::uint64_t stamp = state.header().stamp_ns();
  fg::SceneUpdate update = replacing_all(stamp);
  for (const msg::LandmarkEstimate& l : state.landmarks()) {
    fg::SceneEntity e = entity(options_.map_frame, "landmark_" + std::to_string(l.landmark_id()), stamp,
                               state.header().robot_id());
    e.cylinders().push_back(ellipse_disc(
        l.x_m(), l.y_m(), covariance_ellipse(l.cov_xx_m2(), l.cov_xy_m2(), l.cov_yy_m2(), options_.ellipse_sigma),
        rgba(1.0, 0.55, 0.0, 0.6)));
    fg::SpherePrimitive centre;
    centre.pose(pose_at(l.x_m(), l.y_m(), 0.0, 0.0));
    centre.size().x(0.04);
    centre.size().y(0.04);
    centre.size().z(0.04);
    centre.color(rgba(1.0, 0.55, 0.0, 1.0));
    e.spheres().push_back(centre);
    fg::TextPrimitive label;
    label.pose(pose_at(l.x_m(), l.y_m(), 0.15, 0.0));
    label.billboard(true);
    label.font_size(14.0);
    label.scale_invariant(true);
    label.color(rgba(1.0, 1.0, 1.0, 1.0));
    label.text(std::to_string(l.landmark_id()));
    e.texts().push_back(label);
    update.entities().push_back(std::move(e));
  }
  return update;
}

fg::SceneUpdate Visualiser::estimate_scene(const msg::MapState& state) const {
  const std::uint64_t stamp = state.header().stamp_ns();
  fg::SceneUpdate update = replacing_all(stamp);
  fg::SceneEntity particles = entity(options_.map_frame, "particles", stamp, state.header().robot_id());
  for (const msg::Pose2D& p : state.particle_poses()) {
    fg::ArrowPrimitive a;
    a.pose(pose_at(p.x_m(), p.y_m(), 0.0, p.theta_rad()));
    a.shaft_length(0.06);
    a.shaft_diameter(0.008);
    a.head_length(0.03);
    a.head_diameter(0.02);
    a.color(rgba(0.2, 0.5, 1.0, 0.7));
    particles.arrows().push_back(a);
  }
  update.entities().push_back(std::move(particles));

  const auto& cov = state.pose_covariance();  // row-major (x, y, theta)
  fg::SceneEntity pose = entity(options_.map_frame, "pose_uncertainty", stamp, state.header().robot_id());
  pose.cylinders().push_back(ellipse_disc(state.mean_pose().x_m(), state.mean_pose().y_m(),
                                          covariance_ellipse(cov[0], cov[1], cov[4], options_.ellipse_sigma),
                                          rgba(0.1, 0.9, 0.3, 0.4)));
  update.entities().push_back(std::move(pose));
  return update;
}

void Visualiser::extend_path(std::deque<msg::Pose2D>& path, const msg::Pose2D& pose) const {
  if (path.empty() ||
      std::hypot(pose.x_m() - path.back().x_m(), pose.y_m() - path.back().y_m()) >= options_.path_min_step_m) {
    path.push_back(pose);
  } else {
    path.back() = pose;  // the path always ends at the current pose
  }
  if (path.size() > options_.path_max_poses) {
    // Keep every other pose (and the newest), so the whole run stays in view.
    std::deque<msg::Pose2D> kept;
    for (std::size_t i = 0; i + 1 < path.size(); i += 2) kept.push_back(path[i]);
    kept.push_back(path.back());
    path.swap(kept);
  }
}

fg::PosesInFrame Visualiser::path_message(const std::deque<msg::Pose2D>& path, std::uint64_t stamp_ns) const {
  fg::PosesInFrame out;
  out.timestamp(to_time(stamp_ns));
  out.frame_id(options_.map_frame);
  for (const msg::Pose2D& p : path) out.poses().push_back(pose_at(p.x_m(), p.y_m(), 0.0, p.theta_rad()));
  return out;
}

bool Visualiser::drawn(const std::string& robot_id) {
  if (options_.robot_id.empty()) options_.robot_id = robot_id;
  if (robot_id == options_.robot_id) return true;
  ++other_robot_;
  return false;
}

std::vector<VisualMessage> Visualiser::on_map_state(const msg::MapState& state, const ChannelFilter& wanted) {
  if (!drawn(state.header().robot_id())) return {};
  const std::uint64_t stamp = state.header().stamp_ns();
  const auto want = [&](VisualChannel c) { return !wanted || wanted(c); };
  extend_path(path_, state.mean_pose());
  std::vector<VisualMessage> out;
  if (want(VisualChannel::kLandmarks)) {
    out.push_back(serialized(serializers_->scene, VisualChannel::kLandmarks, stamp, landmark_scene(state)));
  }
  if (want(VisualChannel::kEstimate)) {
    out.push_back(serialized(serializers_->scene, VisualChannel::kEstimate, stamp, estimate_scene(state)));
  }
  if (want(VisualChannel::kPath)) {
    out.push_back(serialized(serializers_->poses, VisualChannel::kPath, stamp, path_message(path_, stamp)));
  }
  if (want(VisualChannel::kTransform)) {
    fg::FrameTransform tf;
    tf.timestamp(to_time(stamp));
    tf.parent_frame_id(options_.map_frame);
    tf.child_frame_id(options_.robot_frame);
    tf.translation().x(state.mean_pose().x_m());
    tf.translation().y(state.mean_pose().y_m());
    tf.rotation(yaw_quaternion(state.mean_pose().theta_rad()));
    out.push_back(serialized(serializers_->transform, VisualChannel::kTransform, stamp, tf));
  }
  return out;
}

std::vector<VisualMessage> Visualiser::on_ground_truth(const msg::GroundTruth& truth, const ChannelFilter& wanted) {
  if (!drawn(truth.header().robot_id())) return {};
  const std::uint64_t stamp = truth.header().stamp_ns();
  const auto want = [&](VisualChannel c) { return !wanted || wanted(c); };
  extend_path(true_path_, truth.pose());
  std::vector<VisualMessage> out;
  if (want(VisualChannel::kTruePath)) {
    out.push_back(serialized(serializers_->poses, VisualChannel::kTruePath, stamp, path_message(true_path_, stamp)));
  }
  if (!want(VisualChannel::kTrueLandmarks)) return out;
  fg::SceneUpdate update = replacing_all(stamp);
  for (const msg::TrueLandmark& l : truth.landmarks()) {
    fg::SceneEntity e = entity(options_.map_frame, "true_landmark_" + std::to_string(l.landmark_id()), stamp,
                               truth.header().robot_id());
    fg::CubePrimitive cube;
    cube.pose(pose_at(l.x_m(), l.y_m(), 0.0, 0.0));
    cube.size().x(0.05);
    cube.size().y(0.05);
    cube.size().z(0.05);
    cube.color(rgba(0.7, 0.7, 0.7, 0.9));
    e.cubes().push_back(cube);
    update.entities().push_back(std::move(e));
  }
  out.push_back(serialized(serializers_->scene, VisualChannel::kTrueLandmarks, stamp, update));
  return out;
}

bool Visualiser::on_payload(std::string_view type_name, const std::vector<std::uint8_t>& payload,
                            std::vector<VisualMessage>& out, std::string& error) {
  if (type_name == "pixyslam::msg::MapState") {
    msg::MapState state;
    if (!dds::from_cdr(payload, state, error)) return false;
    out = on_map_state(state);
  } else if (type_name == "pixyslam::msg::GroundTruth") {
    msg::GroundTruth truth;
    if (!dds::from_cdr(payload, truth, error)) return false;
    out = on_ground_truth(truth);
  } else {
    out.clear();
  }
  return true;
}

}  // namespace pixyslam::foxglove
