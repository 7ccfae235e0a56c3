#include "pixyslam/dds/participant.h"

#include "pixyslam/dds/topics.h"

#include <cerrno>
#include <chrono>
#include <mutex>
#include <stdexcept>

#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

namespace pixyslam::dds {

namespace fdds = eprosima::fastdds::dds;

DdsOptions read_dds_options(config::YamlReader& reader, const std::string& config_dir) {
  DdsOptions o;
  o.domain_id = static_cast<int>(reader.integer("domain_id", 0, 232, o.domain_id));
  o.profiles_file = reader.text("profiles_file", o.profiles_file);
  o.participant_profile = reader.text("participant_profile", o.participant_profile);
  o.robot_id = reader.text("robot_id", o.robot_id);
  if (o.robot_id.empty()) reader.fail("robot_id", "must not be empty");
  o.type_information = reader.boolean("type_information", o.type_information);
  reader.finish();
  if (!o.profiles_file.empty() && o.profiles_file.front() != '/' && !config_dir.empty()) {
    o.profiles_file = config_dir + "/" + o.profiles_file;
  }
  return o;
}

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
  });
}

}  // namespace

Participant::Participant(const DdsOptions& options, const std::string& name) : options_(options) {
  register_all_type_objects();
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (!options.profiles_file.empty() &&
      factory->load_XML_profiles_file(options.profiles_file) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("cannot load Fast DDS profiles file '" + options.profiles_file +
                             "' (missing or not valid XML profiles)");
  }
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.participant_profile, qos) !=
      ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("no participant profile '" + options.participant_profile + "' in '" +
                             (options.profiles_file.empty() ? std::string("(no profiles file)")
                                                            : options.profiles_file) +
                             "'");
  }
  qos.name(name);
  // Who this is, for inspection tools (pixyslam_spy participants): sent in discovery.
  char host[256] = {};
  if (gethostname(host, sizeof(host) - 1) != 0) host[0] = '\0';
  const std::string process = program_invocation_short_name;  // glibc: argv[0] without folder
  qos.properties().properties().emplace_back("pixyslam.host", host, true);
  qos.properties().properties().emplace_back("pixyslam.pid", std::to_string(getpid()), true);
  qos.properties().properties().emplace_back("pixyslam.process", process, true);
  participant_ = factory->create_participant(options.domain_id, qos);
  if (participant_ == nullptr) {
    throw std::runtime_error("cannot create DDS participant '" + name + "' on domain " +
                             std::to_string(options.domain_id));
  }
  publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
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
