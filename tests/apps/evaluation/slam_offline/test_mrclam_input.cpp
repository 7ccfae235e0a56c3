// The MRCLAM robot model applied to a dataset's commands and detections
// (pixyslam/offline/offline_run.h, docs/mrclam.md).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"

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

// A robot that turns at 0.1 rad/s for 60 s while its odometry says 0.12 rad/s,
// with a camera frame every second from t = 20 s.
RunInput over_turning_robot() {
  RunInput in;
  in.start_time_s = 0.0;
  slam::Pose2 truth(0.0, 0.0, 0.0);
  for (int k = 0; k <= 600; ++k) {
    const double t = 0.1 * k;
    in.truth.push_back({t, truth.x(), truth.y(), truth.z()});
    in.odometry.push_back({t, 0.2, 0.12});
    truth = slam::move(truth, 0.2, 0.1, 0.1);
    if (k >= 200 && k % 10 == 0) in.frames.push_back({t, {slam::RangeBearing{}}});
  }
  return in;
}

TEST(DataLimits, HeadingErrorOfDeadReckoningAtTheFirstFrameAndLater) {
  const DataLimits limits = data_limits(over_turning_robot());
  EXPECT_NEAR(limits.first_frame_t_s, 20.0, 1e-9);
  EXPECT_NEAR(limits.heading_error_first_frame_rad, 0.02 * 20.0, 1e-6);
  EXPECT_NEAR(limits.heading_error_30s_later_rad, 0.02 * 50.0, 0.01);
}

TEST(DataLimits, ResetToTheTruthAtFramesLeavesOnlyTheDriftBetweenThem) {
  RunInput in = over_turning_robot();
  const double sparse = data_limits(in).blind_drift.ate_rmse_m;
  // Pure dead reckoning is metres off after 60 s; with a reset every second
  // only the drift of one second remains (and the 20 s before the first frame).
  EXPECT_LT(sparse, 0.5);
  EXPECT_GT(sparse, 0.01);
  for (int k = 0; k < 200; k += 10) in.frames.push_back({0.1 * k, {slam::RangeBearing{}}});
  std::sort(in.frames.begin(), in.frames.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  EXPECT_LT(data_limits(in).blind_drift.ate_rmse_m, 0.5 * sparse);
  in.odometry.assign(in.odometry.size(), {0.0, 0.2, 0.1});
  for (std::size_t i = 0; i < in.odometry.size(); ++i) in.odometry[i].t_s = 0.1 * static_cast<double>(i);
  EXPECT_LT(data_limits(in).blind_drift.ate_rmse_m, 1e-6);  // exact odometry: no drift at all
}

TEST(DataLimits, NeedsTruthAndFrames) {
  RunInput in = over_turning_robot();
  in.frames.clear();
  EXPECT_THROW(data_limits(in), std::invalid_argument);
  in = over_turning_robot();
  in.truth.clear();
  EXPECT_THROW(data_limits(in), std::invalid_argument);
}

}  // namespace
}  // namespace pixyslam::offline
