#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/dds/dds_options.h"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantListener;
class Publisher;
class Subscriber;
class Topic;
class TypeSupport;
}  // namespace eprosima::fastdds::dds

namespace pixyslam::dds {

// Creates a DomainParticipant named `name` from the options' XML participant
// profile (loaded first), the environment overrides and the deployment
// settings, announcing pixyslam.host/pid/process properties for inspection
// unless announces_identity() says otherwise.
// `listener` (may be null) is attached from creation, for discovery callbacks
// only (a listener set afterwards misses the first announcements); with one,
// a discovery-server client is a super client that learns every participant
// (inspection, health), not only those its endpoints match. Throws
// std::runtime_error / std::invalid_argument naming the file, profile, setting.
eprosima::fastdds::dds::DomainParticipant* create_participant(const DdsOptions& options, const std::string& name,
                                                              eprosima::fastdds::dds::DomainParticipantListener* listener);

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
