#include "pixyslam/slam/slam_options_yaml.h"

#include <stdexcept>

namespace pixyslam::slam {

FilterOptions read_filter_options(config::YamlReader& f) {
  FilterOptions o;
  o.particles = static_cast<int>(f.integer("particles", 1, 1000000, o.particles));
  o.seed = static_cast<std::uint64_t>(f.integer("seed", 0, INT64_MAX, static_cast<std::int64_t>(o.seed)));
  if (f.has("motion")) {
    config::YamlReader m = f.child("motion");
    o.motion.v_sigma_m_per_sqrt_s = m.number("v_sigma_m_per_sqrt_s", 0.0, 10.0, o.motion.v_sigma_m_per_sqrt_s);
    o.motion.w_sigma_rad_per_sqrt_s =
        m.number("w_sigma_rad_per_sqrt_s", 0.0, 10.0, o.motion.w_sigma_rad_per_sqrt_s);
    o.motion.distance_sigma_per_sqrt_m =
        m.number("distance_sigma_per_sqrt_m", 0.0, 10.0, o.motion.distance_sigma_per_sqrt_m);
    o.motion.heading_sigma_rad_per_sqrt_m =
        m.number("heading_sigma_rad_per_sqrt_m", 0.0, 10.0, o.motion.heading_sigma_rad_per_sqrt_m);
    o.motion.rotation_sigma_per_sqrt_rad =
        m.number("rotation_sigma_per_sqrt_rad", 0.0, 10.0, o.motion.rotation_sigma_per_sqrt_rad);
    m.finish();
  }
  o.max_speed_mps = f.number("max_speed_mps", 1e-3, 1000.0, o.max_speed_mps);
  o.max_turn_rate_radps = f.number("max_turn_rate_radps", 1e-3, 1000.0, o.max_turn_rate_radps);
  o.control_timeout_s = f.number("control_timeout_s", 1e-3, 3600.0, o.control_timeout_s);
  if (f.has("observation")) {
    config::YamlReader z = f.child("observation");
    o.range_sigma_m = z.number("range_sigma_m", 1e-6, 100.0, o.range_sigma_m);
    o.range_sigma_per_m = z.number("range_sigma_per_m", 0.0, 10.0, o.range_sigma_per_m);
    o.bearing_sigma_rad = z.number("bearing_sigma_rad", 1e-6, 3.0, o.bearing_sigma_rad);
    o.error_correlation_s = z.number("error_correlation_s", 0.0, 100.0, o.error_correlation_s);
    o.min_range_m = z.number("min_range_m", 0.0, 1000.0, o.min_range_m);
    o.max_range_m = z.number("max_range_m", 0.0, 1000.0, o.max_range_m);
    z.finish();
  }
  if (f.has("gate")) {
    config::YamlReader g = f.child("gate");
    o.gate_enabled = g.boolean("enabled", o.gate_enabled);
    o.gate_probability = g.number("probability", 0.5, 0.999999999, o.gate_probability);
    o.gate_readmit_after = static_cast<int>(g.integer("readmit_after", 1, 1000000, o.gate_readmit_after));
    g.finish();
  }
  if (f.has("association")) {
    config::YamlReader a = f.child("association");
    const std::string mode = a.choice("mode", {"known_id", "maximum_likelihood"}, to_string(o.association));
    o.association = mode == "known_id" ? Association::kKnownId : Association::kMaximumLikelihood;
    o.new_landmark_probability = a.number("new_landmark_probability", 0.5, 0.999999999, o.new_landmark_probability);
    a.finish();
  }
  if (f.has("resample")) {
    config::YamlReader r = f.child("resample");
    const std::string mode = r.choice("mode", {"effective_sample_size", "every_frame"}, to_string(o.resample_mode));
    o.resample_mode = mode == "every_frame" ? ResampleMode::kEveryFrame : ResampleMode::kEffectiveSampleSize;
    o.resample_neff_fraction = r.number("neff_fraction", 1e-6, 1.0, o.resample_neff_fraction);
    r.finish();
  }
  if (f.has("delayed_sampling")) {
    config::YamlReader d = f.child("delayed_sampling");
    DelayedSamplingOptions& ds = o.delayed_sampling;
    ds.enabled = d.boolean("enabled", ds.enabled);
    ds.enter_heading_sigma_rad = d.number("enter_heading_sigma_rad", 1e-6, 10.0, ds.enter_heading_sigma_rad);
    ds.enter_position_sigma_m = d.number("enter_position_sigma_m", 1e-6, 1000.0, ds.enter_position_sigma_m);
    ds.exit_heading_sigma_rad = d.number("exit_heading_sigma_rad", 1e-6, 10.0, ds.exit_heading_sigma_rad);
    ds.exit_position_sigma_m = d.number("exit_position_sigma_m", 1e-6, 1000.0, ds.exit_position_sigma_m);
    ds.max_landmarks = static_cast<int>(d.integer("max_landmarks", 1, 1000, ds.max_landmarks));
    d.finish();
  }
  if (f.has("anchor_frame")) {
    config::YamlReader a = f.child("anchor_frame");
    AnchorFrameOptions& af = o.anchor_frame;
    af.enabled = a.boolean("enabled", af.enabled);
    af.min_landmarks = static_cast<int>(a.integer("min_landmarks", 2, 64, af.min_landmarks));
    af.min_observations = static_cast<int>(a.integer("min_observations", 1, 1000000, af.min_observations));
    af.min_spread_m = a.number("min_spread_m", 1e-3, 1000.0, af.min_spread_m);
    a.finish();
  }
  if (f.has("frame_uncertainty")) {
    config::YamlReader u = f.child("frame_uncertainty");
    o.frame_uncertainty = u.boolean("enabled", o.frame_uncertainty);
    o.landmark_uncertainty = u.boolean("landmarks", o.landmark_uncertainty);
    u.finish();
  }
  f.finish();
  try {
    validate(o);
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(f.origin() + ": mapping '" + f.path() + "': " + e.what());
  }
  return o;
}

FilterOptions read_filter_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader filter = root.child("filter");
  FilterOptions o = read_filter_options(filter);
  root.finish();
  return o;
}

}  // namespace pixyslam::slam
