#pragma once

#include <string>
#include <vector>

#include "pixyslam/launcher/launch_plan.h"

namespace pixyslam::launcher {

// One machine of a deployment: its address on the network the hosts share and
// the processes of the launch file (and after_run steps) it runs.
struct HostSpec {
  std::string name;
  std::string address;  // IPv4
  std::vector<std::string> processes;
};

// Which process runs on which host and how the hosts find each other
// (config/deploy_*.yaml, docs/deployment.md).
struct Deployment {
  std::string profile = "lan_peers";  // participant profile of config/dds/profiles.xml
  int domain_id = 0;
  std::string discovery_server_host;  // profile discovery_client: the host that runs `fastdds discovery`
  int discovery_server_port = 11811;
  int discovery_server_id = 0;
  std::string security_dir;  // profile secure: scripts/make_dds_security.sh output
  // Announce XTypes type information ("true" | "false") on every process of
  // the deployment; "" (key absent): each process's own dds.type_information
  // (off by default: other vendors match, ~10x less discovery traffic).
  std::string type_information;
  std::vector<HostSpec> hosts;
};

// Reads the `deployment:` mapping. Errors (unknown keys, a bad address, a host
// or process listed twice, a discovery server host that is not a host, the
// discovery_client profile without one, the secure profile without
// security_dir) throw config::ConfigError naming the file and key.
Deployment read_deployment(const std::string& path);

// The DDS environment of `host`'s processes (see plan_for_host). Throws
// std::invalid_argument for an unknown host. Pure.
std::vector<std::pair<std::string, std::string>> host_environment(const Deployment& deployment,
                                                                  const std::string& host);

// The part of `plan` that `host` runs: its processes and after_run steps in
// launch-file order, each with the DDS environment of the deployment
// (PIXYSLAM_DDS_PROFILE, _DOMAIN, _INTERFACES = the host's address, _PEERS =
// every host's address, _SERVER / _SERVER_ID, _SECURITY_DIR), and first a
// `fastdds discovery` server when this host serves discovery. Throws
// std::invalid_argument for an unknown host, a process of the plan assigned to
// no host, or a host listing a process the plan does not have. Pure.
LaunchPlan plan_for_host(const LaunchPlan& plan, const Deployment& deployment, const std::string& host);

}  // namespace pixyslam::launcher
