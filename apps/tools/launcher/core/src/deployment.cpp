#include "pixyslam/launcher/deployment.h"

#include <arpa/inet.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/dds_options.h"

namespace pixyslam::launcher {

namespace {

bool is_ipv4(const std::string& text) {
  in_addr address{};
  return inet_pton(AF_INET, text.c_str(), &address) == 1;
}

const HostSpec* find_host(const Deployment& d, const std::string& name) {
  for (const HostSpec& h : d.hosts) {
    if (h.name == name) return &h;
  }
  return nullptr;
}

// The range of a DDS setting, as dds_parameters() declares it.
std::int64_t dds_bound(const std::string& path, bool upper) {
  const parameters::Parameter<dds::DdsOptions>* p = parameters::find(dds::dds_parameters(), path);
  return static_cast<std::int64_t>(upper ? p->max : p->min);
}

}  // namespace

Deployment read_deployment(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader y = root.child("deployment");
  Deployment d;
  d.profile = y.choice("profile", {"loopback", "lan_multicast", "lan_peers", "discovery_client", "secure"},
                       d.profile);
  d.domain_id = static_cast<int>(y.integer("domain_id", dds_bound("domain_id", false), dds_bound("domain_id", true),
                                           d.domain_id));
  if (y.has("discovery_server")) {
    config::YamlReader server = y.child("discovery_server");
    d.discovery_server_host = server.text("host");
    d.discovery_server_port = static_cast<int>(server.integer("port", 1, 65535, d.discovery_server_port));
    d.discovery_server_id =
        static_cast<int>(server.integer("id", dds_bound("discovery_server_id", false),
                                        dds_bound("discovery_server_id", true), d.discovery_server_id));
    server.finish();
  }
  d.security_dir = y.text("security_dir", "");
  if (y.has("type_information")) d.type_information = y.choice("type_information", {"true", "false"}, "false");
  if (d.type_information == "true" && d.profile == "discovery_client") {
    // `fastdds discovery` (2.9) crashes on the type information of a sequence of structs.
    y.fail("type_information", "true does not work with profile discovery_client (the Fast DDS 2.9 discovery "
                               "server crashes on it)");
  }
  if (!d.security_dir.empty() && d.security_dir.front() != '/') {
    d.security_dir = config::folder_of(path) + "/" + d.security_dir;
  }
  config::YamlReader hosts = y.child("hosts");
  std::set<std::string> processes;
  std::set<std::string> addresses;
  for (const std::string& name : hosts.keys()) {
    config::YamlReader h = hosts.child(name);
    HostSpec host;
    host.name = name;
    host.address = h.text("address");
    if (!is_ipv4(host.address)) h.fail("address", "'" + host.address + "' is not an IPv4 address");
    if (!addresses.insert(host.address).second) h.fail("address", "'" + host.address + "' is used by two hosts");
    host.processes = h.text_list("processes");
    for (const std::string& p : host.processes) {
      if (!processes.insert(p).second) h.fail("processes", "'" + p + "' is listed on two hosts (or twice)");
    }
    h.finish();
    d.hosts.push_back(std::move(host));
  }
  if (d.hosts.empty()) y.fail("hosts", "must name at least one host");
  if (d.profile == "discovery_client" && d.discovery_server_host.empty()) {
    y.fail("discovery_server", "profile discovery_client needs discovery_server: {host: ..., port: ...}");
  }
  if (!d.discovery_server_host.empty() && find_host(d, d.discovery_server_host) == nullptr) {
    y.fail("discovery_server", "host '" + d.discovery_server_host + "' is not one of the hosts");
  }
  if (d.profile == "secure" && d.security_dir.empty()) {
    y.fail("security_dir", "profile secure needs the folder made by scripts/make_dds_security.sh");
  }
  y.finish();
  root.finish();
  return d;
}

static const HostSpec& host_of(const Deployment& d, const std::string& host) {
  const HostSpec* self = find_host(d, host);
  if (self == nullptr) {
    std::string names;
    for (const HostSpec& h : d.hosts) names += (names.empty() ? "" : ", ") + h.name;
    throw std::invalid_argument("host '" + host + "' is not in the deployment (hosts: " + names + ")");
  }
  return *self;
}

std::vector<std::pair<std::string, std::string>> host_environment(const Deployment& d, const std::string& host) {
  const HostSpec& self = host_of(d, host);
  std::string peers;
  for (const HostSpec& h : d.hosts) peers += (peers.empty() ? "" : ",") + h.address;
  std::vector<std::pair<std::string, std::string>> environment{
      {"PIXYSLAM_DDS_PROFILE", d.profile},
      {"PIXYSLAM_DDS_DOMAIN", std::to_string(d.domain_id)},
      {"PIXYSLAM_DDS_INTERFACES", self.address},
      {"PIXYSLAM_DDS_PEERS", peers}};
  const HostSpec* server = d.discovery_server_host.empty() ? nullptr : find_host(d, d.discovery_server_host);
  if (server != nullptr && d.profile == "discovery_client") {
    environment.emplace_back("PIXYSLAM_DDS_SERVER", server->address + ":" + std::to_string(d.discovery_server_port));
    environment.emplace_back("PIXYSLAM_DDS_SERVER_ID", std::to_string(d.discovery_server_id));
  }
  if (!d.type_information.empty()) environment.emplace_back("PIXYSLAM_DDS_TYPE_INFORMATION", d.type_information);
  if (!d.security_dir.empty()) environment.emplace_back("PIXYSLAM_DDS_SECURITY_DIR", d.security_dir);
  return environment;
}

LaunchPlan plan_for_host(const LaunchPlan& plan, const Deployment& d, const std::string& host) {
  const HostSpec* self = &host_of(d, host);
  std::set<std::string> in_plan;
  for (const auto* list : {&plan.processes, &plan.after_run}) {
    for (const ProcessSpec& p : *list) {
      in_plan.insert(p.name);
      const bool assigned = std::any_of(d.hosts.begin(), d.hosts.end(), [&](const HostSpec& h) {
        return std::find(h.processes.begin(), h.processes.end(), p.name) != h.processes.end();
      });
      if (!assigned) throw std::invalid_argument("process '" + p.name + "' is on no host of the deployment");
    }
  }
  for (const HostSpec& h : d.hosts) {
    for (const std::string& p : h.processes) {
      if (in_plan.count(p) == 0) {
        throw std::invalid_argument("host '" + h.name + "' lists '" + p + "', which the launch file does not have");
      }
    }
  }

  const auto environment = host_environment(d, host);
  const HostSpec* server = d.discovery_server_host.empty() ? nullptr : find_host(d, d.discovery_server_host);

  LaunchPlan out;
  out.duration_s = plan.duration_s;
  out.stop_timeout_s = plan.stop_timeout_s;
  if (server == self && d.profile == "discovery_client") {
    ProcessSpec discovery;
    discovery.name = "discovery_server";
    discovery.command = {"fastdds", "discovery", "-i", std::to_string(d.discovery_server_id), "-l", self->address,
                         "-p", std::to_string(d.discovery_server_port)};
    out.processes.push_back(discovery);
  }
  auto mine = [&](const std::vector<ProcessSpec>& from, std::vector<ProcessSpec>& to) {
    for (const ProcessSpec& p : from) {
      if (std::find(self->processes.begin(), self->processes.end(), p.name) == self->processes.end()) continue;
      ProcessSpec copy = p;
      copy.environment.insert(copy.environment.end(), environment.begin(), environment.end());
      to.push_back(std::move(copy));
    }
  };
  mine(plan.processes, out.processes);
  mine(plan.after_run, out.after_run);
  return out;
}

}  // namespace pixyslam::launcher
