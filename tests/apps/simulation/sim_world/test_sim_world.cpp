// The simulated world's scripted paths, given poles and detection misses (the
// seed paper's experiments, config/paper/).
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/observation_model.h"

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

TEST(SimWorld, OptionsTableReadsKeysAndOverridesWithOneSetOfRanges) {
  // A key read through the table and the same key set as an override agree.
  const WorldOptions from_yaml = read("world:\n  speed_mps: 0.35\n  inner_poles: false\n  seed: 42\n");
  WorldOptions overridden;
  parameters::apply_override(overridden, world_parameters(), "world", "world.speed_mps=0.35");
  parameters::apply_override(overridden, world_parameters(), "world", "world.inner_poles=false");
  parameters::apply_override(overridden, world_parameters(), "world", "world.seed=42");
  EXPECT_EQ(from_yaml.speed_mps, overridden.speed_mps);
  EXPECT_EQ(from_yaml.inner_poles, overridden.inner_poles);
  EXPECT_EQ(from_yaml.seed, overridden.seed);
  // The range is the table's in both ways in.
  EXPECT_THROW(read("world:\n  speed_mps: 6\n"), config::ConfigError);
  EXPECT_THROW(parameters::apply_override(overridden, world_parameters(), "world", "world.speed_mps=6"),
               std::invalid_argument);
  // The rule between two keys names the key.
  try {
    read("world:\n  min_range_m: 2\n  max_range_m: 1\n");
    ADD_FAILURE();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_range_m"), std::string::npos) << e.what();
  }
  overridden.max_range_m = overridden.min_range_m;
  EXPECT_THROW(validate(overridden), parameters::RuleError);
}

// The range and bearing errors of every sighting, against the true geometry at its frame.
struct SightingError {
  int pole;
  double t_s, range_m, bearing_rad;
};
std::vector<SightingError> sighting_errors(const WorldRun& run, double odometry_dt) {
  std::vector<SightingError> errors;
  for (const slam::ObservationFrame& f : run.frames) {
    // Truth is sampled with the odometry: the frame's pose moved on from the sample before it.
    const auto k = static_cast<std::size_t>(std::floor(f.t_s / odometry_dt + 1e-9));
    const eval::TimedPose& g = run.truth.at(k);
    const slam::Pose2 pose(g.x_m, g.y_m, g.theta_rad);
    for (const slam::RangeBearing& d : f.detections) {
      const Pole& p = run.poles.at(static_cast<std::size_t>(d.landmark_id - run.poles.front().id));
      const slam::PredictedObservation z = slam::predict_observation(pose, Eigen::Vector2d(p.x_m, p.y_m));
      errors.push_back({d.landmark_id, f.t_s, d.range_m - z.z.x(), slam::wrap_angle(d.bearing_rad - z.z.y())});
    }
  }
  return errors;
}

// Lag-one correlation of each pole's successive errors (range, bearing).
std::pair<double, double> successive_correlation(const std::vector<SightingError>& errors, double range_bias) {
  std::map<int, const SightingError*> last;
  double rr = 0, r0 = 0, r1 = 0, bb = 0, b0 = 0, b1 = 0;
  for (const SightingError& e : errors) {
    const auto it = last.find(e.pole);
    if (it != last.end()) {
      const double ra = it->second->range_m - range_bias, rb = e.range_m - range_bias;
      rr += ra * rb, r0 += ra * ra, r1 += rb * rb;
      bb += it->second->bearing_rad * e.bearing_rad, b0 += it->second->bearing_rad * it->second->bearing_rad,
          b1 += e.bearing_rad * e.bearing_rad;
    }
    last[e.pole] = &e;
  }
  return {rr / std::sqrt(r0 * r1), bb / std::sqrt(b0 * b1)};
}

TEST(SimWorld, RangeBiasAndCorrelatedErrorsKeepTheirSigmas) {
  // Odometry and camera at 20 Hz (one truth sample per frame), no motion noise.
  WorldOptions o;
  o.duration_s = 300.0;
  o.odometry_rate_hz = 20.0;
  o.camera_rate_hz = 20.0;
  o.v_sigma_mps = o.w_sigma_radps = 0.0;
  const WorldRun white = simulate(o);
  o.range_bias_m = 0.05;
  o.error_correlation_s = 0.5;
  const WorldRun correlated = simulate(o);
  // Same random sequence: same sightings.
  ASSERT_EQ(white.pole_sightings, correlated.pole_sightings);
  ASSERT_GT(white.pole_sightings, 5000u);

  const auto moments = [](const std::vector<SightingError>& errors) {
    double mean = 0, range_var = 0, bearing_var = 0;
    for (const SightingError& e : errors) mean += e.range_m;
    mean /= static_cast<double>(errors.size());
    for (const SightingError& e : errors) {
      range_var += (e.range_m - mean) * (e.range_m - mean);
      bearing_var += e.bearing_rad * e.bearing_rad;
    }
    const double n = static_cast<double>(errors.size());
    return std::array<double, 3>{mean, std::sqrt(range_var / n), std::sqrt(bearing_var / n)};
  };
  const std::vector<SightingError> white_errors = sighting_errors(white, 0.05);
  const std::vector<SightingError> correlated_errors = sighting_errors(correlated, 0.05);
  const auto w = moments(white_errors), c = moments(correlated_errors);
  EXPECT_NEAR(w[0], 0.0, 0.005);
  EXPECT_NEAR(c[0], 0.05, 0.02);  // fewer independent draws: a looser mean
  EXPECT_NEAR(w[1], o.range_sigma_m, 0.1 * o.range_sigma_m);
  EXPECT_NEAR(c[1], o.range_sigma_m, 0.25 * o.range_sigma_m);
  EXPECT_NEAR(w[2], o.bearing_sigma_rad, 0.1 * o.bearing_sigma_rad);
  EXPECT_NEAR(c[2], o.bearing_sigma_rad, 0.25 * o.bearing_sigma_rad);
  // Successive sightings of a pole 0.05 s apart (mostly): exp(-0.05 / 0.5) = 0.90.
  const auto [white_range_rho, white_bearing_rho] = successive_correlation(white_errors, 0.0);
  const auto [range_rho, bearing_rho] = successive_correlation(correlated_errors, c[0]);
  EXPECT_NEAR(white_range_rho, 0.0, 0.05);
  EXPECT_NEAR(white_bearing_rho, 0.0, 0.05);
  EXPECT_GT(range_rho, 0.8);
  EXPECT_GT(bearing_rho, 0.8);
}

TEST(SimWorld, OdometryLeadStampsEachSampleEarlier) {
  WorldOptions o;
  o.duration_s = 10.0;
  const WorldRun base = simulate(o);
  o.odometry_lead_s = 0.2;
  const WorldRun lead = simulate(o);
  ASSERT_EQ(base.odometry.size(), lead.odometry.size());
  for (std::size_t i = 0; i < base.odometry.size(); ++i) {
    EXPECT_NEAR(lead.odometry[i].t_s, base.odometry[i].t_s - 0.2, 1e-12);
    EXPECT_EQ(lead.odometry[i].v_mps, base.odometry[i].v_mps);
    EXPECT_EQ(lead.odometry[i].w_radps, base.odometry[i].w_radps);
  }
  EXPECT_EQ(lead.truth.back().t_s, base.truth.back().t_s);
}

}  // namespace
}  // namespace pixyslam::sim
