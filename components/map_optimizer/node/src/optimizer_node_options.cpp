#include <cmath>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/map_optimizer_node/optimizer_node.h"
#include "pixyslam/slam_node/estimator_options.h"

namespace pixyslam::map_optimizer_node {

const parameters::Table<OptimizerNodeOptions>& optimizer_node_parameters() {
  using O = OptimizerNodeOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, int>("published_keyframes", 2, 8192, "", "OptimisedMap keyframes at most",
                         [](O& o) -> int& { return o.published_keyframes; }),
      P::integer<O, std::size_t>("max_keyframes", 0, 100000000, "",
                                 "a problem this large starts anew at the current pose, its landmarks as priors "
                                 "(0: unbounded; ~13 KB a keyframe)",
                                 [](O& o) -> std::size_t& { return o.max_keyframes; }),
      P::real<O>("status_period_s", 0.0, 3600.0, "s", "counters to the log every so often (0: never)",
                 [](O& o) -> double& { return o.status_period_s; }),
  };
  return table;
}

void apply_overrides(OptimizerNodeOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  const std::vector<std::string> optimizer = parameters::take_section(rest, "optimizer");
  if (!rest.empty()) throw std::invalid_argument("'" + rest.front() + "': not an optimizer. or dds. parameter");
  for (const std::string& a : optimizer) {
    const std::string path = a.substr(0, a.find('='));
    if (parameters::find(optimizer_node_parameters(), path.substr(path.find('.') + 1)) != nullptr) {
      parameters::apply_override(o, optimizer_node_parameters(), "optimizer", a);
    } else {
      map_optimizer::apply_optimizer_override(o.optimizer, o.schedule, a);
    }
  }
  map_optimizer::validate(o.optimizer);
  dds::resolve_settings(o.dds, dds);
}

std::string to_yaml(const OptimizerNodeOptions& o) {
  // One section, three tables: the core's keys, the schedule's, the node's.
  const auto below_section = [](std::string yaml) { return yaml.erase(0, yaml.find('\n') + 1); };
  return parameters::to_yaml(o.optimizer, map_optimizer::map_optimizer_parameters(), "optimizer") +
         below_section(parameters::to_yaml(o.schedule, map_optimizer::solve_schedule_parameters(), "optimizer")) +
         below_section(parameters::to_yaml(o, optimizer_node_parameters(), "optimizer")) + dds::to_yaml(o.dds);
}

std::string help_text() {
  // Named defaults: GCC 12 warns (maybe-uninitialized, falsely) on the temporary default argument.
  const map_optimizer::MapOptimizerOptions core_defaults;
  const map_optimizer::SolveScheduleOptions schedule_defaults;
  const OptimizerNodeOptions node_defaults;
  return "optimizer parameters (optimizer:; the noise models come from filter_config):\n" +
         parameters::help_text(map_optimizer::map_optimizer_parameters(), "optimizer", core_defaults) +
         parameters::help_text(map_optimizer::solve_schedule_parameters(), "optimizer", schedule_defaults) +
         parameters::help_text(optimizer_node_parameters(), "optimizer", node_defaults) +
         "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

OptimizerNodeOptions read_optimizer_node_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  OptimizerNodeOptions o;
  std::string filter_config = root.text("filter_config");
  if (!filter_config.empty() && filter_config.front() != '/') filter_config = config::folder_of(path) + "/" + filter_config;
  // The estimator's own reader: the same keys, checks and defaults as the filter's.
  const slam_node::EstimatorOptions estimator = config::read_referenced(
      path, "filter_config", [&] { return slam_node::read_estimator_options_file(filter_config); });
  o.optimizer = map_optimizer::MapOptimizerOptions::from_filter(estimator.filter);
  o.initial_pose = estimator.initial_pose;
  o.queue = estimator.queue;
  o.use_detection_sigmas = estimator.use_detection_sigmas;

  config::YamlReader y = root.child("optimizer");
  config::read_parameters(y, map_optimizer::map_optimizer_parameters(), o.optimizer);
  config::read_parameters(y, map_optimizer::solve_schedule_parameters(), o.schedule);
  config::read_parameters(y, optimizer_node_parameters(), o);
  y.finish();
  map_optimizer::validate(o.optimizer);

  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, config::folder_of(path));
  } else {
    o.dds = estimator.dds;  // the estimator's domain and profiles
  }
  root.finish();
  return o;
}

}  // namespace pixyslam::map_optimizer_node
