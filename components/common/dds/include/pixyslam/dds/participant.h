#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "pixyslam/config/yaml_reader.h"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class Publisher;
class Subscriber;
class Topic;
class TypeSupport;
}  // namespace eprosima::fastdds::dds

namespace pixyslam::dds {

// How a process joins the DDS system. QoS and transports come from a Fast DDS
// XML profiles file; the shipped default (config/dds/loopback.xml) keeps all
// traffic on 127.0.0.1.
struct DdsOptions {
  int domain_id = 0;
  std::string profiles_file;  // XML; relative paths are resolved against the YAML file's folder
  std::string participant_profile = "pixyslam_participant";
  std::string robot_id = "robot1";  // written into every message header
  bool type_information = true;     // announce XTypes type information (generic tools);
                                    // off for readers of other vendors (see README)
};

// Reads a `dds:` mapping (all keys optional) and calls reader.finish().
// `config_dir` resolves a relative profiles_file. Throws config::ConfigError.
DdsOptions read_dds_options(config::YamlReader& reader, const std::string& config_dir);

// A DomainParticipant created from the options' XML profile, with one publisher
// and one subscriber, and the topics created so far (one per name). The profile
// file is loaded before the participant (else Fast DDS silently ignores it).
// Throws std::runtime_error naming the file/profile on failure. Deleting it
// deletes every entity it created; readers and writers must be destroyed first.
// Thread-safe.
class Participant {
 public:
  explicit Participant(const DdsOptions& options, const std::string& name);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  const DdsOptions& options() const { return options_; }
  eprosima::fastdds::dds::DomainParticipant& native() { return *participant_; }
  eprosima::fastdds::dds::Publisher& publisher() { return *publisher_; }
  eprosima::fastdds::dds::Subscriber& subscriber() { return *subscriber_; }

  // The topic `name` of the type (registered on first use), created once.
  eprosima::fastdds::dds::Topic& topic(const std::string& name,
                                       eprosima::fastdds::dds::TypeSupport type);

 private:
  DdsOptions options_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::mutex mutex_;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
};

// Nanoseconds of CLOCK_REALTIME: the stamp clock of every message.
std::uint64_t now_ns();

}  // namespace pixyslam::dds
