// Foxglove scene messages from MapState/GroundTruth (pixyslam/foxglove/visualiser.h).
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "foxglove_framesPubSubTypes.h"
#include "foxglove_scenePubSubTypes.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/foxglove/visualiser.h"

namespace pixyslam::foxglove {
namespace {

msg::MapState state_with_landmarks(std::uint64_t stamp_ns, double x) {
  msg::MapState s;
  s.header().stamp_ns(stamp_ns);
  s.header().robot_id("robot7");
  s.mean_pose().x_m(x);
  s.mean_pose().y_m(-1.0);
  s.mean_pose().theta_rad(0.5);
  s.pose_covariance({0.04, 0, 0, 0, 0.01, 0, 0, 0, 0.001});
  for (int id : {3, 11}) {
    msg::LandmarkEstimate l;
    l.landmark_id(id);
    l.x_m(id);
    l.y_m(2.0);
    l.cov_xx_m2(0.09);
    l.cov_yy_m2(0.01);
    s.landmarks().push_back(l);
  }
  msg::Pose2D p;
  s.particle_poses().push_back(p);
  s.particle_poses().push_back(p);
  return s;
}

TEST(CovarianceEllipse, AxesAreTwiceSigmaTimesTheRootEigenvalues) {
  const Ellipse e = covariance_ellipse(0.09, 0.0, 0.01, 2.0);
  EXPECT_NEAR(e.major_m, 2 * 2 * 0.3, 1e-12);
  EXPECT_NEAR(e.minor_m, 2 * 2 * 0.1, 1e-12);
  EXPECT_NEAR(e.angle_rad, 0.0, 1e-12);
  // Rotated by 45 degrees: cov = R diag(a, b) R^T.
  const Ellipse r = covariance_ellipse(0.05, 0.04, 0.05, 1.0);
  EXPECT_NEAR(r.major_m, 2 * 0.3, 1e-12);
  EXPECT_NEAR(r.minor_m, 2 * 0.1, 1e-12);
  EXPECT_NEAR(r.angle_rad, M_PI / 4, 1e-12);
  // Numerically negative eigenvalue: a zero axis, not NaN.
  EXPECT_EQ(covariance_ellipse(1.0, 1.0 + 1e-12, 1.0, 2.0).minor_m, 0.0);
}

TEST(Visualiser, OneEntityPerLandmarkAfterDeletingAll) {
  Visualiser v;
  const ::foxglove::SceneUpdate u = v.landmark_scene(state_with_landmarks(5'000'000'123, 1.0));
  ASSERT_EQ(u.deletions().size(), 1u);
  EXPECT_EQ(u.deletions()[0].type(), ::foxglove::SceneEntityDeletionType::ALL);
  ASSERT_EQ(u.entities().size(), 2u);
  EXPECT_EQ(u.entities()[0].id(), "landmark_3");
  EXPECT_EQ(u.entities()[1].texts()[0].text(), "11");
  EXPECT_EQ(u.entities()[0].timestamp().sec(), 5u);
  EXPECT_EQ(u.entities()[0].timestamp().nsec(), 123u);
  EXPECT_EQ(u.entities()[0].frame_id(), "map");
  EXPECT_EQ(u.entities()[0].metadata()[0].value(), "robot7");
  EXPECT_NEAR(u.entities()[0].cylinders()[0].size().x(), 1.2, 1e-12);  // 2 sigma of 0.3 m, both sides
}

TEST(Visualiser, MapStateGivesFourMessagesThatDecode) {
  Visualiser v;
  const std::vector<VisualMessage> out = v.on_map_state(state_with_landmarks(1, 2.5));
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[3].channel, VisualChannel::kTransform);
  ::foxglove::FrameTransformPubSubType type;
  ::foxglove::FrameTransform tf;
  std::string error;
  ASSERT_TRUE(dds::deserialize_payload(type, out[3].cdr.data(), out[3].cdr.size(), &tf, error)) << error;
  EXPECT_EQ(tf.translation().x(), 2.5);
  EXPECT_NEAR(2 * std::atan2(tf.rotation().z(), tf.rotation().w()), 0.5, 1e-12);
  ::foxglove::SceneUpdatePubSubType scene_type;
  ::foxglove::SceneUpdate estimate;
  ASSERT_TRUE(dds::deserialize_payload(scene_type, out[1].cdr.data(), out[1].cdr.size(), &estimate, error));
  EXPECT_EQ(estimate.entities()[0].arrows().size(), 2u);  // one per particle
}

TEST(Visualiser, PathIsBoundedAndKeepsItsEnds) {
  VisualOptions o;
  o.path_max_poses = 10;
  o.path_min_step_m = 0.05;
  Visualiser v(o);
  ::foxglove::PosesInFramePubSubType type;
  ::foxglove::PosesInFrame path;
  for (int i = 0; i < 100; ++i) {
    const std::vector<VisualMessage> out = v.on_map_state(state_with_landmarks(i + 1, 0.1 * i));
    std::string error;
    ASSERT_TRUE(dds::deserialize_payload(type, out[2].cdr.data(), out[2].cdr.size(), &path, error)) << error;
    ASSERT_LE(path.poses().size(), 10u);
  }
  EXPECT_EQ(path.poses().front().position().x(), 0.0);
  EXPECT_NEAR(path.poses().back().position().x(), 9.9, 1e-12);
  // Steps below path_min_step_m move the last pose instead of adding one.
  Visualiser still(o);
  for (int i = 0; i < 5; ++i) still.on_map_state(state_with_landmarks(i + 1, 0.01 * i));
  const std::vector<VisualMessage> out = still.on_map_state(state_with_landmarks(9, 0.045));
  std::string error;
  ASSERT_TRUE(dds::deserialize_payload(type, out[2].cdr.data(), out[2].cdr.size(), &path, error));
  EXPECT_EQ(path.poses().size(), 1u);
  EXPECT_EQ(path.poses()[0].position().x(), 0.045);
}

// Several robots (or a hostile writer) on the domain: the visuals follow one
// robot, the first seen unless robot_id names one; the others' states are
// counted and make no visuals, so one path never zigzags between robots.
TEST(Visualiser, OneRobotIsDrawnAndOthersAreCounted) {
  for (const std::string& chosen : {std::string(), std::string("robot8")}) {
    VisualOptions o;
    o.robot_id = chosen;
    Visualiser v(o);
    const std::string drawn = chosen.empty() ? "robot7" : chosen;
    std::size_t paths = 0;
    for (int i = 0; i < 6; ++i) {
      msg::MapState s = state_with_landmarks(i + 1, 0.1 * i);
      s.header().robot_id(i % 2 == 0 ? "robot7" : "robot8");
      const std::vector<VisualMessage> out = v.on_map_state(s);
      if (s.header().robot_id() != drawn) {
        EXPECT_TRUE(out.empty());
        continue;
      }
      ASSERT_EQ(out.size(), 4u);
      ::foxglove::PosesInFramePubSubType type;
      ::foxglove::PosesInFrame path;
      std::string error;
      ASSERT_TRUE(dds::deserialize_payload(type, out[2].cdr.data(), out[2].cdr.size(), &path, error)) << error;
      EXPECT_EQ(path.poses().size(), ++paths);
      for (const auto& p : path.poses()) EXPECT_EQ(std::lround(p.position().x() * 10) % 2, drawn == "robot7" ? 0 : 1);
    }
    EXPECT_EQ(v.other_robot(), 3u);
    msg::GroundTruth other;
    other.header().robot_id("robot9");
    EXPECT_TRUE(v.on_ground_truth(other).empty());
    EXPECT_EQ(v.other_robot(), 4u);
  }
}

TEST(Visualiser, OnlyWantedChannelsAreBuiltAndThePathGrowsMeanwhile) {
  Visualiser v;
  const auto none = [](VisualChannel) { return false; };
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(v.on_map_state(state_with_landmarks(i + 1, 0.1 * i), none).empty());
  const std::vector<VisualMessage> out =
      v.on_map_state(state_with_landmarks(6, 0.5), [](VisualChannel c) { return c == VisualChannel::kPath; });
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].channel, VisualChannel::kPath);
  ::foxglove::PosesInFramePubSubType type;
  ::foxglove::PosesInFrame path;
  std::string error;
  ASSERT_TRUE(dds::deserialize_payload(type, out[0].cdr.data(), out[0].cdr.size(), &path, error)) << error;
  EXPECT_EQ(path.poses().size(), 6u);  // the five unwanted states' poses too
  msg::GroundTruth truth;
  truth.header().robot_id("robot7");
  truth.landmarks().resize(3);
  const std::vector<VisualMessage> true_out =
      v.on_ground_truth(truth, [](VisualChannel c) { return c == VisualChannel::kTrueLandmarks; });
  ASSERT_EQ(true_out.size(), 1u);
  EXPECT_EQ(true_out[0].channel, VisualChannel::kTrueLandmarks);
}

TEST(Visualiser, MalformedPayloadIsRefusedOthersIgnored) {
  Visualiser v;
  std::vector<VisualMessage> out;
  std::string error;
  EXPECT_FALSE(v.on_payload("pixyslam::msg::MapState", {0, 1, 0, 0, 7}, out, error));
  EXPECT_FALSE(error.empty());
  EXPECT_TRUE(v.on_payload("pixyslam::msg::Odometry", {0, 1, 0, 0}, out, error));
  EXPECT_TRUE(out.empty());
  msg::GroundTruth truth;
  truth.landmarks().resize(3);
  ASSERT_TRUE(v.on_payload("pixyslam::msg::GroundTruth", dds::to_cdr(truth), out, error)) << error;
  EXPECT_EQ(out.size(), 2u);
}

}  // namespace
}  // namespace pixyslam::foxglove
