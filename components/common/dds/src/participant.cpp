#include "pixyslam/dds/participant.h"

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/topics.h"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

namespace pixyslam::dds {

namespace fdds = eprosima::fastdds::dds;

namespace {

// Every type of the system is known to the TypeObject factory before any
// participant exists: Fast DDS 2.9 crashes in discovery when it meets a remote
// endpoint of an unregistered type holding a sequence of structs.
void register_all_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] {
    MessageTraits<msg::Odometry>::register_type_object();
    MessageTraits<msg::LandmarkObservation>::register_type_object();
    MessageTraits<msg::MapState>::register_type_object();
    MessageTraits<msg::GroundTruth>::register_type_object();
    MessageTraits<msg::Diagnostics>::register_type_object();
    MessageTraits<msg::OptimisedMap>::register_type_object();
    MessageTraits<msg::RobotSighting>::register_type_object();
    MessageTraits<msg::FleetMap>::register_type_object();
  });
}

}  // namespace

namespace {

eprosima::fastrtps::rtps::Locator_t udp_locator(const std::string& address, std::uint16_t port) {
  eprosima::fastrtps::rtps::Locator_t locator;
  locator.kind = LOCATOR_KIND_UDPv4;
  eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, address);
  locator.port = port;
  return locator;
}

// The deployment settings on top of the XML participant profile. An
// `observer` (watching discovery) of a discovery server is a SUPER_CLIENT: a
// plain client only learns the participants its own endpoints match.
void apply_deployment(const DdsOptions& o, const std::string& name, bool observer, fdds::DomainParticipantQos& qos) {
  if (!o.interfaces.empty()) {
    // One UDPv4 transport limited to these addresses (replaces the profile's).
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList = o.interfaces;
    udp->maxInitialPeersRange = 32;
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports = {udp};
  }
  auto& builtin = qos.wire_protocol().builtin;
  for (const std::string& peer : o.initial_peers) builtin.initialPeersList.push_back(udp_locator(peer, 0));
  if (!o.discovery_server.empty()) {
    const auto [address, port] = split_server(o.discovery_server, "discovery_server");
    eprosima::fastrtps::rtps::RemoteServerAttributes server;
    if (!eprosima::fastrtps::rtps::get_server_client_default_guidPrefix(o.discovery_server_id, server.guidPrefix)) {
      throw std::invalid_argument("discovery_server_id " + std::to_string(o.discovery_server_id) + " is not valid");
    }
    server.metatrafficUnicastLocatorList.push_back(udp_locator(address, port));
    builtin.discovery_config.discoveryProtocol = observer ? eprosima::fastrtps::rtps::DiscoveryProtocol_t::SUPER_CLIENT
                                                          : eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
    builtin.discovery_config.m_DiscoveryServers.push_back(server);
  }
  auto& properties = qos.properties().properties();
  const bool secure_profile = std::any_of(properties.begin(), properties.end(), [](const auto& p) {
    return p.name() == "dds.sec.auth.plugin";
  });
  if (secure_profile && o.security_dir.empty()) {
    throw std::invalid_argument("participant profile '" + o.participant_profile +
                                "' uses DDS Security: set dds.security_dir (or PIXYSLAM_DDS_SECURITY_DIR)");
  }
  if (!o.security_dir.empty()) {
    const std::string dir = "file://" + std::filesystem::absolute(o.security_dir).string() + "/";
    for (const std::string& file : std::vector<std::string>{"ca.cert.pem", "governance.p7s", "permissions.p7s",
                                                            name + ".cert.pem",
                                   name + ".key.pem"}) {
      if (!std::ifstream(o.security_dir + "/" + file).good()) {
        throw std::runtime_error("DDS security: cannot read '" + o.security_dir + "/" + file +
                                 "' (make them with scripts/make_dds_security.sh)");
      }
    }
    auto& p = properties;
    if (!secure_profile) {
      p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
      p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
      p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
    }
    p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", dir + "ca.cert.pem");
    p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", dir + name + ".cert.pem");
    p.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", dir + name + ".key.pem");
    p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", dir + "ca.cert.pem");
    p.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", dir + "governance.p7s");
    p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", dir + "permissions.p7s");
  }
}

}  // namespace

