#include "pixyslam/slam_node/estimator_options.h"

#include <cmath>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace pixyslam::slam_node {

const parameters::Table<EstimatorOptions>& estimator_parameters() {
  using O = EstimatorOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("initial_pose.x_m", -1e6, 1e6, "m", "start pose x (the map frame's origin)",
                 [](O& o) -> double& { return o.initial_pose.x(); }),
      P::real<O>("initial_pose.y_m", -1e6, 1e6, "m", "start pose y", [](O& o) -> double& { return o.initial_pose.y(); }),
      P::real<O>("initial_pose.theta_rad", -2.0 * M_PI, 2.0 * M_PI, "rad", "start heading",
                 [](O& o) -> double& { return o.initial_pose.z(); }),
      P::choice<O, std::string>("initial_pose.source", {{"config", "config"}, {"ground_truth", "ground_truth"}},
                                "the start pose: the three keys above, or this robot's first GroundTruth",
                                [](O& o) -> std::string& { return o.initial_pose_source; }),
      P::real<O>("initial_pose.wait_s", 0.0, 3600.0, "s", "ground_truth: how long the first step waits for it",
                 [](O& o) -> double& { return o.initial_pose_wait_s; }),
      P::real<O>("odometry_max_delay_s", 0.0, 10.0, "s", "how long odometry may lag behind the newest input",
                 [](O& o) -> double& { return o.queue.odometry_max_delay_s; }),
      P::real<O>("observation_max_delay_s", 0.0, 10.0, "s", "how long observations may lag behind the newest input",
                 [](O& o) -> double& { return o.queue.observation_max_delay_s; }),
      P::real<O>("max_stamp_jump_s", 0.0, 1e9, "s",
                 "a stamp further ahead of the newest waits for the next sample to confirm it (else dropped)",
                 [](O& o) -> double& { return o.queue.max_stamp_jump_s; }),
      P::integer<O, std::size_t>("max_held_samples", std::size_t{1}, std::size_t{10000000}, "",
                                 "sensor samples waiting at most; more are dropped (a flood)",
                                 [](O& o) -> std::size_t& { return o.queue.max_held; }),
      P::boolean<O>("use_detection_sigmas", "the camera's per-detection sigmas (else the filter's)",
                    [](O& o) -> bool& { return o.use_detection_sigmas; }),
      P::integer<O, int>("published_particle_poses", 0, 512, "", "particle poses in each MapState (a subsample)",
                         [](O& o) -> int& { return o.published_particle_poses; }),
      P::real<O>("map_state_period_s", 0.0, 3600.0, "s", "a MapState at most this often in filter time (0: every step)",
                 [](O& o) -> double& { return o.map_state_period_s; }),
      P::choice<O, std::string>("landmarks", {{"best", "best"}, {"mixture", "mixture"}},
                                "MapState landmarks: the best particle's, or the mixture over particles",
                                [](O& o) -> std::string& { return o.landmarks; }),
      P::real<O>("status_period_s", 0.0, 3600.0, "s", "counters to the log every so often (0: never)",
                 [](O& o) -> double& { return o.status_period_s; }),
      P::text<O>("checkpoint.file", "pose and map saved here every period (relative: to the config's folder; '': none)",
                 [](O& o) -> std::string& { return o.checkpoint.file; }),
      P::real<O>("checkpoint.period_s", 0.01, 3600.0, "s", "filter time between writes",
                 [](O& o) -> double& { return o.checkpoint.period_s; }),
      P::boolean<O>("checkpoint.resume", "start from the file when it is fresh enough",
                    [](O& o) -> bool& { return o.checkpoint.resume; }),
      P::real<O>("checkpoint.max_age_s", 0.0, 1e9, "s", "older than this at the first input: start from scratch",
                 [](O& o) -> double& { return o.checkpoint.max_age_s; }),
      P::real<O>("checkpoint.max_speed_mps", 0.0, 100.0, "m/s", "how fast the robot may have moved while no estimator ran",
                 [](O& o) -> double& { return o.checkpoint.max_speed_mps; }),
      P::real<O>("checkpoint.max_turn_rate_radps", 0.0, 100.0, "rad/s", "how fast it may have turned",
                 [](O& o) -> double& { return o.checkpoint.max_turn_rate_radps; }),
  };
  return table;
}

void apply_overrides(EstimatorOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> filter = parameters::take_section(rest, "filter");
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  const std::vector<std::string> estimator = parameters::take_section(rest, "estimator");
  if (!rest.empty()) throw std::invalid_argument("'" + rest.front() + "': not a filter., estimator. or dds. parameter");
  for (const std::string& a : estimator) parameters::apply_override(o, estimator_parameters(), "estimator", a);
  slam::apply_overrides(o.filter, filter);
  dds::resolve_settings(o.dds, dds);
}

std::string to_yaml(const EstimatorOptions& o) {
  return parameters::to_yaml(o.filter, slam::filter_parameters(), "filter") +
         parameters::to_yaml(o, estimator_parameters(), "estimator") + dds::to_yaml(o.dds);
}

std::string help_text() {
  const EstimatorOptions defaults;
  return "filter parameters (the config's filter: section):\n" +
         parameters::help_text(slam::filter_parameters(), "filter") +
         "estimator parameters (estimator:):\n" + parameters::help_text(estimator_parameters(), "estimator") +
         "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

EstimatorOptions read_estimator_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  EstimatorOptions o;
  // `filter:` here, or `filter_config: FILE`: the filter: of another file (e.g.
  // the offline runner's slam_mrclam.yaml), relative to this one.
  if (root.has("filter_config")) {
    if (root.has("filter")) root.fail("filter_config", "give filter: or filter_config:, not both");
    std::string filter_config = root.text("filter_config");
    if (!filter_config.empty() && filter_config.front() != '/') filter_config = config::folder_of(path) + "/" + filter_config;
    o.filter = config::read_referenced(path, "filter_config", [&] {
      config::YamlReader filter_root = config::YamlReader::from_file(filter_config);
      config::YamlReader filter = filter_root.child("filter");
      return slam::read_filter_options(filter);
    });
  } else {
    config::YamlReader filter = root.child("filter");
    o.filter = slam::read_filter_options(filter);
  }

  config::YamlReader estimator = root.child("estimator");
  config::read_parameters(estimator, estimator_parameters(), o);
  CheckpointOptions& k = o.checkpoint;
  if (!k.file.empty() && k.file.front() != '/') k.file = config::folder_of(path) + "/" + k.file;
  estimator.finish();

  o.dds = dds::read_dds_section(root, config::folder_of(path));
  root.finish();
  return o;
}

}  // namespace pixyslam::slam_node
