#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::dds {

// How a process joins the DDS system. QoS per topic and the participant
// profiles of each deployment (loopback, lan_multicast, lan_peers,
// discovery_client, secure) live in one Fast DDS XML file (config/dds/profiles.xml);
// the addresses of a deployment are settings applied on top of the profile
// (docs/deployment.md). The default keeps all traffic on 127.0.0.1.
// Keys, ranges and help: dds_parameters().
// How much of Fast DDS's own log reaches stderr.
enum class DdsLogLevel { kError, kWarning, kInfo };

struct DdsOptions {
  int domain_id = 0;
  std::string profiles_file;  // XML; relative paths are resolved against the YAML file's folder
  std::string participant_profile = "loopback";
  std::string robot_id = "robot1";  // written into every message header
  bool type_information = false;    // announce XTypes type information: off by default, so that
                                    // other vendors (Cyclone DDS) match; docs/inspection.md says why
  std::vector<std::string> interfaces;     // IPv4 addresses DDS may use on this host (whitelist);
                                           // empty: the profile's choice
  std::vector<std::string> initial_peers;  // IPv4 addresses of other hosts, for unicast discovery
  std::string discovery_server;            // "ADDR:PORT" of a `fastdds discovery` server: be its client
  int discovery_server_id = 0;             // that server's `-i`
  double diagnostics_period_s = 1.0;  // every process's report on pixyslam/diagnostics (0: none)
  std::string security_dir;  // DDS Security: ca.cert.pem, governance.p7s, permissions.p7s and
                             // <participant name>.cert.pem / .key.pem (scripts/make_dds_security.sh)
  // Participant announcements (SPDP) are plaintext even with DDS Security (the
  // standard sends them before authentication). When announced, they carry the
  // process's role as participant name and pixyslam.host/pid/process properties
  // (spy participants, the launcher's health lines). `announce_identity`:
  // true | false | auto (unset: on, except with DDS Security, where the name is
  // "pixyslam" and no property is sent).
  std::optional<bool> announce_identity;
  DdsLogLevel log_level = DdsLogLevel::kError;
};

// One declaration per setting: key below `dds:`, range or check, help.
const parameters::Table<DdsOptions>& dds_parameters();

// Whether a participant with these options and this QoS announces its identity.
bool announces_identity(const DdsOptions& options, bool secure);

// Reads a `dds:` mapping (all keys optional) and calls reader.finish().
// `config_dir` resolves a relative profiles_file and security_dir; without a
// profiles_file, default_profiles_file(). Throws config::ConfigError.
DdsOptions read_dds_options(config::YamlReader& reader, const std::string& config_dir);

// The optional `dds:` mapping of a config file's `root` (read_dds_options), or
// `fallback` when the file has none (its profiles_file, if empty, default_profiles_file()).
DdsOptions read_dds_section(config::YamlReader& root, const std::string& config_dir, const DdsOptions& fallback = {});

// The profiles file a tool uses without --config: for a program in its build
// tree config/dds/profiles.xml of the checkout, for an installed one the
// package's /etc/pixyslam/dds/profiles.xml (the checkout's if that is absent).
std::string default_profiles_file();

// The `dds:` mapping of a YAML file (a tool's --config, e.g.
// config/slam_estimator.yaml); an empty path gives the defaults with
// `default_profiles_file`. Throws config::ConfigError naming the file and key.
DdsOptions read_dds_options_file(const std::string& yaml_path, const std::string& default_profiles_file);

// Deployment overrides from the environment, for every process of a host at
// once (the per-host launcher and containers set them): PIXYSLAM_DDS_DOMAIN,
// PIXYSLAM_DDS_PROFILES_FILE, PIXYSLAM_DDS_PROFILE, PIXYSLAM_DDS_INTERFACES and
// PIXYSLAM_DDS_PEERS (comma-separated IPv4), PIXYSLAM_DDS_SERVER (ADDR:PORT),
// PIXYSLAM_DDS_SERVER_ID, PIXYSLAM_DDS_SECURITY_DIR, PIXYSLAM_DDS_TYPE_INFORMATION
// (true/false), PIXYSLAM_DDS_LOG (error/warning/info). Unset or empty variables
// change nothing. Throws std::invalid_argument naming the variable and value.
void apply_environment(DdsOptions& options, const std::function<const char*(const char*)>& getenv);

// The DDS settings of a process, resolved once in its main, later sources
// winning: the YAML file's `dds:` mapping (already in `options`), the
// PIXYSLAM_DDS_* environment of this process, then `overrides`
// ("dds.KEY=VALUE", e.g. from --domain or --set). Participant reads no
// environment. Throws config::ConfigError naming the variable or key.
void resolve_settings(DdsOptions& options, const std::vector<std::string>& overrides = {});

// "--domain N" as an override for resolve_settings().
std::string domain_override(const std::string& value);

// "ADDR:PORT" -> (ADDR, PORT); throws std::invalid_argument naming `what`.
std::pair<std::string, std::uint16_t> split_server(const std::string& text, const std::string& what);

// Throws std::invalid_argument naming `what` unless `text` is a dotted IPv4 address.
void check_ipv4(const std::string& text, const std::string& what);

// The options as a `dds:` YAML block (effective-configuration printouts).
std::string to_yaml(const DdsOptions& options);

}  // namespace pixyslam::dds
