#pragma once

#include <cstdint>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/eval/trajectory_metrics.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::sim {

// A paper-like test world: a robot drives laps of a rounded rectangle among
// coloured poles placed outside it, so that loop closure happens every lap.
// Noise as in the seed paper: odometry samples carry v, w errors, camera frames
// range and bearing errors; the camera sees poles inside its horizontal field of
// view and range limits (no occlusion). Units SI, frame as slam::Pose2.
// One leg of a scripted path: `length_m` driven at speed_mps along an arc that
// turns the heading by `turn_rad` (0: straight; > 0 counter-clockwise).
struct PathLeg {
  double length_m = 0.0;
  double turn_rad = 0.0;
};

struct Pole {
  int id = 0;
  double x_m = 0.0;
  double y_m = 0.0;
};

struct WorldOptions {
  std::uint64_t seed = 7;
  double duration_s = 150.0;
  // Path: straight sides of length_m x width_m joined by quarter circles.
  double length_m = 4.0;
  double width_m = 2.5;
  double corner_radius_m = 0.5;
  double speed_mps = 0.2;
  // Poles: this many per side, `pole_offset_m` outside the path, and as many
  // inside it when inner_poles is set.
  int poles_per_long_side = 3;
  int poles_per_short_side = 2;
  double pole_offset_m = 0.6;
  bool inner_poles = true;
  int first_landmark_id = 1;
  // A scripted world instead (e.g. the seed paper's corner and corridor): when
  // `path` is set the robot drives its legs once from initial_pose, then stands
  // still; when `poles` is set they replace the generated ones.
  std::vector<PathLeg> path;
  std::vector<Pole> poles;
  slam::Pose2 initial_pose = slam::Pose2::Zero();
  // Chance that the camera reports a pole in view (the paper lost some to the
  // carpet's colours); 1: always.
  double detection_probability = 1.0;
  // Sensors.
  double odometry_rate_hz = 10.0;
  double camera_rate_hz = 5.0;
  double v_sigma_mps = 0.03;           // paper: 3 cm forward
  double w_sigma_radps = 0.0349;       // paper: 2 deg turn
  double range_sigma_m = 0.07;         // paper: 70 mm
  double bearing_sigma_rad = 0.027;    // paper: 0.027 rad
  // Real sensors' errors are neither zero-mean nor white: a constant range
  // bias, and per pole range and bearing errors that decay with this time
  // constant (first-order Gauss-Markov, same sigmas; 0: white).
  double range_bias_m = 0.0;
  double error_correlation_s = 0.0;
  // Odometry stamped this long before the motion it reports (MRCLAM's command
  // lag: a command is logged when sent, executed later).
  double odometry_lead_s = 0.0;
  double field_of_view_rad = 1.309;    // Pixy: 75 deg horizontal
  double min_range_m = 0.2;
  double max_range_m = 3.0;
};

// The scalar keys of `world:` (path, poles and initial_pose are lists and a
// mapping, read by read_world_options).
const parameters::Table<WorldOptions>& world_parameters();
// Of those, the ones that lay out the world (the path and the poles), without
// the sensors, seed and duration of simulate(): what robot_sim, which emulates
// the sensors itself (its hardware: keys), takes.
const parameters::Table<WorldOptions>& world_layout_parameters();
// Ranges and rules (max_range_m > min_range_m); std::invalid_argument naming the key.
void validate(const WorldOptions& options);

// Reads a `world:` mapping with the keys of `table`; unknown keys and bad
// values throw config::ConfigError.
WorldOptions read_world_options(config::YamlReader& world,
                                const parameters::Table<WorldOptions>& table = world_parameters());

struct WorldRun {
  slam::Pose2 initial_pose = slam::Pose2::Zero();
  std::vector<Pole> poles;
  std::vector<slam::OdometrySample> odometry;   // noisy, at odometry_rate_hz
  std::vector<slam::ObservationFrame> frames;   // noisy, at camera_rate_hz, frames with >= 1 pole
  std::vector<eval::TimedPose> truth;           // true pose at every odometry sample
  std::size_t pole_sightings = 0;
  // Per pole (same order as poles): camera frames in which it was in view, and
  // in which it was reported.
  std::vector<int> frames_in_view;
  std::vector<int> frames_detected;
};

// The true (v, w) command of the path at time t (piecewise constant).
struct PathCommand {
  double v_mps = 0.0;
  double w_radps = 0.0;
};

// The rounded-rectangle loop, or the scripted path (driven once) when o.path is set.
class LoopPath {
 public:
  explicit LoopPath(const WorldOptions& o);
  PathCommand command_at(double t_s) const;
  double lap_time_s() const { return lap_time_s_; }

 private:
  std::vector<std::pair<double, PathCommand>> segments_;  // (end time in lap, command)
  double lap_time_s_ = 0.0;
  bool loops_ = true;
};

std::vector<Pole> place_poles(const WorldOptions& o);

// Simulates the whole run deterministically from o.seed.
WorldRun simulate(const WorldOptions& o);

}  // namespace pixyslam::sim
