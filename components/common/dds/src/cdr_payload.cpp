#include "pixyslam/dds/cdr_payload.h"

#include <algorithm>
#include <cstring>
#include <exception>
#include <stdexcept>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

namespace pixyslam::dds {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::SerializedPayload_t;

std::vector<std::uint8_t> serialize_payload(fdds::TopicDataType& type, const void* sample) {
  // The generated code takes void*, but only reads the sample.
  void* data = const_cast<void*>(sample);
  SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload)) {
    throw std::runtime_error(std::string("cannot serialize a ") + type.getName() +
                             " sample (does it exceed the IDL bounds?)");
  }
  return std::vector<std::uint8_t>(payload.data, payload.data + payload.length);
}

bool deserialize_payload(fdds::TopicDataType& type, const std::uint8_t* data, std::size_t size,
                         void* sample, std::string& error) {
  if (size < 4) {
    error = "payload of " + std::to_string(size) + " bytes has no encapsulation header";
    return false;
  }
  if (data[0] != 0x00 || (data[1] != 0x00 && data[1] != 0x01)) {
    error = "encapsulation is not plain CDR (CDR_BE/CDR_LE)";
    return false;
  }
  SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  try {
    if (!type.deserialize(&payload, sample)) {
      error = "CDR ends early (payload of " + std::to_string(size) + " bytes cut short?)";
      return false;
    }
  } catch (const std::exception& e) {
    error = std::string("CDR not valid: ") + e.what();
    return false;
  } catch (...) {
    error = "CDR not valid";
    return false;
  }
  return true;
}

namespace {

template <class Message>
TopicInfo topic_info() {
  typename dds::MessageTraits<Message>::PubSubType type;
  return {std::string(dds::MessageTraits<Message>::topic), type.getName(),
          std::string(dds::MessageTraits<Message>::idl_stem)};
}

// Decode, then check that serializing the result again gives the same bytes.
template <class Message>
bool decode_strict(const std::uint8_t* data, std::size_t size, SampleHeader& header, std::string& error) {
  typename dds::MessageTraits<Message>::PubSubType type;
  Message message;
  if (!deserialize_payload(type, data, size, &message, error)) return false;
  std::vector<std::uint8_t> again;
  try {
    again = serialize_payload(type, &message);
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
  const bool big_endian = data[1] == 0x00;
  const std::size_t extra = size >= again.size() ? size - again.size() : 0;
  if (big_endian) {
    // This host writes little-endian: only the length can be compared.
    if (size < again.size() || extra > 3) {
      error = "payload length " + std::to_string(size) + " does not match its content (" +
              std::to_string(again.size()) + " bytes)";
      return false;
    }
  } else if (size < again.size() || extra > 3 ||
             !std::equal(again.begin() + 4, again.end(), data + 4) ||
             !std::all_of(data + again.size(), data + size, [](std::uint8_t b) { return b == 0; })) {
    error = "payload of " + std::to_string(size) + " bytes is not exactly one " +
            std::string(type.getName()) + " (re-encoded: " + std::to_string(again.size()) + " bytes)";
    return false;
  }
  header.stamp_ns = message.header().stamp_ns();
  header.seq = message.header().seq();
  header.robot_id = message.header().robot_id();
  header.frame_id = message.header().frame_id();
  return true;
}

// Every message type with its decoder, in the order of known_topics().
struct Entry {
  TopicInfo info;
  bool (*decode)(const std::uint8_t*, std::size_t, SampleHeader&, std::string&);
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = {
      {topic_info<msg::Odometry>(), &decode_strict<msg::Odometry>},
      {topic_info<msg::LandmarkObservation>(), &decode_strict<msg::LandmarkObservation>},
      {topic_info<msg::MapState>(), &decode_strict<msg::MapState>},
      {topic_info<msg::GroundTruth>(), &decode_strict<msg::GroundTruth>},
      {topic_info<msg::Diagnostics>(), &decode_strict<msg::Diagnostics>},
      {topic_info<msg::OptimisedMap>(), &decode_strict<msg::OptimisedMap>},
      {topic_info<msg::RobotSighting>(), &decode_strict<msg::RobotSighting>},
      {topic_info<msg::FleetMap>(), &decode_strict<msg::FleetMap>}};
  return table;
}

}  // namespace

const std::vector<TopicInfo>& known_topics() {
  static const std::vector<TopicInfo> topics = [] {
    std::vector<TopicInfo> out;
    for (const Entry& e : entries()) out.push_back(e.info);
    return out;
  }();
  return topics;
}

const std::vector<std::string>& known_topic_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const TopicInfo& t : known_topics()) out.push_back(t.topic);
    return out;
  }();
  return names;
}

const TopicInfo* find_topic(std::string_view topic) {
  for (const TopicInfo& t : known_topics()) {
    if (t.topic == topic) return &t;
  }
  return nullptr;
}

bool decode_header(std::string_view type_name, const std::uint8_t* data, std::size_t size,
                   SampleHeader& header, std::string& error) {
  for (const Entry& e : entries()) {
    if (e.info.type_name == type_name) return e.decode(data, size, header, error);
  }
  error = "unknown type '" + std::string(type_name) + "'";
  return false;
}

}  // namespace pixyslam::dds
