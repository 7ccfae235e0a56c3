// The estimator process's node, fed over DDS (loopback profile) with the
// simulated world's odometry and camera frames by writers in this test.
#include <chrono>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/eval/trajectory_metrics.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam_node/estimator_node.h"
#include "pixyslam/slam_node/map_state_conversions.h"
#include "sim_sensor_messages.h"

namespace pixyslam::slam_node {
namespace {

EstimatorOptions test_options() {
  EstimatorOptions o = read_estimator_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/slam_estimator.yaml");
  o.status_period_s = 0.0;
  o.dds.robot_id = "test_robot";
  return o;
}

TEST(EstimatorNode, MapsTheSimulatedWorldFromDdsInputInTimeOrder) {
  sim::WorldOptions world;
  world.duration_s = 60.0;
  world.camera_rate_hz = 10.0;
  world.max_range_m = 4.0;
  const sim::WorldRun run = sim::simulate(world);
  // Stamps from now on: the data runs ahead of the wall clock, so the queue
  // orders by the streams' own stamps (the wall-clock timeouts never fire).
  const std::uint64_t base_ns = dds::now_ns();

  EstimatorOptions options = test_options();
  options.initial_pose = run.initial_pose;
  EstimatorNode node(options);
  node.start();

  dds::Participant sensors(options.dds, "test_sensors");
  dds::Writer<msg::Odometry> odometry_writer(sensors);
  dds::Writer<msg::LandmarkObservation> observation_writer(sensors);
  std::mutex mutex;
  std::vector<msg::MapState> states;
  dds::Reader<msg::MapState> map_reader(sensors, [&](const msg::MapState& m) {
    std::lock_guard<std::mutex> lock(mutex);
    states.push_back(m);
  });
  ASSERT_TRUE(odometry_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(observation_writer.wait_for_readers(1, std::chrono::seconds(10)));

  // Interleave the streams by time, frames slightly out of order with odometry
  // (as live: odometry is sent at the end of its period).
  std::size_t o = 0, f = 0;
  const double period = 1.0 / world.odometry_rate_hz;
  while (o < run.odometry.size() || f < run.frames.size()) {
    const bool send_odometry =
        f == run.frames.size() ||
        (o < run.odometry.size() && run.odometry[o].t_s + period <= run.frames[f].t_s);
    if (send_odometry) {
      const slam::OdometrySample& s = run.odometry[o++];
      msg::Odometry m = test_support::odometry_msg(s, period, to_stamp_ns(s.t_s, base_ns));
      ASSERT_TRUE(odometry_writer.publish(m));
    } else {
      const slam::ObservationFrame& frame = run.frames[f++];
      msg::LandmarkObservation m = test_support::observation_msg(frame, to_stamp_ns(frame.t_s, base_ns));
      ASSERT_TRUE(observation_writer.publish(m));
    }
    if ((o + f) % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(odometry_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
  ASSERT_TRUE(observation_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  node.stop();

  const EstimatorCounters c = node.counters();
  EXPECT_EQ(c.odometry_received, run.odometry.size());
  EXPECT_EQ(c.observations_received, run.frames.size());
  EXPECT_EQ(c.odometry_lost + c.observations_lost, 0u);
  EXPECT_EQ(c.steps, run.odometry.size() + run.frames.size());
  EXPECT_EQ(c.samples_late, 0u);

  const msg::MapState last = node.latest_map_state();
  EXPECT_EQ(last.odometry_sequence(), run.odometry.size());
  EXPECT_EQ(last.observation_sequence(), run.frames.size());
  EXPECT_EQ(last.particle_count(), static_cast<std::uint32_t>(options.filter.particles));
  EXPECT_EQ(last.particle_poses().size(), 100u);
  std::set<int> seen;
  for (const slam::ObservationFrame& frame : run.frames) {
    for (const slam::RangeBearing& rb : frame.detections) seen.insert(rb.landmark_id);
  }
  EXPECT_EQ(last.landmarks().size(), seen.size());

  std::vector<eval::TimedPose> estimate;
  for (const auto& [stamp_ns, pose] : node.trajectory()) {
    estimate.push_back({static_cast<double>(stamp_ns - base_ns) * 1e-9, pose.x(), pose.y(), pose.z()});
  }
  const eval::TrajectoryErrors errors = eval::compare_trajectory(estimate, run.truth);
  EXPECT_LT(errors.ate_rmse_m, 0.15);

  // The published stream: every step, in order (the reader history is deep).
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.back().header().seq(), c.map_states_published);
  EXPECT_EQ(map_reader.lost(), 0u);
}

TEST(EstimatorOptions, ShippedConfigIsValid) {
  const EstimatorOptions o = test_options();
  EXPECT_EQ(o.filter.particles, 100);
  EXPECT_NE(o.dds.profiles_file.find("dds/profiles.xml"), std::string::npos);
}

}  // namespace
}  // namespace pixyslam::slam_node
