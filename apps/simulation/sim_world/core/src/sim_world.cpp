#include "pixyslam/sim/sim_world.h"

#include <cmath>
#include <random>
#include <set>
#include <string>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/observation_model.h"

namespace pixyslam::sim {

const parameters::Table<WorldOptions>& world_parameters() {
  using O = WorldOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, std::uint64_t>("seed", 0, P::kMaxSeed, "", "odometry and camera noise; same seed = same run",
                                   [](O& o) -> std::uint64_t& { return o.seed; }),
      P::real<O>("duration_s", 1.0, 1e6, "s", "simulated time", [](O& o) -> double& { return o.duration_s; }),
      P::real<O>("length_m", 0.0, 1000.0, "m", "the loop's long sides", [](O& o) -> double& { return o.length_m; }),
      P::real<O>("width_m", 0.0, 1000.0, "m", "the loop's short sides", [](O& o) -> double& { return o.width_m; }),
      P::real<O>("corner_radius_m", 0.05, 100.0, "m", "quarter circles joining the sides",
                 [](O& o) -> double& { return o.corner_radius_m; }),
      P::real<O>("speed_mps", 0.01, 5.0, "m/s", "driving speed", [](O& o) -> double& { return o.speed_mps; }),
      P::integer<O, int>("poles_per_long_side", 0, 100, "", "poles beside each long side",
                         [](O& o) -> int& { return o.poles_per_long_side; }),
      P::integer<O, int>("poles_per_short_side", 0, 100, "", "poles beside each short side",
                         [](O& o) -> int& { return o.poles_per_short_side; }),
      P::real<O>("pole_offset_m", 0.05, 100.0, "m", "poles' distance from the path",
                 [](O& o) -> double& { return o.pole_offset_m; }),
      P::boolean<O>("inner_poles", "as many poles inside the loop", [](O& o) -> bool& { return o.inner_poles; }),
      P::integer<O, int>("first_landmark_id", 0, 1000000, "", "id of the first generated pole",
                         [](O& o) -> int& { return o.first_landmark_id; }),
      P::real<O>("odometry_rate_hz", 0.1, 1000.0, "Hz", "odometry samples per second",
                 [](O& o) -> double& { return o.odometry_rate_hz; }),
      P::real<O>("camera_rate_hz", 0.1, 100.0, "Hz", "camera frames per second",
                 [](O& o) -> double& { return o.camera_rate_hz; }),
      P::real<O>("v_sigma_mps", 0.0, 10.0, "m/s", "odometry speed noise per sample",
                 [](O& o) -> double& { return o.v_sigma_mps; }),
      P::real<O>("w_sigma_radps", 0.0, 10.0, "rad/s", "odometry turn-rate noise per sample",
                 [](O& o) -> double& { return o.w_sigma_radps; }),
      P::real<O>("range_sigma_m", 0.0, 10.0, "m", "camera range noise", [](O& o) -> double& { return o.range_sigma_m; }),
      P::real<O>("bearing_sigma_rad", 0.0, 1.0, "rad", "camera bearing noise",
                 [](O& o) -> double& { return o.bearing_sigma_rad; }),
      P::real<O>("range_bias_m", -10.0, 10.0, "m", "constant range error", [](O& o) -> double& { return o.range_bias_m; }),
      P::real<O>("error_correlation_s", 0.0, 1e4, "s",
                 "per pole range and bearing errors persist with this time constant (0: white)",
                 [](O& o) -> double& { return o.error_correlation_s; }),
      P::real<O>("odometry_lead_s", 0.0, 10.0, "s", "odometry stamped this long before the motion it reports",
                 [](O& o) -> double& { return o.odometry_lead_s; }),
      P::real<O>("field_of_view_rad", 0.01, 2.0 * M_PI, "rad", "the camera's horizontal field of view",
                 [](O& o) -> double& { return o.field_of_view_rad; }),
      P::real<O>("min_range_m", 0.0, 100.0, "m", "the camera sees poles from here", [](O& o) -> double& { return o.min_range_m; }),
      P::real<O>("max_range_m", 0.01, 1000.0, "m", "... to here", [](O& o) -> double& { return o.max_range_m; }),
      P::real<O>("detection_probability", 0.0, 1.0, "", "chance that a pole in view is reported",
                 [](O& o) -> double& { return o.detection_probability; }),
  };
  return table;
}

