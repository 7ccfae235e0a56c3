// The MRCLAM robot model applied to a dataset's commands and detections
// (apps/slam_offline/offline_run.h, docs/mrclam.md).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "mrclam_dataset.h"
#include "offline_run.h"

namespace pixyslam::offline {
namespace {

mrclam::RobotData one_robot() {
  mrclam::RobotData d;
  d.groundtruth.push_back({10.0, 1.0, 2.0, 0.5});
  d.odometry.push_back({10.0, 0.1, 0.0});
  d.odometry.push_back({11.0, 0.1, 0.4});
  d.odometry.push_back({12.0, 0.1, -1.0});
  mrclam::MeasurementFrame f;
  f.t_s = 10.5;
  f.detections.push_back({7, 2.0, 0.6});
  d.frames.push_back(f);
  return d;
}

TEST(MrclamInput, RobotsDriveSlowerWhileTurning) {
  MrclamSensorModel model;
  model.speed_scale = 1.04;
  model.speed_loss_per_radps = 1.13;
  model.odometry_delay_s = 0.15;
  const RunInput in = mrclam_input(one_robot(), model);
  ASSERT_EQ(in.odometry.size(), 3u);
  EXPECT_DOUBLE_EQ(in.odometry[0].t_s, 10.15);
  EXPECT_NEAR(in.odometry[0].v_mps, 0.104, 1e-12);
  EXPECT_NEAR(in.odometry[1].v_mps, 0.1 * (1.04 - 1.13 * 0.4), 1e-12);
  EXPECT_DOUBLE_EQ(in.odometry[2].v_mps, 0.0);  // never driven backwards
  EXPECT_DOUBLE_EQ(in.odometry[2].w_radps, -1.0);
  EXPECT_DOUBLE_EQ(in.start_time_s, 10.0);
}

TEST(MrclamInput, RangeShortenedOffAxisIsRestored) {
  MrclamSensorModel model;
  model.range_scale = 1.03;
  model.range_cos_bearing_exponent = 0.85;
  const RunInput in = mrclam_input(one_robot(), model);
  ASSERT_EQ(in.frames.size(), 1u);
  ASSERT_EQ(in.frames[0].detections.size(), 1u);
  EXPECT_NEAR(in.frames[0].detections[0].range_m, 2.0 / (1.03 * std::pow(std::cos(0.6), 0.85)), 1e-12);
  // Ideal sensors leave the data as recorded.
  const RunInput plain = mrclam_input(one_robot());
  EXPECT_DOUBLE_EQ(plain.frames[0].detections[0].range_m, 2.0);
  EXPECT_DOUBLE_EQ(plain.odometry[1].v_mps, 0.1);
}

}  // namespace
}  // namespace pixyslam::offline
