#include "pixyslam/slam_node/estimator_options.h"

#include <cmath>

#include "pixyslam/app/command_line.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace pixyslam::slam_node {

EstimatorOptions read_estimator_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  EstimatorOptions o;
  config::YamlReader filter = root.child("filter");
  o.filter = slam::read_filter_options(filter);

  config::YamlReader estimator = root.child("estimator");
  if (estimator.has("initial_pose")) {
    config::YamlReader pose = estimator.child("initial_pose");
    o.initial_pose.x() = pose.number("x_m", -1e6, 1e6, 0.0);
    o.initial_pose.y() = pose.number("y_m", -1e6, 1e6, 0.0);
    o.initial_pose.z() = pose.number("theta_rad", -2.0 * M_PI, 2.0 * M_PI, 0.0);
    pose.finish();
  }
  o.queue.odometry_max_delay_s =
      estimator.number("odometry_max_delay_s", 0.0, 10.0, o.queue.odometry_max_delay_s);
  o.queue.observation_max_delay_s =
      estimator.number("observation_max_delay_s", 0.0, 10.0, o.queue.observation_max_delay_s);
  o.use_detection_sigmas = estimator.boolean("use_detection_sigmas", o.use_detection_sigmas);
  o.published_particle_poses = static_cast<int>(
      estimator.integer("published_particle_poses", 0, 512, o.published_particle_poses));
  o.landmarks = estimator.choice("landmarks", {"best", "mixture"}, o.landmarks);
  o.status_period_s = estimator.number("status_period_s", 0.0, 3600.0, o.status_period_s);
  if (estimator.has("checkpoint")) {
    config::YamlReader c = estimator.child("checkpoint");
    CheckpointOptions& k = o.checkpoint;
    k.file = c.text("file", k.file);
    if (!k.file.empty() && k.file.front() != '/') k.file = app::folder_of(path) + "/" + k.file;
    k.period_s = c.number("period_s", 0.01, 3600.0, k.period_s);
    k.resume = c.boolean("resume", k.resume);
    k.max_age_s = c.number("max_age_s", 0.0, 1e9, k.max_age_s);
    k.max_speed_mps = c.number("max_speed_mps", 0.0, 100.0, k.max_speed_mps);
    k.max_turn_rate_radps = c.number("max_turn_rate_radps", 0.0, 100.0, k.max_turn_rate_radps);
    c.finish();
  }
  estimator.finish();

  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, app::folder_of(path));
  }
  root.finish();
  return o;
}

}  // namespace pixyslam::slam_node
