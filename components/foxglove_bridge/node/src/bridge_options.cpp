#include "pixyslam/foxglove_node/bridge_options.h"

#include <stdexcept>

#include <arpa/inet.h>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/dds/topic_config.h"

namespace pixyslam::foxglove_node {

namespace {

void check_frame(const std::string& v) {
  if (v.empty()) throw std::invalid_argument("empty");
}

// A numeric IPv4 or IPv6 address (the server binds it; no name lookup).
void check_address(const std::string& v) {
  unsigned char bytes[16];
  if (::inet_pton(AF_INET, v.c_str(), bytes) != 1 && ::inet_pton(AF_INET6, v.c_str(), bytes) != 1) {
    throw std::invalid_argument("'" + v + "' is not a numeric IPv4 or IPv6 address");
  }
}

}  // namespace

const parameters::Table<BridgeOptions>& bridge_parameters() {
  using O = BridgeOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::text<O>("address", "IPv4/IPv6 address to listen on (127.0.0.1: this host only; 0.0.0.0: every interface)",
                 [](O& o) -> std::string& { return o.server.address; }, check_address),
      P::integer<O, std::uint16_t>("port", 0, 65535, "", "TCP port (Foxglove's default 8765; 0: any free port)",
                                   [](O& o) -> std::uint16_t& { return o.server.port; }),
      P::integer<O, std::size_t>("max_clients", 1, 1000, "", "connections beyond this are refused",
                                 [](O& o) -> std::size_t& { return o.server.max_clients; }),
      P::integer<O, std::size_t>("client_queue_max_bytes", std::size_t{1} << 16, P::kMaxBytes4GiB, "B",
                                 "bytes waiting to be sent to one client; beyond, its messages are dropped and counted",
                                 [](O& o) -> std::size_t& { return o.server.client_queue_max_bytes; }),
      P::integer<O, std::size_t>("backlog_max_bytes", std::size_t{1} << 16, P::kMaxBytes4GiB, "B",
                                 "bytes received from DDS and not yet handed to clients; beyond, dropped and counted",
                                 [](O& o) -> std::size_t& { return o.server.backlog_max_bytes; }),
      P::boolean<O>("visuals", "the pixyslam/viz/* channels (foxglove.SceneUpdate, PosesInFrame, FrameTransform)",
                    [](O& o) -> bool& { return o.visuals; }),
      P::real<O>("ellipse_sigma", 0.5, 10.0, "", "landmark and pose ellipses at this many standard deviations",
                 [](O& o) -> double& { return o.visual.ellipse_sigma; }),
      P::integer<O, std::size_t>("path_max_poses", 2, 1000000, "",
                                 "poses in a path message; a longer path keeps every other pose",
                                 [](O& o) -> std::size_t& { return o.visual.path_max_poses; }),
      P::real<O>("path_min_step_m", 0.0, 10.0, "m", "a pose joins the path once this far from the previous one",
                 [](O& o) -> double& { return o.visual.path_min_step_m; }),
      P::text<O>("map_frame", "frame of the map (parent of robot_frame)",
                 [](O& o) -> std::string& { return o.visual.map_frame; }, check_frame),
      P::text<O>("robot_frame", "frame of the robot, placed at the mean pose",
                 [](O& o) -> std::string& { return o.visual.robot_frame; }, check_frame),
      P::text<O>("visual_robot_id", "the robot drawn in pixyslam/viz/* ('': the first whose MapState arrives)",
                 [](O& o) -> std::string& { return o.visual.robot_id; }),
  };
  return table;
}

BridgeOptions read_bridge_options(config::YamlReader& root, const std::string& config_dir) {
  BridgeOptions o;
  config::YamlReader section = root.child("foxglove_bridge");
  o.topics = dds::read_topic_patterns(section);
  config::read_parameters(section, bridge_parameters(), o);
  config::check_rules(section, [&] { parameters::check_ranges(o, bridge_parameters(), "foxglove_bridge"); });
  section.finish();
  o.dds = dds::read_dds_section(root, config_dir);
  root.finish();
  return o;
}

BridgeOptions read_bridge_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_bridge_options(root, config::folder_of(path));
}

void apply_overrides(BridgeOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  for (const std::string& a : rest) parameters::apply_override(o, bridge_parameters(), "foxglove_bridge", a);
  parameters::check_ranges(o, bridge_parameters(), "foxglove_bridge");
  dds::resolve_settings(o.dds, dds);
}

std::string to_yaml(const BridgeOptions& o) {
  std::string topics;
  for (const std::string& t : o.topics) topics += (topics.empty() ? "" : ", ") + t;
  return parameters::to_yaml(o, bridge_parameters(), "foxglove_bridge") + "  topics: [" + topics + "]\n" +
         dds::to_yaml(o.dds);
}

}  // namespace pixyslam::foxglove_node
