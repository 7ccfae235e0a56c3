#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "foxglove_frames.h"
#include "foxglove_scene.h"
#include "ground_truth.h"
#include "map_state.h"

// The system's state as Foxglove's own schemas (foxglove.SceneUpdate,
// foxglove.PosesInFrame, foxglove.FrameTransform), drawn by Foxglove's 3D panel
// with no plugin. Used live (foxglove_bridge) and on recordings
// (pixyslam_log foxglove). Pure: messages in, messages out, no clock.
namespace pixyslam::foxglove {

// The channels the visualiser writes, in this order (VisualMessage::channel).
enum class VisualChannel : std::size_t {
  kLandmarks = 0,     // SceneUpdate: each landmark's n-sigma ellipse and id
  kEstimate,          // SceneUpdate: particles (arrows), pose n-sigma ellipse
  kPath,              // PosesInFrame: the estimated trajectory (mean pose)
  kTransform,         // FrameTransform: map -> robot frame (mean pose)
  kTruePath,          // PosesInFrame: the true trajectory (simulation)
  kTrueLandmarks,     // SceneUpdate: the true landmarks (simulation)
  kCount
};

struct VisualChannelInfo {
  std::string topic;        // e.g. "pixyslam/viz/landmarks"
  std::string schema_name;  // e.g. "foxglove::SceneUpdate"
  std::string idl_stem;     // msg::idl_text(idl_stem) is its schema
};
// Indexed by VisualChannel.
const std::vector<VisualChannelInfo>& visual_channels();

struct VisualOptions {
  std::string map_frame = "map";
  std::string robot_frame = "base_link";
  double ellipse_sigma = 2.0;        // ellipses drawn at this many standard deviations
  std::size_t path_max_poses = 1000; // a longer path keeps every other pose (whole extent, bounded size)
  double path_min_step_m = 0.02;     // a pose joins the path once this far from the last one
  // The robot drawn (header.robot_id of MapState and GroundTruth); empty: the
  // first robot seen. Other robots' samples make no visuals (other_robot()).
  std::string robot_id;
};

// One output message: CDR payload (encapsulation header first) of the channel's schema.
struct VisualMessage {
  VisualChannel channel = VisualChannel::kLandmarks;
  std::uint64_t stamp_ns = 0;  // the input's header stamp
  std::vector<std::uint8_t> cdr;
};

// An ellipse of a 2x2 covariance at `sigma` standard deviations: full axis
// lengths and the major axis' angle from x.
struct Ellipse {
  double major_m = 0.0;
  double minor_m = 0.0;
  double angle_rad = 0.0;
};
Ellipse covariance_ellipse(double cov_xx, double cov_xy, double cov_yy, double sigma);

// Not thread-safe (one per thread, or a lock): it keeps the paths and the
// serializers.
class Visualiser {
 public:
  explicit Visualiser(VisualOptions options = {});
  ~Visualiser();
  Visualiser(const Visualiser&) = delete;
  Visualiser& operator=(const Visualiser&) = delete;

  // Which channels to build and serialize (empty: all). The paths grow either
  // way, so a channel wanted later starts with the whole path.
  using ChannelFilter = std::function<bool(VisualChannel)>;

  // Landmarks, particles and pose ellipse, path, transform (nothing for
  // another robot's state).
  std::vector<VisualMessage> on_map_state(const msg::MapState& state, const ChannelFilter& wanted = {});
  // True path and true landmarks (nothing for another robot's).
  std::vector<VisualMessage> on_ground_truth(const msg::GroundTruth& truth, const ChannelFilter& wanted = {});
  // Decodes a CDR payload of `type_name` and calls the above; other types give
  // nothing. Returns false with `error` set when the payload does not decode.
  bool on_payload(std::string_view type_name, const std::vector<std::uint8_t>& payload,
                  std::vector<VisualMessage>& out, std::string& error);

  // Samples of robots other than the one drawn.
  std::uint64_t other_robot() const { return other_robot_; }

  // The typed messages (what on_* serialize), for tests.
  ::foxglove::SceneUpdate landmark_scene(const msg::MapState& state) const;
  ::foxglove::SceneUpdate estimate_scene(const msg::MapState& state) const;

 private:
  // True for the robot drawn (the first seen when options_.robot_id is empty).
  bool drawn(const std::string& robot_id);
  // Adds `pose` to `path` (decimating).
  void extend_path(std::deque<msg::Pose2D>& path, const msg::Pose2D& pose) const;
  ::foxglove::PosesInFrame path_message(const std::deque<msg::Pose2D>& path, std::uint64_t stamp_ns) const;

  // The generated serializers, made once: their constructors walk the nested
  // unbounded sequences (fastddsgen's maximum size), far too slow per message.
  struct Serializers;
  std::unique_ptr<Serializers> serializers_;
  VisualOptions options_;
  std::deque<msg::Pose2D> path_;
  std::deque<msg::Pose2D> true_path_;
  std::uint64_t other_robot_ = 0;
};

}  // namespace pixyslam::foxglove
