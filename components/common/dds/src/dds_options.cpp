#include "pixyslam/dds/dds_options.h"

#include <arpa/inet.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "pixyslam/config/parameters_yaml.h"

namespace pixyslam::dds {

namespace {

std::string resolve(const std::string& path, const std::string& dir) {
  if (path.empty() || path.front() == '/' || dir.empty()) return path;
  return dir + "/" + path;
}

void ipv4_item(const std::string& text) {
  in_addr address{};
  if (inet_pton(AF_INET, text.c_str(), &address) != 1) throw std::invalid_argument("not an IPv4 address");
}

// The environment variable of each setting a deployment sets per host.
struct EnvironmentKey {
  const char* variable;
  const char* path;
};
constexpr EnvironmentKey kEnvironment[] = {
    {"PIXYSLAM_DDS_DOMAIN", "domain_id"},
    {"PIXYSLAM_DDS_PROFILES_FILE", "profiles_file"},
    {"PIXYSLAM_DDS_PROFILE", "participant_profile"},
    {"PIXYSLAM_DDS_INTERFACES", "interfaces"},
    {"PIXYSLAM_DDS_PEERS", "initial_peers"},
    {"PIXYSLAM_DDS_SERVER", "discovery_server"},
    {"PIXYSLAM_DDS_SERVER_ID", "discovery_server_id"},
    {"PIXYSLAM_DDS_SECURITY_DIR", "security_dir"},
    {"PIXYSLAM_DDS_TYPE_INFORMATION", "type_information"},
    {"PIXYSLAM_DDS_LOG", "log_level"},
};

}  // namespace

const parameters::Table<DdsOptions>& dds_parameters() {
  using O = DdsOptions;
  namespace P = parameters;
  static const P::Table<O> table = [] {
    P::Table<O> t = {
        P::integer<O, int>("domain_id", 0, 232, "", "DDS domain: processes meet only on the same one",
                           [](O& o) -> int& { return o.domain_id; }),
        P::text<O>("profiles_file", "Fast DDS XML profiles (relative: to the YAML file's folder; none: the checkout's, or the installed, config/dds/profiles.xml)",
                   [](O& o) -> std::string& { return o.profiles_file; }),
        P::text<O>("participant_profile", "loopback | lan_multicast | lan_peers | discovery_client | secure",
                   [](O& o) -> std::string& { return o.participant_profile; },
                   [](const std::string& v) {
                     if (v.empty()) throw std::invalid_argument("empty");
                   }),
        P::text<O>("robot_id", "written into every message header",
                   [](O& o) -> std::string& { return o.robot_id; },
                   [](const std::string& v) {
                     if (v.empty()) throw std::invalid_argument("empty");
                   }),
        P::boolean<O>("type_information",
                      "announce XTypes type information (generic Fast DDS tools; other vendors then cannot match)",
                      [](O& o) -> bool& { return o.type_information; }),
        P::real<O>("diagnostics_period_s", 0.0, 3600.0, "s", "period of the report on pixyslam/diagnostics (0: none)",
                   [](O& o) -> double& { return o.diagnostics_period_s; }),
        P::list<O>("interfaces", "IPv4 addresses DDS may use on this host (empty: the profile's choice)",
                   [](O& o) -> std::vector<std::string>& { return o.interfaces; }, ipv4_item),
        P::list<O>("initial_peers", "IPv4 addresses of other hosts, for unicast discovery",
                   [](O& o) -> std::vector<std::string>& { return o.initial_peers; }, ipv4_item),
        P::text<O>("discovery_server", "ADDR:PORT of a `fastdds discovery` server to be a client of (empty: none)",
                   [](O& o) -> std::string& { return o.discovery_server; },
                   [](const std::string& v) {
                     if (v.empty()) return;
                     try {
                       split_server(v, "discovery_server");
                     } catch (const std::invalid_argument&) {
                       throw std::invalid_argument("not ADDR:PORT (e.g. 10.200.0.3:11811)");
                     }
                   }),
        P::integer<O, int>("discovery_server_id", 0, 255, "", "that server's `-i`",
                           [](O& o) -> int& { return o.discovery_server_id; }),
        P::text<O>("security_dir", "DDS Security certificates and documents (relative: to the YAML file's folder)",
                   [](O& o) -> std::string& { return o.security_dir; }),
        P::choice<O, DdsLogLevel>(
            "log_level",
            {{"error", DdsLogLevel::kError}, {"warning", DdsLogLevel::kWarning}, {"info", DdsLogLevel::kInfo}},
            "how much of Fast DDS's own log reaches stderr", [](O& o) -> DdsLogLevel& { return o.log_level; }),
    };
    // true | false | auto: an optional<bool>, declared by hand.
    P::Parameter<O> announce;
    announce.path = "announce_identity";
    announce.kind = P::Kind::kChoice;
    announce.choices = {"true", "false", "auto"};
    announce.help = "name, host and pid in the plaintext discovery announcement (auto: unless secure)";
    announce.get_choice = [](const O& o) {
      return o.announce_identity ? (*o.announce_identity ? "true" : "false") : std::string("auto");
    };
    announce.set_choice = [](O& o, const std::string& v) {
      if (v == "auto") {
        o.announce_identity.reset();
      } else if (v == "true" || v == "false") {
        o.announce_identity = v == "true";
      } else {
        throw std::invalid_argument("not one of the choices");
      }
    };
    t.push_back(announce);
    return t;
  }();
  return table;
}

void check_ipv4(const std::string& text, const std::string& what) {
  in_addr address{};
  if (inet_pton(AF_INET, text.c_str(), &address) != 1) {
    throw std::invalid_argument(what + ": '" + text + "' is not an IPv4 address");
  }
}

std::pair<std::string, std::uint16_t> split_server(const std::string& text, const std::string& what) {
  const auto colon = text.rfind(':');
  const std::string port_text = colon == std::string::npos ? "" : text.substr(colon + 1);
  if (colon == std::string::npos || port_text.empty() || port_text.size() > 5 ||
      port_text.find_first_not_of("0123456789") != std::string::npos || std::stoul(port_text) == 0 ||
      std::stoul(port_text) > 65535) {
    throw std::invalid_argument(what + ": '" + text + "' is not ADDR:PORT (e.g. 10.200.0.3:11811)");
  }
  check_ipv4(text.substr(0, colon), what);
  return {text.substr(0, colon), static_cast<std::uint16_t>(std::stoul(port_text))};
}

DdsOptions read_dds_options(config::YamlReader& reader, const std::string& config_dir) {
  DdsOptions o;
  config::read_parameters(reader, dds_parameters(), o);
  reader.finish();
  o.profiles_file = o.profiles_file.empty() ? default_profiles_file() : resolve(o.profiles_file, config_dir);
  o.security_dir = resolve(o.security_dir, config_dir);
  return o;
}

DdsOptions read_dds_section(config::YamlReader& root, const std::string& config_dir, const DdsOptions& fallback) {
  if (!root.has("dds")) {
    DdsOptions o = fallback;
    if (o.profiles_file.empty()) o.profiles_file = default_profiles_file();
    return o;
  }
  config::YamlReader dds = root.child("dds");
  return read_dds_options(dds, config_dir);
}

std::string default_profiles_file() {
  // A program of the build tree uses its checkout's file; an installed one the
  // package's (/etc/pixyslam/dds/profiles.xml, the file the services use).
  std::error_code error;
  const std::string exe = std::filesystem::read_symlink("/proc/self/exe", error).string();
  const bool in_build_tree = !error && exe.rfind(std::string(PIXYSLAM_BUILD_TREE) + "/", 0) == 0;
  if (!in_build_tree && std::filesystem::exists(PIXYSLAM_INSTALLED_PROFILES_FILE, error)) {
    return PIXYSLAM_INSTALLED_PROFILES_FILE;
  }
  return PIXYSLAM_SOURCE_PROFILES_FILE;
}

DdsOptions read_dds_options_file(const std::string& yaml_path, const std::string& default_profiles_file) {
  if (yaml_path.empty()) {
    DdsOptions o;
    o.profiles_file = default_profiles_file;
    return o;
  }
  config::YamlReader root = config::YamlReader::from_file(yaml_path);
  config::YamlReader dds = root.child("dds");
  return read_dds_options(dds, std::filesystem::path(yaml_path).parent_path().string());
}

void apply_environment(DdsOptions& o, const std::function<const char*(const char*)>& getenv) {
  for (const EnvironmentKey& key : kEnvironment) {
    const char* v = getenv(key.variable);
    if (v == nullptr || *v == '\0') continue;
    std::string text = v;
    if (std::string(key.path) == "type_information" && (text == "1" || text == "0")) {
      text = text == "1" ? "true" : "false";
    }
    try {
      parameters::set_from_text(o, dds_parameters(), "dds", key.path, text);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(key.variable) + "='" + v + "': " + e.what());
    }
  }
}

void resolve_settings(DdsOptions& o, const std::vector<std::string>& overrides) {
  try {
    apply_environment(o, [](const char* n) { return std::getenv(n); });
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(std::string("environment: ") + e.what());
  }
  for (const std::string& assignment : overrides) {
    try {
      parameters::apply_override(o, dds_parameters(), "dds", assignment);
    } catch (const std::invalid_argument& e) {
      throw config::ConfigError(std::string("command line: ") + e.what());
    }
  }
}

std::string domain_override(const std::string& value) { return "dds.domain_id=" + value; }

std::string to_yaml(const DdsOptions& o) { return parameters::to_yaml(o, dds_parameters(), "dds"); }

bool announces_identity(const DdsOptions& options, bool secure) { return options.announce_identity.value_or(!secure); }

}  // namespace pixyslam::dds