fdds::DomainParticipant* create_participant(const DdsOptions& options, const std::string& name,
                                            fdds::DomainParticipantListener* listener) {
  register_all_type_objects();
  // Fast DDS's own log (dds.log_level).
  switch (options.log_level) {
    case DdsLogLevel::kError: fdds::Log::SetVerbosity(fdds::Log::Error); break;
    case DdsLogLevel::kWarning: fdds::Log::SetVerbosity(fdds::Log::Warning); break;
    case DdsLogLevel::kInfo: fdds::Log::SetVerbosity(fdds::Log::Info); break;
  }
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (!options.profiles_file.empty() &&
      factory->load_XML_profiles_file(options.profiles_file) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("cannot load Fast DDS profiles file '" + options.profiles_file +
                             "' (missing or not valid XML profiles)");
  }
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.participant_profile, qos) !=
      ReturnCode_t::RETCODE_OK) {
    // A setting, not a failure of the network: a config error (exit 2) naming where it comes from.
    throw config::ConfigError("dds.participant_profile (or --set / PIXYSLAM_DDS_PROFILE): no participant profile '" +
                              options.participant_profile + "' in '" +
                              (options.profiles_file.empty() ? std::string("(no profiles file)")
                                                             : options.profiles_file) +
                              "'");
  }
  qos.name(name);
  apply_deployment(options, name, listener != nullptr, qos);
  const auto& properties = qos.properties().properties();
  const bool secure = std::any_of(properties.begin(), properties.end(),
                                  [](const auto& p) { return p.name() == "dds.sec.auth.plugin"; });
  if (announces_identity(options, secure)) {
    // Who this is, for inspection tools (pixyslam_spy participants): sent in discovery.
    char host[256] = {};
    if (gethostname(host, sizeof(host) - 1) != 0) host[0] = '\0';
    const std::string process = program_invocation_short_name;  // glibc: argv[0] without folder
    qos.properties().properties().emplace_back("pixyslam.host", host, true);
    qos.properties().properties().emplace_back("pixyslam.pid", std::to_string(getpid()), true);
    qos.properties().properties().emplace_back("pixyslam.process", process, true);
  } else {
    qos.name("pixyslam");  // the role stays out of the plaintext announcement too
  }
  fdds::DomainParticipant* participant =
      factory->create_participant(options.domain_id, qos, listener,
                                  listener != nullptr ? fdds::StatusMask::none() : fdds::StatusMask::all());
  if (participant == nullptr) {
    throw std::runtime_error("cannot create DDS participant '" + name + "' on domain " +
                             std::to_string(options.domain_id) + " with profile '" + options.participant_profile +
                             "'" + (options.security_dir.empty() ? "" : " (check the DDS security files)"));
  }
  return participant;
}

Participant::Participant(const DdsOptions& options, const std::string& name) : options_(options) {
  participant_ = create_participant(options_, name, nullptr);
  publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    throw std::runtime_error("cannot create DDS publisher/subscriber for '" + name + "'");
  }
}

Participant::~Participant() {
  participant_->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

fdds::Topic& Participant::topic(const std::string& name, fdds::TypeSupport type) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = topics_.find(name);
  if (it != topics_.end()) return *it->second;
  type->auto_fill_type_information(options_.type_information);
  type->auto_fill_type_object(options_.type_information);
  if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK &&
      participant_->find_type(type.get_type_name()).empty()) {
    throw std::runtime_error("cannot register DDS type " + type.get_type_name());
  }
  fdds::Topic* topic = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) throw std::runtime_error("cannot create DDS topic '" + name + "'");
  topics_.emplace(name, topic);
  return *topic;
}

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace pixyslam::dds
