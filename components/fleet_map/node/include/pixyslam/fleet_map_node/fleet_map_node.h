#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fleet_map.h"
#include "map_state.h"
#include "pixyslam/dds/dds_options.h"
#include "pixyslam/fleet_map/map_fusion.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::dds {
class Participant;
template <class Message>
class Reader;
template <class Message>
class Writer;
}  // namespace pixyslam::dds
namespace pixyslam::diagnostics {
class DiagnosticsPublisher;
struct Snapshot;
}  // namespace pixyslam::diagnostics

namespace pixyslam::fleet_map_node {

// config/fleet_map.yaml.
struct FleetMapOptions {
  double period_s = 1.0;  // `fleet_map.period_s`: a fleet map this often while some robot's map changed
  int max_robots = 64;    // `fleet_map.max_robots`: MapStates of further robot ids are dropped (counted)
  // `fleet_map.robot_timeout_s`: a robot heard from no MapState for this long
  // (receive time) leaves the fusion, and its place under max_robots is free
  // again (0: robots stay for good).
  double robot_timeout_s = 60.0;
  fleet_map::FusionOptions fusion;  // `fleet_map.min_common_landmarks`, `agreement_probability`, `disagreement`
  dds::DdsOptions dds;    // dds.robot_id names the fleet map's writer (e.g. "fleet")
};

const parameters::Table<FleetMapOptions>& fleet_map_parameters();
// Reads `fleet_map:` and `dds:`; throws config::ConfigError naming the file and key.
FleetMapOptions read_fleet_map_options_file(const std::string& path);
// "fleet_map.KEY=V", "dds.KEY=V"; validated; DDS settings resolved.
void apply_overrides(FleetMapOptions& options, const std::vector<std::string>& assignments);
std::string to_yaml(const FleetMapOptions& options);

// Conversions (pure).
fleet_map::RobotMap to_robot_map(const msg::MapState& state);
msg::FleetMap to_fleet_map_msg(const fleet_map::FleetMap& fleet, const std::vector<fleet_map::RobotMap>& maps,
                               std::uint64_t stamp_ns);

struct FleetMapCounters {
  std::uint64_t map_states = 0;       // received, every robot
  std::uint64_t stale = 0;            // older than the robot's newest: ignored
  std::uint64_t restarts = 0;         // more than 10 s older than the robot's newest: a restart, taken
  std::uint64_t robots_over_limit = 0;  // MapStates of robots beyond max_robots: dropped
  std::uint64_t robots_timed_out = 0;   // robots silent for robot_timeout_s: left the fusion
  std::uint64_t malformed = 0;        // did not decode, or the callback threw
  std::uint64_t seq_jumps = 0;
  std::uint64_t fleet_maps = 0;       // published
  std::uint64_t publish_failures = 0;
  std::size_t robots = 0;
};

// Reads every robot's MapState (whatever its robot_id, up to max_robots),
// keeps each robot's newest, and every period_s in which one changed fuses
// them (fleet_map::fuse_maps) and publishes a FleetMap stamped with the newest
// kept MapState's stamp. A MapState more than 10 s older than its
// robot's newest is taken as a restart (a new clock), not as stale, so that
// one stamp from the far future cannot freeze a robot's map. A robot silent for
// robot_timeout_s leaves the fusion (the fleet map is of the robots on the
// domain now, and invented robot ids cannot hold max_robots for good). A
// robot's frame verdict that changes, and a robot that times out, are logged;
// counters go out on pixyslam/diagnostics.
class FleetMapNode {
 public:
  explicit FleetMapNode(const FleetMapOptions& options);
  ~FleetMapNode();
  FleetMapNode(const FleetMapNode&) = delete;
  FleetMapNode& operator=(const FleetMapNode&) = delete;

  void start();
  void stop();  // joins the fusion thread after a last fleet map; idempotent
  FleetMapCounters counters() const;

 private:
  void on_map_state(const msg::MapState& state);
  void loop();
  void fuse_and_publish();
  // Drops the robots heard from no MapState since `now - robot_timeout_s`.
  // Call with mutex_ held.
  void time_out_silent_robots(std::chrono::steady_clock::time_point now);
  diagnostics::Snapshot diagnostics_snapshot() const;

  const FleetMapOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  struct KeptMap {
    fleet_map::RobotMap map;                      // the robot's newest
    std::chrono::steady_clock::time_point heard;  // when its last MapState came
  };
  std::map<std::string, KeptMap> maps_;
  std::uint64_t published_stamp_ns_ = 0;          // of the last fleet map
  std::map<std::string, std::string> verdicts_;      // last logged per robot
  bool changed_ = false;
  bool stopping_ = false;
  FleetMapCounters counters_;
  std::thread thread_;

  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::Writer<msg::FleetMap>> writer_;
  std::unique_ptr<dds::Reader<msg::MapState>> reader_;  // its callback uses the above
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;  // last: reads the reader
};

}  // namespace pixyslam::fleet_map_node
