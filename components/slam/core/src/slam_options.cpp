#include "pixyslam/slam/slam_options.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pixyslam::slam {

const parameters::Table<FilterOptions>& filter_parameters() {
  using O = FilterOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, int>("particles", 1, 1000000, "", "M, the number of particles",
                         [](O& o) -> int& { return o.particles; }),
      P::integer<O, std::uint64_t>("seed", 0, P::kMaxSeed, "",
                                   "random seed: the same seed and input give bit-identical output",
                                   [](O& o) -> std::uint64_t& { return o.seed; }),
      P::real<O>("motion.v_sigma_m_per_sqrt_s", 0.0, 10.0, "m/sqrt(s)", "white-noise density of the forward speed",
                 [](O& o) -> double& { return o.motion.v_sigma_m_per_sqrt_s; }),
      P::real<O>("motion.w_sigma_rad_per_sqrt_s", 0.0, 10.0, "rad/sqrt(s)", "white-noise density of the turn rate",
                 [](O& o) -> double& { return o.motion.w_sigma_rad_per_sqrt_s; }),
      P::real<O>("motion.distance_sigma_per_sqrt_m", 0.0, 10.0, "1/sqrt(m)",
                 "distance noise growing with the distance driven (wheel slip)",
                 [](O& o) -> double& { return o.motion.distance_sigma_per_sqrt_m; }),
      P::real<O>("motion.heading_sigma_rad_per_sqrt_m", 0.0, 10.0, "rad/sqrt(m)",
                 "heading noise growing with the distance driven",
                 [](O& o) -> double& { return o.motion.heading_sigma_rad_per_sqrt_m; }),
      P::real<O>("motion.rotation_sigma_per_sqrt_rad", 0.0, 10.0, "1/sqrt(rad)",
                 "heading noise growing with the angle turned",
                 [](O& o) -> double& { return o.motion.rotation_sigma_per_sqrt_rad; }),
      P::real<O>("max_speed_mps", 1e-3, 1000.0, "m/s", "odometry faster than this is impossible: dropped and counted",
                 [](O& o) -> double& { return o.max_speed_mps; }),
      P::real<O>("max_turn_rate_radps", 1e-3, 1000.0, "rad/s",
                 "odometry turning faster than this is impossible: dropped and counted",
                 [](O& o) -> double& { return o.max_turn_rate_radps; }),
      P::integer<O, int>("max_map_landmarks", 1, 4096, "",
                         "landmarks the map may hold; detections that would start more are dropped and counted",
                         [](O& o) -> int& { return o.max_map_landmarks; }),
      P::real<O>("control_timeout_s", 1e-3, 3600.0, "s", "a command held longer than this counts as stopped",
                 [](O& o) -> double& { return o.control_timeout_s; }),
      P::real<O>("observation.range_sigma_m", 1e-6, 100.0, "m",
                 "range sd (+ range_sigma_per_m * range) of a detection without sigmas",
                 [](O& o) -> double& { return o.range_sigma_m; }),
      P::real<O>("observation.range_sigma_per_m", 0.0, 10.0, "m/m", "range sd growing with the range",
                 [](O& o) -> double& { return o.range_sigma_per_m; }),
      P::real<O>("observation.bearing_sigma_rad", 1e-6, 3.0, "rad", "bearing sd of a detection without sigmas",
                 [](O& o) -> double& { return o.bearing_sigma_rad; }),
      P::real<O>("observation.error_correlation_s", 0.0, 100.0, "s",
                 "how long a landmark's measurement errors persist (0: white; known_id only)",
                 [](O& o) -> double& { return o.error_correlation_s; }),
      P::real<O>("observation.min_range_m", 0.0, 1000.0, "m", "detections nearer than this are invalid",
                 [](O& o) -> double& { return o.min_range_m; }),
      P::real<O>("observation.max_range_m", 0.0, 1000.0, "m",
                 "detections farther than this are invalid (> min_range_m)",
                 [](O& o) -> double& { return o.max_range_m; }),
      P::boolean<O>("gate.enabled", "Mahalanobis gate on observations of mapped landmarks",
                    [](O& o) -> bool& { return o.gate_enabled; }),
      P::real<O>("gate.probability", 0.5, 0.999999999, "", "chi-square (2 dof) quantile of the gate",
                 [](O& o) -> double& { return o.gate_probability; }),
      P::integer<O, int>("gate.readmit_after", 1, 1000000, "",
                         "consecutive rejections before a landmark is let back in",
                         [](O& o) -> int& { return o.gate_readmit_after; }),
      P::choice<O, Association>("association.mode",
                                {{"known_id", Association::kKnownId},
                                 {"maximum_likelihood", Association::kMaximumLikelihood}},
                                "landmarks by the detection's id, or per particle the most likely",
                                [](O& o) -> Association& { return o.association; }),
      P::list<O>("association.landmark_ids",
                 "known_id: the landmark ids there are, each an id or a range A-B (e.g. 1-20); a detection with "
                 "another id is dropped and counted (observations_unknown_id). Empty: every id. Not read by "
                 "maximum_likelihood",
                 [](O& o) -> std::vector<std::string>& { return o.landmark_ids; },
                 [](const std::string& item) {
                   try {
                     parse_landmark_ids({item});
                   } catch (const std::invalid_argument&) {
                     throw std::invalid_argument("not an id or a range A-B of ids (0 .. 1000000, the smaller first)");
                   }
                 }),
      P::real<O>("association.new_landmark_probability", 0.5, 0.999999999, "",
                 "maximum_likelihood: chi-square (2 dof) quantile beyond which a detection starts a landmark",
                 [](O& o) -> double& { return o.new_landmark_probability; }),
      P::choice<O, ResampleMode>("resample.mode",
                                 {{"effective_sample_size", ResampleMode::kEffectiveSampleSize},
                                  {"every_frame", ResampleMode::kEveryFrame}},
                                 "when to resample: N_eff below neff_fraction * M, or every frame (the paper)",
                                 [](O& o) -> ResampleMode& { return o.resample_mode; }),
      P::real<O>("resample.neff_fraction", 1e-9, 1.0, "", "resample when N_eff < this * M (tiny: almost never)",
                 [](O& o) -> double& { return o.resample_neff_fraction; }),
      P::boolean<O>("delayed_sampling.enabled", "keep uncertain poses and their new landmarks joint until pinned",
                    [](O& o) -> bool& { return o.delayed_sampling.enabled; }),
      P::real<O>("delayed_sampling.enter_heading_sigma_rad", 1e-6, 10.0, "rad", "heading sd that starts a joint state",
                 [](O& o) -> double& { return o.delayed_sampling.enter_heading_sigma_rad; }),
      P::real<O>("delayed_sampling.enter_position_sigma_m", 1e-6, 1000.0, "m",
                 "position sd (worst direction) that starts a joint state",
                 [](O& o) -> double& { return o.delayed_sampling.enter_position_sigma_m; }),
      P::real<O>("delayed_sampling.exit_heading_sigma_rad", 1e-6, 10.0, "rad",
                 "heading sd that ends it (<= enter_heading_sigma_rad)",
                 [](O& o) -> double& { return o.delayed_sampling.exit_heading_sigma_rad; }),
      P::real<O>("delayed_sampling.exit_position_sigma_m", 1e-6, 1000.0, "m",
                 "position sd that ends it (<= enter_position_sigma_m)",
                 [](O& o) -> double& { return o.delayed_sampling.exit_position_sigma_m; }),
      P::integer<O, int>("delayed_sampling.max_landmarks", 1, 1000, "", "landmarks a joint state holds at most",
                         [](O& o) -> int& { return o.delayed_sampling.max_landmarks; }),
      P::boolean<O>("delayed_sampling.split_heading",
                    "split an uncertain heading into components when mapped landmarks come back",
                    [](O& o) -> bool& { return o.delayed_sampling.split_heading; }),
      P::boolean<O>("anchor_frame.enabled", "keep the output on the first landmarks' frame",
                    [](O& o) -> bool& { return o.anchor_frame.enabled; }),
      P::integer<O, int>("anchor_frame.min_landmarks", 2, 64, "", "landmarks that pin the frame (a rotation needs two)",
                         [](O& o) -> int& { return o.anchor_frame.min_landmarks; }),
      P::integer<O, int>("anchor_frame.min_observations", 1, 1000000, "", "observations of each in the best particle",
                         [](O& o) -> int& { return o.anchor_frame.min_observations; }),
      P::real<O>("anchor_frame.min_spread_m", 1e-3, 1000.0, "m", "their RMS spread around their centroid",
                 [](O& o) -> double& { return o.anchor_frame.min_spread_m; }),
      P::boolean<O>("frame_uncertainty.enabled", "output covariance floored at the map frame's uncertainty",
                    [](O& o) -> bool& { return o.frame_uncertainty; }),
      P::boolean<O>("frame_uncertainty.landmarks", "and at what the seen landmarks' spread when mapped implies",
                    [](O& o) -> bool& { return o.landmark_uncertainty; }),
  };
  return table;
}

