#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dataset_bridge/timeline.h"
#include "pixyslam/dds/dds_options.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/slam/slam_options.h"

namespace pixyslam::dataset_bridge_node {

// config/dataset_bridge.yaml.
struct DatasetBridgeOptions {
  double rate = 1.0;                 // `dataset_bridge.rate`: times the recording's speed; 0: as fast as
                                     // the readers acknowledge (reliable flow control)
  std::vector<int> robots = {1, 2, 3, 4, 5};  // `dataset_bridge.robots`
  int wait_readers = 0;              // `dataset_bridge.wait_readers`: matched readers per topic before the first sample
  int wait_readers_per_robot = 0;    // ... plus this many per robot published (its estimator, its evaluator)
  double wait_readers_timeout_s = 10.0;
  int flow_batch = 200;              // rate 0: samples between waits for every reader's acknowledgement
  double ack_timeout_s = 10.0;       // rate 0: longest wait for acknowledgements (then counted, go on)
  slam::FilterOptions filter;        // from filter_config: the observation sigmas put in the messages
  offline::MrclamSensorModel sensor_model;  // from filter_config's `mrclam:`
  dds::DdsOptions dds;
};

const parameters::Table<DatasetBridgeOptions>& dataset_bridge_parameters();
// Reads `dataset_bridge:`, `filter_config` (its filter: and mrclam:) and `dds:`.
DatasetBridgeOptions read_dataset_bridge_options_file(const std::string& path);
// "dataset_bridge.KEY=V", "dds.KEY=V"; validated; DDS settings resolved.
void apply_overrides(DatasetBridgeOptions& options, const std::vector<std::string>& assignments);
// The effective configuration as YAML (--verbose): dataset_bridge:, the
// filter_config's filter: and mrclam: it takes sigmas and corrections from, dds:.
std::string to_yaml(const DatasetBridgeOptions& options);

struct PublishCounters {
  std::uint64_t odometry = 0, observations = 0, ground_truth = 0, sightings = 0;
  std::uint64_t write_failures = 0;     // DDS refused a sample
  std::uint64_t ack_timeouts = 0;       // rate 0: readers that did not acknowledge in time
  double wall_time_s = 0.0;
  double recording_time_s = 0.0;        // first to last sample
};

// Publishes every robot's Odometry, LandmarkObservation, GroundTruth and RobotSighting (one
// DDS writer per robot and topic, header.robot_id "robot<N>", header seq 1..N
// per writer, stamps = the recording's times) in time order, paced by
// `options.rate`. Returns when done or when `stop` becomes true.
PublishCounters publish_recording(const DatasetBridgeOptions& options, const std::vector<dataset_bridge::RobotStream>& robots,
                                  const std::atomic<bool>& stop);

}  // namespace pixyslam::dataset_bridge_node