const parameters::Table<WorldOptions>& world_layout_parameters() {
  static const parameters::Table<WorldOptions> table = [] {
    const std::set<std::string> layout = {"length_m",      "width_m",           "corner_radius_m",
                                          "speed_mps",     "poles_per_long_side", "poles_per_short_side",
                                          "pole_offset_m", "inner_poles",       "first_landmark_id"};
    parameters::Table<WorldOptions> t;
    for (const auto& p : world_parameters()) {
      if (layout.count(p.path) != 0) t.push_back(p);
    }
    return t;
  }();
  return table;
}

void validate(const WorldOptions& o) {
  parameters::check_ranges(o, world_parameters(), "world");
  if (o.max_range_m <= o.min_range_m) {
    throw parameters::RuleError("world", "max_range_m", "must be greater than min_range_m");
  }
}

WorldOptions read_world_options(config::YamlReader& w, const parameters::Table<WorldOptions>& table) {
  WorldOptions o;
  config::read_parameters(w, table, o);
  config::check_rules(w, [&] { validate(o); });
  if (w.has("path")) {
    for (config::YamlReader& leg : w.mapping_list("path")) {
      PathLeg l;
      l.length_m = leg.number("length_m", 0.001, 1000.0);
      l.turn_rad = leg.number("turn_deg", -3600.0, 3600.0, 0.0) * M_PI / 180.0;
      leg.finish();
      o.path.push_back(l);
    }
  }
  if (w.has("poles")) {
    for (config::YamlReader& p : w.mapping_list("poles")) {
      Pole pole;
      pole.id = static_cast<int>(p.integer("id", 0, 1000000));
      pole.x_m = p.number("x_m", -1000.0, 1000.0);
      pole.y_m = p.number("y_m", -1000.0, 1000.0);
      for (const Pole& other : o.poles) {
        if (other.id == pole.id) p.fail("id", "pole " + std::to_string(pole.id) + " is given twice");
      }
      p.finish();
      o.poles.push_back(pole);
    }
  }
  if (w.has("initial_pose")) {
    config::YamlReader pose = w.child("initial_pose");
    o.initial_pose = slam::Pose2(pose.number("x_m", -1000.0, 1000.0, 0.0), pose.number("y_m", -1000.0, 1000.0, 0.0),
                                 pose.number("theta_deg", -360.0, 360.0, 0.0) * M_PI / 180.0);
    pose.finish();
  }
  w.finish();
  return o;
}

LoopPath::LoopPath(const WorldOptions& o) {
  const double v = o.speed_mps;
  if (!o.path.empty()) {
    loops_ = false;
    double t = 0.0;
    for (const PathLeg& leg : o.path) {
      const double duration = leg.length_m / v;
      t += duration;
      segments_.push_back({t, PathCommand{v, leg.turn_rad / duration}});
    }
    lap_time_s_ = t;
    return;
  }
  const double turn_time = (M_PI / 2.0) * o.corner_radius_m / v;
  const PathCommand straight{v, 0.0};
  const PathCommand turn{v, v / o.corner_radius_m};
  double t = 0.0;
  for (double side : {o.length_m, o.width_m, o.length_m, o.width_m}) {
    t += side / v;
    segments_.push_back({t, straight});
    t += turn_time;
    segments_.push_back({t, turn});
  }
  lap_time_s_ = t;
}

PathCommand LoopPath::command_at(double t_s) const {
  if (!loops_ && t_s >= lap_time_s_) return PathCommand{};  // the scripted path is over: stand still
  const double in_lap = std::fmod(std::max(t_s, 0.0), lap_time_s_);
  for (const auto& [end, cmd] : segments_) {
    if (in_lap < end) return cmd;
  }
  return segments_.back().second;
}