void validate(const FilterOptions& o) {
  parameters::check_ranges(o, filter_parameters(), "filter");
  // Rules between parameters.
  const auto require = [](bool ok, const std::string& path, double value, const std::string& why) {
    if (!ok) throw parameters::RuleError("filter", path, "value " + parameters::number_text(value) + " " + why);
  };
  require(o.max_range_m > o.min_range_m, "observation.max_range_m", o.max_range_m,
          "must be greater than min_range_m (" + parameters::number_text(o.min_range_m) + ")");
  require(o.error_correlation_s == 0.0 || o.association == Association::kKnownId, "observation.error_correlation_s",
          o.error_correlation_s, "needs association known_id (a landmark's last sighting is tracked by its id)");
  const DelayedSamplingOptions& d = o.delayed_sampling;
  require(d.exit_heading_sigma_rad <= d.enter_heading_sigma_rad, "delayed_sampling.exit_heading_sigma_rad",
          d.exit_heading_sigma_rad,
          "must be <= enter_heading_sigma_rad (" + parameters::number_text(d.enter_heading_sigma_rad) + ")");
  require(d.exit_position_sigma_m <= d.enter_position_sigma_m, "delayed_sampling.exit_position_sigma_m",
          d.exit_position_sigma_m,
          "must be <= enter_position_sigma_m (" + parameters::number_text(d.enter_position_sigma_m) + ")");
}

