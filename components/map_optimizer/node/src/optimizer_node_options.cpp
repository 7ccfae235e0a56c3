#include <cmath>

#include "pixyslam/app/command_line.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/map_optimizer_node/optimizer_node.h"
#include "pixyslam/slam_node/estimator_options.h"

namespace pixyslam::map_optimizer_node {

OptimizerNodeOptions read_optimizer_node_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  OptimizerNodeOptions o;
  std::string filter_config = root.text("filter_config");
  if (!filter_config.empty() && filter_config.front() != '/') filter_config = app::folder_of(path) + "/" + filter_config;
  // The estimator's own reader: the same keys, checks and defaults as the filter's.
  const slam_node::EstimatorOptions estimator = slam_node::read_estimator_options_file(filter_config);
  o.optimizer = map_optimizer::MapOptimizerOptions::from_filter(estimator.filter);
  o.initial_pose = estimator.initial_pose;
  o.queue = estimator.queue;
  o.use_detection_sigmas = estimator.use_detection_sigmas;

  config::YamlReader y = root.child("optimizer");
  map_optimizer::MapOptimizerOptions& m = o.optimizer;
  m.keyframe_interval_s = y.number("keyframe_interval_s", 0.01, 3600.0, m.keyframe_interval_s);
  m.huber_threshold = y.number("huber_threshold", 1e-3, 1e6, m.huber_threshold);
  m.max_iterations = static_cast<int>(y.integer("max_iterations", 1, 10000, m.max_iterations));
  o.schedule.window_keyframes = static_cast<std::size_t>(
      y.integer("window_keyframes", 1, 1000000, static_cast<std::int64_t>(o.schedule.window_keyframes)));
  o.schedule.window_period_s = y.number("window_period_s", 0.01, 3600.0, o.schedule.window_period_s);
  o.schedule.whole_period_s = y.number("whole_period_s", 0.01, 86400.0, o.schedule.whole_period_s);
  o.published_keyframes = static_cast<int>(y.integer("published_keyframes", 2, 8192, o.published_keyframes));
  o.status_period_s = y.number("status_period_s", 0.0, 3600.0, o.status_period_s);
  y.finish();
  map_optimizer::validate(o.optimizer);

  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, app::folder_of(path));
  } else {
    o.dds = estimator.dds;  // the estimator's domain and profiles
  }
  root.finish();
  return o;
}

}  // namespace pixyslam::map_optimizer_node