std::vector<Pole> place_poles(const WorldOptions& o) {
  if (!o.poles.empty()) return o.poles;
  // The path starts at (0, 0) heading +x; its rectangle spans x in [0, L] and
  // y in [0, W + 2R] with the corners rounded by R.
  const double l = o.length_m;
  const double h = o.width_m + 2.0 * o.corner_radius_m;
  const double off = o.pole_offset_m;
  std::vector<Pole> poles;
  int id = o.first_landmark_id;
  auto along = [&](int count, double x0, double y0, double x1, double y1) {
    for (int i = 0; i < count; ++i) {
      const double f = (i + 0.5) / count;
      poles.push_back({id++, x0 + f * (x1 - x0), y0 + f * (y1 - y0)});
    }
  };
  // Outer ring (offset outside the path), then the inner ring if enabled.
  for (const double d : {off, o.inner_poles ? -off : 0.0}) {
    if (d == 0.0) continue;
    along(o.poles_per_long_side, 0.0, -d, l, -d);                                              // bottom
    along(o.poles_per_short_side, l + o.corner_radius_m + d, o.corner_radius_m,
          l + o.corner_radius_m + d, h - o.corner_radius_m);                                   // right
    along(o.poles_per_long_side, l, h + d, 0.0, h + d);                                         // top
    along(o.poles_per_short_side, -o.corner_radius_m - d, h - o.corner_radius_m,
          -o.corner_radius_m - d, o.corner_radius_m);                                           // left
  }
  return poles;
}

WorldRun simulate(const WorldOptions& o) {
  WorldRun run;
  run.poles = place_poles(o);
  run.initial_pose = o.initial_pose;
  run.frames_in_view.assign(run.poles.size(), 0);
  run.frames_detected.assign(run.poles.size(), 0);
  const LoopPath path(o);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  const double odo_dt = 1.0 / o.odometry_rate_hz;
  const double cam_dt = 1.0 / o.camera_rate_hz;
  const double sim_dt = std::min(0.01, 0.5 * std::min(odo_dt, cam_dt));
  // Per pole: the current (range, bearing) error in sigmas and when it was drawn.
  struct PoleError {
    double range = 0.0, bearing = 0.0, t_s = -1.0;
  };
  std::vector<PoleError> pole_error(run.poles.size());
  // Two normals per detection whether or not the errors are correlated, so a
  // world keeps its random sequence.
  const auto next_error = [&](PoleError& e, double t_s) {
    const double n_range = normal(rng), n_bearing = normal(rng);
    const double a = (o.error_correlation_s > 0.0 && e.t_s >= 0.0) ? std::exp(-(t_s - e.t_s) / o.error_correlation_s)
                                                                   : 0.0;
    const double b = std::sqrt(1.0 - a * a);
    e = PoleError{a * e.range + b * n_range, a * e.bearing + b * n_bearing, t_s};
  };
  slam::Pose2 pose = run.initial_pose;
  double next_odo = 0.0;
  double next_cam = cam_dt;
  const auto steps = static_cast<long>(std::llround(o.duration_s / sim_dt));
  for (long step = 0; step <= steps; ++step) {
    const double t = static_cast<double>(step) * sim_dt;
    if (t + 1e-9 >= next_odo) {
      const PathCommand c = path.command_at(t);
      const double v = c.v_mps + o.v_sigma_mps * normal(rng);
      run.odometry.push_back({t - o.odometry_lead_s, v, c.w_radps + o.w_sigma_radps * normal(rng)});
      run.truth.push_back({t, pose.x(), pose.y(), pose.z()});
      next_odo += odo_dt;
    }
    if (t + 1e-9 >= next_cam) {
      slam::ObservationFrame frame{t, {}};
      for (std::size_t i = 0; i < run.poles.size(); ++i) {
        const Pole& p = run.poles[i];
        const slam::PredictedObservation z = slam::predict_observation(pose, Eigen::Vector2d(p.x_m, p.y_m));
        if (z.z.x() < o.min_range_m || z.z.x() > o.max_range_m) continue;
        if (std::abs(z.z.y()) > 0.5 * o.field_of_view_rad) continue;
        ++run.frames_in_view[i];
        // Drawn only when misses are possible: worlds without them keep their random sequence.
        if (o.detection_probability < 1.0 && uniform(rng) >= o.detection_probability) continue;
        ++run.frames_detected[i];
        slam::RangeBearing d;
        d.landmark_id = p.id;
        next_error(pole_error[i], t);
        d.range_m = z.z.x() + o.range_bias_m + o.range_sigma_m * pole_error[i].range;
        d.bearing_rad = slam::wrap_angle(z.z.y() + o.bearing_sigma_rad * pole_error[i].bearing);
        frame.detections.push_back(d);
      }
      run.pole_sightings += frame.detections.size();
      if (!frame.detections.empty()) run.frames.push_back(std::move(frame));
      next_cam += cam_dt;
    }
    const PathCommand c = path.command_at(t);
    pose = slam::move(pose, c.v_mps, c.w_radps, sim_dt);
  }
  return run;
}

}  // namespace pixyslam::sim
