// The simulated world's scripted paths, given poles and detection misses (the
// seed paper's experiments, config/paper/).
#include <cmath>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/sim/sim_world.h"

namespace pixyslam::sim {
namespace {

WorldOptions read(const std::string& text) {
  config::YamlReader root = config::YamlReader::from_string(text, "world.yaml");
  config::YamlReader w = root.child("world");
  return read_world_options(w);
}

TEST(SimWorld, ScriptedPathIsDrivenOnceThenTheRobotStandsStill) {
  const WorldOptions o = read(
      "world:\n  duration_s: 30\n  speed_mps: 0.1\n  initial_pose: {x_m: 1, y_m: 2, theta_deg: 90}\n"
      "  path:\n    - {length_m: 0.5}\n    - {length_m: 0.7854, turn_deg: 180}\n"
      "  poles:\n    - {id: 7, x_m: 1.5, y_m: 3}\n  v_sigma_mps: 0\n  w_sigma_radps: 0\n  range_sigma_m: 0\n"
      "  bearing_sigma_rad: 0\n");
  const LoopPath path(o);
  EXPECT_NEAR(path.lap_time_s(), 12.854, 1e-3);
  EXPECT_DOUBLE_EQ(path.command_at(20.0).v_mps, 0.0);
  EXPECT_NEAR(path.command_at(10.0).w_radps, M_PI / 7.854, 1e-6);
  const WorldRun run = simulate(o);
  ASSERT_EQ(run.poles.size(), 1u);
  EXPECT_EQ(run.poles[0].id, 7);
  // 0.5 m north, then a half circle of radius 0.25 m to the left: (0.5, 2.5) heading south.
  const eval::TimedPose& end = run.truth.back();
  EXPECT_NEAR(end.x_m, 0.5, 0.01);
  EXPECT_NEAR(end.y_m, 2.5, 0.01);
  EXPECT_NEAR(std::abs(end.theta_rad), M_PI / 2, 0.01);
  EXPECT_NEAR(run.initial_pose.y(), 2.0, 1e-12);
}

TEST(SimWorld, DetectionProbabilityDropsThatShareOfSightings) {
  WorldOptions o;
  o.duration_s = 100.0;
  o.detection_probability = 0.7;
  const WorldRun run = simulate(o);
  long in_view = 0, detected = 0;
  for (std::size_t i = 0; i < run.poles.size(); ++i) {
    in_view += run.frames_in_view[i];
    detected += run.frames_detected[i];
  }
  ASSERT_GT(in_view, 1000);
  EXPECT_EQ(static_cast<std::size_t>(detected), run.pole_sightings);
  EXPECT_NEAR(static_cast<double>(detected) / in_view, 0.7, 0.03);
  o.detection_probability = 1.0;
  const WorldRun all = simulate(o);
  long all_in_view = 0;
  for (int n : all.frames_in_view) all_in_view += n;
  EXPECT_EQ(static_cast<std::size_t>(all_in_view), all.pole_sightings);
}

TEST(SimWorld, BadScriptedWorldsNameTheKey) {
  EXPECT_THROW(read("world:\n  path:\n    - {length_m: 0}\n"), config::ConfigError);
  try {
    read("world:\n  poles:\n    - {id: 1, x_m: 0, y_m: 0}\n    - {id: 1, x_m: 1, y_m: 0}\n");
    ADD_FAILURE();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("poles[1].id"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read("world:\n  detection_probability: 1.5\n"), config::ConfigError);
}

}  // namespace
}  // namespace pixyslam::sim
