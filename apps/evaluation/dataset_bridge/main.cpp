// dataset_bridge: a multi-robot recording (MRCLAM) onto the live topics, as the
// robots' own bridges would publish it: per robot Odometry, LandmarkObservation
// (range and bearing after the data set's corrections, with the filter's
// sigmas) and GroundTruth, header.robot_id "robot<N>", on the recording's
// timeline at --rate times its speed (0: as fast as the readers acknowledge).
//   dataset_bridge --config config/dataset_bridge.yaml --dataset DIR [--robots 1,2] [--rate R] [--duration S]
//                  [--set KEY=VALUE ...] [--domain N] [--verbose]
// Exit status: 0 when every sample was published, 1 when DDS refused some or
// readers did not acknowledge in time (counted), 2 for a usage, configuration
// or data set error.
#include <atomic>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dataset_bridge_node/dataset_publisher.h"
#include "pixyslam/parameters/parameters.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config, dataset, robots;
  double rate = -1.0, duration_s = 0.0;
  bool verbose = false;
  std::vector<std::string> overrides, domain;
  app::Cli cli{"dataset_bridge",
               "A multi-robot recording (MRCLAM data set) onto the live topics: each robot's Odometry, "
               "LandmarkObservation and GroundTruth on the recording's timeline."};
  app::add_config(cli, config, "config/dataset_bridge.yaml: dataset_bridge:, filter_config (sigmas, mrclam:), dds:");
  cli.option("--dataset", dataset, "the data set's folder (e.g. ../shared/data/mrclam/Dataset6)").required().type("DIR");
  cli.option("--robots", robots, "robots to publish (overrides dataset_bridge.robots), e.g. 1,3").type("LIST");
  cli.option("--rate", rate, "times the recording's speed (overrides dataset_bridge.rate; 0: as fast as acknowledged)")
      .non_negative()
      .type("R");
  cli.option("--duration", duration_s,
             "only the first S seconds of each robot's recording from its start (default: all; as slam_offline "
             "mrclam --duration)")
      .non_negative()
      .type("S");
  app::add_set(cli, overrides, "dataset_bridge.wait_readers=2");
  app::add_domain(cli, domain);
  app::add_verbose(cli, verbose);
  cli.footer("dataset_bridge parameters (dataset_bridge:; robots apart):\n" +
             parameters::help_text(dataset_bridge_node::dataset_bridge_parameters(), "dataset_bridge") +
             "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
             parameters::help_text(pixyslam::dds::dds_parameters(), "dds"));
  if (const auto done = cli.parse(argc, argv)) return *done;

  dataset_bridge_node::DatasetBridgeOptions options;
  std::vector<dataset_bridge::RobotStream> streams;
  const std::optional<int> bad = app::configure("dataset_bridge", [&] {
    options = dataset_bridge_node::read_dataset_bridge_options_file(config);
    if (!robots.empty()) overrides.push_back("dataset_bridge.robots=" + robots);
    if (rate >= 0.0) overrides.push_back("dataset_bridge.rate=" + std::to_string(rate));
    overrides.insert(overrides.end(), domain.begin(), domain.end());  // --domain last: it wins
    dataset_bridge_node::apply_overrides(options, overrides);
  });
  if (bad) return *bad;
  if (verbose) app::print_effective_configuration("dataset_bridge", dataset_bridge_node::to_yaml(options));
  return app::run_main("dataset_bridge", [&] {
    // An input that is missing or does not read is a runtime failure (1), as in
    // slam_offline, pixyslam_calibrate and pixyslam_spy.
    for (int r : options.robots) {
      streams.push_back(dataset_bridge::make_robot_stream(mrclam::load_robot(dataset, r), options.sensor_model));
      dataset_bridge::keep_first_seconds(streams.back(), duration_s);
    }
    for (const dataset_bridge::RobotStream& s : streams) {
      std::fprintf(stderr, "dataset_bridge: %s: %zu odometry, %zu frames, %zu ground truth, %zu robot sightings\n",
                   s.robot_id.c_str(), s.input.odometry.size(), s.input.frames.size(), s.input.truth.size(),
                   s.sightings.size());
    }
    std::atomic<bool> stop{false};
    std::thread watcher([&] {
      while (!stop.load() && !app::StopSignal::wait_for(std::chrono::milliseconds(100))) {
      }
      stop = true;
    });
    const dataset_bridge_node::PublishCounters c = dataset_bridge_node::publish_recording(options, streams, stop);
    const bool interrupted = stop.exchange(true);
    watcher.join();
    std::fprintf(stderr,
                 "dataset_bridge: published %llu odometry, %llu observations, %llu ground truth, %llu robot sightings "
                 "(%.1f s of recording in %.1f s); %llu write failures, %llu acknowledgement time-outs%s\n",
                 static_cast<unsigned long long>(c.odometry), static_cast<unsigned long long>(c.observations),
                 static_cast<unsigned long long>(c.ground_truth), static_cast<unsigned long long>(c.sightings),
                 c.recording_time_s, c.wall_time_s,
                 static_cast<unsigned long long>(c.write_failures), static_cast<unsigned long long>(c.ack_timeouts),
                 interrupted ? " (interrupted)" : "");
    return c.write_failures > 0 || c.ack_timeouts > 0 ? 1 : 0;
  });
}