void apply_overrides(FilterOptions& options, const std::vector<std::string>& assignments) {
  for (const std::string& assignment : assignments) {
    parameters::apply_override(options, filter_parameters(), "filter", assignment);
  }
  validate(options);
}

double gate_mahalanobis2(const FilterOptions& o) {
  // Chi-square with 2 degrees of freedom: P(d2 <= x) = 1 - exp(-x / 2).
  return -2.0 * std::log(1.0 - o.gate_probability);
}

IdRanges parse_landmark_ids(const std::vector<std::string>& items) {
  IdRanges ranges;
  for (const std::string& item : items) {
    const auto bad = [&](const std::string& why) {
      return std::invalid_argument("landmark id item '" + item + "': " + why);
    };
    const std::size_t dash = item.find('-', 1);  // a leading '-' is a sign
    const auto number = [&](const std::string& text) {
      std::vector<int> v;  // one item: the list has been split at its commas
      try {
        v = parameters::parse_int_list(text, "landmark id", 0);
      } catch (const std::invalid_argument&) {
        throw bad("expected an id or a range A-B of ids");
      }
      if (v.size() != 1) throw bad("expected an id or a range A-B of ids");
      if (v.front() > 1000000) throw bad("an id is 0 .. 1000000");
      return v.front();
    };
    const int first = number(item.substr(0, dash));
    const int last = dash == std::string::npos ? first : number(item.substr(dash + 1));
    if (last < first) throw bad("a range runs from the smaller id to the larger");
    ranges.emplace_back(first, last);
  }
  // Sorted and merged: contains_id() is one binary search.
  std::sort(ranges.begin(), ranges.end());
  IdRanges merged;
  for (const auto& r : ranges) {
    if (!merged.empty() && r.first <= merged.back().second + 1) {
      merged.back().second = std::max(merged.back().second, r.second);
    } else {
      merged.push_back(r);
    }
  }
  return merged;
}

bool contains_id(const IdRanges& ranges, int id) {
  // The range starting last at or before id.
  const auto after = std::upper_bound(ranges.begin(), ranges.end(), std::make_pair(id, std::numeric_limits<int>::max()));
  return after != ranges.begin() && id <= std::prev(after)->second;
}

std::string to_string(Association association) {
  return association == Association::kKnownId ? "known_id" : "maximum_likelihood";
}

std::string to_string(ResampleMode mode) {
  return mode == ResampleMode::kEveryFrame ? "every_frame" : "effective_sample_size";
}

}  // namespace pixyslam::slam
