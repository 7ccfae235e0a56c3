// The map_optimizer process's node beside the estimator's, both fed over DDS
// (loopback profile) with the simulated world by writers in this test: the
// OptimisedMap arrives, its landmarks are at most as far from the truth as the
// filter's, keyframes start from the filter's poses, and bytes that do not
// decode are counted and dropped.
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/eval/trajectory_metrics.h"
#include "pixyslam/map_optimizer_node/optimizer_node.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam_node/estimator_node.h"
#include "pixyslam/slam_node/map_state_conversions.h"
#include "temp_dir.h"
#include "raw_sample_writer.h"
#include "sensor_writers.h"
#include "sim_sensor_messages.h"

namespace pixyslam::map_optimizer_node {
namespace {

const std::string kConfigDir = PIXYSLAM_CONFIG_DIR;

OptimizerNodeOptions test_options() {
  OptimizerNodeOptions o = read_optimizer_node_options_file(kConfigDir + "/map_optimizer.yaml");
  o.status_period_s = 0.0;
  o.dds.robot_id = "test_robot";
  return o;
}

// Waits up to 20 s for the node's malformed-sample count to reach `target`.
bool wait_for_malformed(const OptimizerNode& node, std::uint64_t target) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (node.counters().malformed < target && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return node.counters().malformed >= target;
}

// 60 s of the simulated world, a camera frame every 0.1 s seeing poles within 4 m.
sim::WorldRun simulated_minute() {
  sim::WorldOptions world;
  world.duration_s = 60.0;
  world.camera_rate_hz = 10.0;
  world.max_range_m = 4.0;
  return sim::simulate(world);
}

// The simulated run in stamp order, paced (an estimator answers every message
// with a MapState), until every sample is acknowledged.
void feed(const sim::WorldRun& run, std::uint64_t base_ns, dds::Writer<msg::Odometry>& odometry_writer,
          dds::Writer<msg::LandmarkObservation>& observation_writer) {
  std::size_t o = 0, f = 0;
  const double period = run.odometry[1].t_s - run.odometry[0].t_s;
  while (o < run.odometry.size() || f < run.frames.size()) {
    if (f == run.frames.size() || (o < run.odometry.size() && run.odometry[o].t_s + period <= run.frames[f].t_s)) {
      const slam::OdometrySample& s = run.odometry[o++];
      msg::Odometry m = test_support::odometry_msg(s, period, slam_node::to_stamp_ns(s.t_s, base_ns));
      ASSERT_TRUE(odometry_writer.publish(m));
    } else {
      const slam::ObservationFrame& frame = run.frames[f++];
      msg::LandmarkObservation m =
          test_support::observation_msg(frame, slam_node::to_stamp_ns(frame.t_s, base_ns));
      ASSERT_TRUE(observation_writer.publish(m));
    }
    std::this_thread::sleep_for(std::chrono::microseconds(1500));
  }
  ASSERT_TRUE(odometry_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
  ASSERT_TRUE(observation_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
}

// Signed seconds from base to stamp (a stamp a few ns before base is not 2^64 ns after it).
double seconds_after(std::uint64_t base_ns, std::uint64_t stamp_ns) {
  return static_cast<double>(static_cast<std::int64_t>(stamp_ns - base_ns)) * 1e-9;
}

// What map_optimizer --out-dir writes, as seconds after base.
void collect_keyframes(OptimizerNode& node, std::uint64_t base_ns, std::vector<eval::TimedPose>& out) {
  node.set_keyframe_sink([&out, base_ns](std::uint64_t stamp_ns, const slam::Pose2& pose) {
    out.push_back({seconds_after(base_ns, stamp_ns), pose.x(), pose.y(), pose.z()});
  });
}

using test_support::SensorWriters;

TEST(OptimizerNode, OptimisesBesideTheEstimatorFromDdsInput) {
  const sim::WorldRun run = simulated_minute();
  const std::uint64_t base_ns = dds::now_ns();

  slam_node::EstimatorOptions estimator_options =
      slam_node::read_estimator_options_file(kConfigDir + "/slam_estimator.yaml");
  estimator_options.status_period_s = 0.0;
  estimator_options.initial_pose = run.initial_pose;
  estimator_options.dds.robot_id = "test_robot";  // the sensors' robot: an estimator reads only its own
  slam_node::EstimatorNode estimator(estimator_options);
  estimator.start();
  OptimizerNodeOptions options = test_options();
  options.initial_pose = run.initial_pose;
  OptimizerNode node(options);
  node.start();

  dds::Participant sensors(options.dds, "test_sensors");
  dds::Writer<msg::Odometry> odometry_writer(sensors);
  dds::Writer<msg::LandmarkObservation> observation_writer(sensors);
  std::mutex mutex;
  std::vector<msg::OptimisedMap> maps;
  dds::Reader<msg::OptimisedMap> map_reader(sensors, [&](const msg::OptimisedMap& m) {
    std::lock_guard<std::mutex> lock(mutex);
    maps.push_back(m);
  });
  ASSERT_TRUE(odometry_writer.wait_for_readers(2, std::chrono::seconds(10)));
  ASSERT_TRUE(observation_writer.wait_for_readers(2, std::chrono::seconds(10)));

  feed(run, base_ns, odometry_writer, observation_writer);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  estimator.stop();
  node.stop();

  const OptimizerNodeCounters c = node.counters();
  EXPECT_EQ(c.odometry_received, run.odometry.size());
  EXPECT_EQ(c.observations_received, run.frames.size());
  EXPECT_GT(c.map_states_received, 0u);
  EXPECT_GT(c.guesses_from_filter, 0u);  // keyframes started at the filter's pose
  EXPECT_GE(c.whole_solves, 6u);         // every 10 s of data and at the end
  EXPECT_GT(c.window_solves, 30u);
  EXPECT_GT(c.cpu_time_s, 0.0);
  EXPECT_EQ(c.malformed, 0u);

  // The final solution: every landmark seen, at most as far from the truth as the filter's.
  const msg::OptimisedMap last = node.latest_map();
  EXPECT_TRUE(last.whole_problem());
  EXPECT_EQ(last.odometry_sequence(), run.odometry.size());
  EXPECT_EQ(last.observation_sequence(), run.frames.size());
  EXPECT_GT(last.keyframe_count(), 60u);
  EXPECT_EQ(last.keyframes().size(), last.keyframe_count());
  std::set<int> seen;
  for (const slam::ObservationFrame& frame : run.frames) {
    for (const slam::RangeBearing& rb : frame.detections) seen.insert(rb.landmark_id);
  }
  ASSERT_EQ(last.landmarks().size(), seen.size());
  std::vector<eval::LandmarkPoint> truth, optimised, filtered;
  for (const sim::Pole& p : run.poles) truth.push_back({p.id, p.x_m, p.y_m});
  for (const msg::OptimisedLandmark& l : last.landmarks()) {
    optimised.push_back({l.landmark_id(), l.x_m(), l.y_m()});
    EXPECT_TRUE(std::isfinite(l.cov_xx_m2()) && l.cov_xx_m2() > 0.0) << l.landmark_id();
    EXPECT_GT(l.observations(), 0u);
  }
  for (const msg::LandmarkEstimate& l : estimator.latest_map_state().landmarks()) {
    filtered.push_back({l.landmark_id(), l.x_m(), l.y_m()});
  }
  const eval::LandmarkErrors opt = eval::compare_landmarks(optimised, truth);
  const eval::LandmarkErrors fil = eval::compare_landmarks(filtered, truth);
  std::printf("landmark RMSE: filter %.3f m, map optimiser %.3f m (%zu matched)\n", fil.rmse_m, opt.rmse_m,
              opt.matched);
  EXPECT_EQ(opt.matched, seen.size());
  EXPECT_LE(opt.rmse_m, fil.rmse_m);
  std::vector<eval::TimedPose> keyframes;
  for (const msg::OptimisedKeyframe& k : last.keyframes()) {
    keyframes.push_back({static_cast<double>(k.stamp_ns() - base_ns) * 1e-9, k.pose().x_m(), k.pose().y_m(),
                         k.pose().theta_rad()});
  }
  EXPECT_LT(eval::compare_trajectory(keyframes, run.truth).ate_rmse_m, 0.15);

  // What went out on the topic: one map per solve, in order, none lost.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_FALSE(maps.empty());
  EXPECT_EQ(maps.back().header().seq(), c.maps_published);
  EXPECT_EQ(c.maps_published, c.whole_solves + c.window_solves);
  EXPECT_EQ(map_reader.lost(), 0u);
}

// A station that runs for days: at optimizer.max_keyframes the problem starts
// anew from the current pose with the landmarks as priors; it stays bounded,
// the map keeps every landmark near the truth, and the pose goes on.
TEST(OptimizerNode, AProblemAtItsKeyframeLimitStartsAnewWithItsLandmarksAsPriors) {
  const sim::WorldRun run = simulated_minute();
  const std::uint64_t base_ns = dds::now_ns();
  OptimizerNodeOptions options = test_options();
  options.initial_pose = run.initial_pose;
  options.max_keyframes = 150;  // 10 Hz frames: a new problem every ~15 s
  OptimizerNode node(options);
  std::vector<eval::TimedPose> emitted;  // what map_optimizer --out-dir writes
  collect_keyframes(node, base_ns, emitted);
  node.start();
  SensorWriters sensors(options.dds);
  ASSERT_TRUE(sensors.matched());
  feed(run, base_ns, sensors.odometry, sensors.observations);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  node.stop();

  const OptimizerNodeCounters c = node.counters();
  EXPECT_EQ(c.odometry_received, run.odometry.size());
  EXPECT_GE(c.segments, 3u);
  const msg::OptimisedMap last = node.latest_map();
  EXPECT_LE(last.keyframe_count(), options.max_keyframes);
  std::set<int> seen;
  for (const slam::ObservationFrame& frame : run.frames) {
    for (const slam::RangeBearing& rb : frame.detections) seen.insert(rb.landmark_id);
  }
  EXPECT_EQ(last.landmarks().size(), seen.size());  // the earlier problems' landmarks carried on
  std::vector<eval::LandmarkPoint> truth, optimised;
  for (const sim::Pole& p : run.poles) truth.push_back({p.id, p.x_m, p.y_m});
  for (const msg::OptimisedLandmark& l : last.landmarks()) optimised.push_back({l.landmark_id(), l.x_m(), l.y_m()});
  const eval::LandmarkErrors errors = eval::compare_landmarks(optimised, truth);
  std::printf("landmark RMSE after %llu new problems: %.3f m\n", static_cast<unsigned long long>(c.segments),
              errors.rmse_m);
  EXPECT_LT(errors.rmse_m, 0.15);
  std::vector<eval::TimedPose> keyframes;
  for (const msg::OptimisedKeyframe& k : last.keyframes()) {
    keyframes.push_back({static_cast<double>(k.stamp_ns() - base_ns) * 1e-9, k.pose().x_m(), k.pose().y_m(),
                         k.pose().theta_rad()});
  }
  EXPECT_LT(eval::compare_trajectory(keyframes, run.truth).ate_rmse_m, 0.15);

  // The sink got every problem's keyframes, once, in time order: the whole run.
  ASSERT_FALSE(emitted.empty());
  EXPECT_GE(emitted.size(), c.segments * (options.max_keyframes - 1) + last.keyframe_count() - 1);
  for (std::size_t i = 1; i < emitted.size(); ++i) ASSERT_LT(emitted[i - 1].t_s, emitted[i].t_s) << i;
  EXPECT_LT(emitted.front().t_s, run.odometry.front().t_s + 1.0);
  EXPECT_NEAR(emitted.back().t_s, keyframes.back().t_s, 1e-6);
  EXPECT_LT(eval::compare_trajectory(emitted, run.truth).ate_rmse_m, 0.15);
}

// A consistent pair of odometry samples a year ahead moves the time; the run's
// own samples after it would all be dropped as late. Once only they came for a
// second, the time goes back: a new problem from the newest keyframe before
// the jump, and the written trajectory keeps to the run's time, in order.
TEST(OptimizerNode, AfterAHostilePairOfFutureStampsTheOptimiserGoesOnAtTheRunsTime) {
  const sim::WorldRun run = simulated_minute();
  const std::uint64_t base_ns = dds::now_ns();
  OptimizerNodeOptions options = test_options();
  options.initial_pose = run.initial_pose;
  OptimizerNode node(options);
  std::vector<eval::TimedPose> emitted;
  collect_keyframes(node, base_ns, emitted);
  node.start();
  SensorWriters sensors(options.dds);
  ASSERT_TRUE(sensors.matched());
  const std::uint64_t year_ns = 365ull * 86400ull * 1000000000ull;
  for (int i = 0; i < 2; ++i) {
    msg::Odometry m = test_support::odometry_msg(run.odometry[0], 0.1, base_ns + year_ns + 100'000'000ull * i);
    ASSERT_TRUE(sensors.odometry.publish(m));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  feed(run, base_ns, sensors.odometry, sensors.observations);  // ~1.8 s of arrivals
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  node.stop();

  const msg::OptimisedMap last = node.latest_map();
  const double end_s = run.odometry.back().t_s + 1.0;
  EXPECT_LT(seconds_after(base_ns, last.header().stamp_ns()), end_s);  // not a year on
  ASSERT_FALSE(last.keyframes().empty());
  EXPECT_LT(seconds_after(base_ns, last.keyframes().back().stamp_ns()), end_s);
  EXPECT_GT(last.landmarks().size(), 0u);
  ASSERT_FALSE(emitted.empty());
  for (std::size_t i = 1; i < emitted.size(); ++i) ASSERT_LT(emitted[i - 1].t_s, emitted[i].t_s) << i;
  EXPECT_LT(emitted.back().t_s, end_s);
  EXPECT_GT(emitted.back().t_s, run.odometry.back().t_s - 2.0);  // the new problem's keyframes were written
}

// Any participant can send any bytes: what does not decode is counted and dropped.
TEST(OptimizerNode, MalformedSamplesAreCountedAndTheOptimiserGoesOn) {
  OptimizerNodeOptions options = test_options();
  options.initial_pose = slam::Pose2::Zero();
  OptimizerNode node(options);
  node.start();
  dds::Participant hostile(options.dds, "test_hostile");
  test_support::RawSampleWriter<msg::Odometry> bad_odometry(hostile);
  test_support::RawSampleWriter<msg::MapState> bad_maps(hostile);
  dds::Participant sensors(options.dds, "test_sensors");
  dds::Writer<msg::Odometry> odometry_writer(sensors);
  ASSERT_TRUE(bad_odometry.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(bad_maps.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(odometry_writer.wait_for_readers(1, std::chrono::seconds(10)));

  const std::uint64_t base_ns = dds::now_ns();
  slam::OdometrySample good;
  good.v_mps = 0.1;
  const auto bad_o = test_support::malformed_payloads(
      test_support::wire_bytes(test_support::odometry_msg(good, 0.1, base_ns)),
      test_support::max_payload_size<msg::Odometry>());
  const auto bad_m = test_support::malformed_payloads(test_support::wire_bytes(msg::MapState()),
                                                      test_support::max_payload_size<msg::MapState>());
  for (const auto& b : bad_o) ASSERT_TRUE(bad_odometry.write(b));
  for (const auto& b : bad_m) ASSERT_TRUE(bad_maps.write(b));
  for (int i = 0; i < 30; ++i) {
    good.t_s = 0.1 * i;
    msg::Odometry m = test_support::odometry_msg(good, 0.1, slam_node::to_stamp_ns(good.t_s, base_ns));
    ASSERT_TRUE(odometry_writer.publish(m));
  }
  ASSERT_TRUE(odometry_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
  EXPECT_TRUE(wait_for_malformed(node, bad_o.size() + bad_m.size()));
  node.stop();
  const OptimizerNodeCounters c = node.counters();
  EXPECT_EQ(c.odometry_received, 30u);
  EXPECT_EQ(c.malformed, bad_o.size() + bad_m.size());
  // Three seconds of odometry: window solves went on, and the final whole one.
  EXPECT_GE(c.window_solves, 2u);
  EXPECT_EQ(c.whole_solves, 1u);
  const msg::OptimisedMap last = node.latest_map();
  EXPECT_NEAR(last.current_pose().x_m(), 0.29, 0.02);  // 2.9 s at 0.1 m/s from the origin
}

TEST(OptimizerNodeOptions, ShippedConfigTakesTheEstimatorsModels) {
  const OptimizerNodeOptions o = test_options();
  const slam_node::EstimatorOptions e = slam_node::read_estimator_options_file(kConfigDir + "/slam_estimator.yaml");
  EXPECT_EQ(o.optimizer.motion.w_sigma_rad_per_sqrt_s, e.filter.motion.w_sigma_rad_per_sqrt_s);
  EXPECT_EQ(o.optimizer.bearing_sigma_rad, e.filter.bearing_sigma_rad);
  EXPECT_EQ(o.initial_pose, e.initial_pose);
  EXPECT_EQ(o.dds.domain_id, e.dds.domain_id);
  EXPECT_EQ(o.schedule.window_keyframes, 100u);
}

TEST(OptimizerNodeOptions, SetReachesEachOfTheThreeTablesOfTheSection) {
  OptimizerNodeOptions o = test_options();
  apply_overrides(o, {"optimizer.huber_threshold=2.5", "optimizer.window_period_s=3", "optimizer.published_keyframes=64",
                      "dds.domain_id=7"});
  EXPECT_EQ(o.optimizer.huber_threshold, 2.5);  // the core's
  EXPECT_EQ(o.schedule.window_period_s, 3.0);  // the schedule's
  EXPECT_EQ(o.published_keyframes, 64);  // the process's
  EXPECT_EQ(o.dds.domain_id, 7);
  const auto error_of = [&](const std::string& assignment) {
    try {
      apply_overrides(o, {assignment});
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error_of("optimizer.windwo_period_s=3").find("optimizer.windwo_period_s"), std::string::npos);
  EXPECT_NE(error_of("optimizer.window_period_s=-1").find("window_period_s"), std::string::npos);
  EXPECT_NE(error_of("filter.particles=10").find("filter.particles"), std::string::npos);
}

TEST(OptimizerNodeOptions, ErrorsNameTheFileAndKey) {
  const test::TempDir dir;
  const auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir.file("map_optimizer_test.yaml");
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(text.c_str(), f);
    std::fclose(f);
    try {
      read_optimizer_node_options_file(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const std::string estimator = "filter_config: " + kConfigDir + "/slam_estimator.yaml\n";
  expect_error(estimator + "optimizer:\n  window_period_s: -1\n", "window_period_s");
  expect_error(estimator + "optimizer:\n  windwo_keyframes: 5\n", "windwo_keyframes");
  // The missing file, and the file and key that named it.
  expect_error("filter_config: no_such_file.yaml\noptimizer: {}\n",
               dir.file("map_optimizer_test.yaml") + ": filter_config: " + dir.path() + "/no_such_file.yaml");
  expect_error(estimator, "optimizer");  // the section is required
}

}  // namespace
}  // namespace pixyslam::map_optimizer_node
