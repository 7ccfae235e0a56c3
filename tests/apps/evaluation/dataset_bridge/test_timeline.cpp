// The dataset bridge's pure core: one robot's streams from MRCLAM rows, the
// merged time line of several robots, and the pacing.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "pixyslam/dataset_bridge/timeline.h"

namespace pixyslam::dataset_bridge {
namespace {

mrclam::RobotData robot_data(int robot, double t0) {
  mrclam::RobotData d;
  d.robot = robot;
  d.groundtruth = {{t0 + 1.0, 1.0, 2.0, 0.5}, {t0 + 2.0, 1.1, 2.0, 0.5}};
  d.odometry = {{t0 + 0.2, 0.1, 0.0}, {t0 + 0.9, 0.2, 0.1}, {t0 + 1.5, 0.3, 0.0}};
  d.frames = {{t0 + 0.5, {{11, 2.0, 0.1}}}, {t0 + 1.5, {{12, 3.0, -0.2}}}};
  d.robot_sightings = {{t0 + 0.7, {{2, 1.0, 0.0}}}, {t0 + 1.7, {{3, 2.0, 0.5}, {4, 4.0, -0.5}}}};
  return d;
}

TEST(RobotStream, SightingsGetTheCamerasRangeCorrectionAndNameTheRobotSeen) {
  offline::MrclamSensorModel model;
  model.range_scale = 0.9;
  model.range_cos_bearing_exponent = 1.0;
  const RobotStream s = make_robot_stream(robot_data(4, 100.0), model);
  EXPECT_EQ(s.robot_id, "robot4");
  EXPECT_EQ(mrclam::robot_id(s.sightings[1].detections[0].landmark_id), "robot3");
  ASSERT_EQ(s.sightings.size(), 2u);
  const slam::RangeBearing& z = s.sightings[1].detections[1];
  EXPECT_EQ(z.landmark_id, 4);
  EXPECT_NEAR(z.range_m, 4.0 / (0.9 * std::cos(-0.5)), 1e-12);
  EXPECT_DOUBLE_EQ(z.bearing_rad, -0.5);
  // The same correction as the landmark frames'.
  EXPECT_NEAR(s.input.frames[0].detections[0].range_m, 2.0 / (0.9 * std::cos(0.1)), 1e-12);
}

TEST(Timeline, MergesRobotsInTimeFromEachStartWithTheHeldControl) {
  const std::vector<RobotStream> robots = {make_robot_stream(robot_data(1, 100.0), {}),
                                           make_robot_stream(robot_data(2, 100.3), {})};
  const std::vector<Event> events = merge_timeline(robots);
  for (std::size_t i = 1; i < events.size(); ++i) EXPECT_LE(events[i - 1].t_s, events[i].t_s) << i;
  // Robot 1 starts at its first ground truth (101.0): the odometry of 100.9 is
  // held and published at the start, the frame at 100.5 and the sighting at 100.7 are not.
  std::vector<Event> r1;
  for (const Event& e : events) {
    if (e.robot == 0) r1.push_back(e);
  }
  ASSERT_EQ(r1.size(), 6u);  // truth 2, odometry 2 (the held control and 101.5), frame 1, sighting 1
  EXPECT_EQ(r1[0].kind, EventKind::kGroundTruth);
  EXPECT_DOUBLE_EQ(r1[0].t_s, 101.0);
  EXPECT_EQ(r1[1].kind, EventKind::kOdometry);
  EXPECT_EQ(r1[1].index, 1u);
  EXPECT_DOUBLE_EQ(r1[1].t_s, 101.0);
  std::size_t sightings = 0;
  for (const Event& e : r1) sightings += e.kind == EventKind::kSighting;
  EXPECT_EQ(sightings, 1u);
  // The held control lasts until the next odometry.
  EXPECT_NEAR(odometry_period(robots[0], 1), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(odometry_period(robots[0], 2), 0.1);
}

TEST(Timeline, EqualTimesGoTruthOdometryFramesSightingsThenByRobot) {
  mrclam::RobotData a = robot_data(1, 100.0), b = robot_data(2, 100.0);
  a.robot_sightings = {{101.5, {{2, 1.0, 0.0}}}};
  const std::vector<RobotStream> robots = {make_robot_stream(a, {}), make_robot_stream(b, {})};
  std::vector<Event> at;
  for (const Event& e : merge_timeline(robots)) {
    if (e.t_s == 101.5) at.push_back(e);
  }
  ASSERT_EQ(at.size(), 5u);  // odometry and frame of both robots, robot 1's sighting
  EXPECT_EQ(at[0].kind, EventKind::kOdometry);
  EXPECT_EQ(at[0].robot, 0u);
  EXPECT_EQ(at[1].kind, EventKind::kOdometry);
  EXPECT_EQ(at[1].robot, 1u);
  EXPECT_EQ(at[2].kind, EventKind::kFrame);
  EXPECT_EQ(at[3].kind, EventKind::kFrame);
  EXPECT_EQ(at[4].kind, EventKind::kSighting);
}

TEST(RobotStream, KeepsTheFirstSecondsFromItsStart) {
  RobotStream s = make_robot_stream(robot_data(1, 100.0), {});
  RobotStream all = s;
  keep_first_seconds(all, 0.0);  // <= 0: everything
  EXPECT_EQ(all.input.odometry.size(), 3u);
  keep_first_seconds(s, 0.6);  // start 101.0: up to 101.6
  ASSERT_EQ(s.input.truth.size(), 1u);
  ASSERT_EQ(s.input.odometry.size(), 3u);  // 100.2 and 100.9 (before the start: the held control) and 101.5
  ASSERT_EQ(s.input.frames.size(), 2u);    // 100.5 (skipped later, before the start) and 101.5
  EXPECT_TRUE(s.sightings.size() == 1u && s.sightings[0].t_s == 100.7);
  // The offline runner's cut is the same one.
  offline::RunInput in = offline::mrclam_input(robot_data(1, 100.0), {});
  offline::keep_first_seconds(in, 0.6);
  EXPECT_EQ(in.odometry.size(), s.input.odometry.size());
  EXPECT_EQ(in.frames.size(), s.input.frames.size());
}

TEST(Pacer, SpreadsTheRecordingOverWallTimeAtTheRate) {
  const auto start = Pacer::Clock::now();
  const Pacer ten(10.0, 100.0, start);
  EXPECT_TRUE(ten.paced());
  EXPECT_EQ(ten.due(100.0), start);
  EXPECT_EQ(std::chrono::duration_cast<std::chrono::milliseconds>(ten.due(105.0) - start).count(), 500);
  EXPECT_EQ(ten.due(99.0), start);  // before the first sample: now
  const Pacer unpaced(0.0, 100.0, start);
  EXPECT_FALSE(unpaced.paced());
  EXPECT_EQ(unpaced.due(1000.0), start);
}

TEST(RobotList, RobotsAreOneToFiveAndNoneTwice) {
  EXPECT_NO_THROW(mrclam::check_robot_list({1, 5, 3}, "robots"));
  EXPECT_THROW(mrclam::check_robot_list({0}, "robots"), std::invalid_argument);
  EXPECT_THROW(mrclam::check_robot_list({6}, "robots"), std::invalid_argument);
  try {
    mrclam::check_robot_list({2, 3, 2}, "--robots");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "--robots: robot 2 given twice");
  }
}

}  // namespace
}  // namespace pixyslam::dataset_bridge
