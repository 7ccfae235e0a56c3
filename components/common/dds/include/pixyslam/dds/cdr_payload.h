#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/dds/topics.h"

namespace eprosima::fastdds::dds {
class TopicDataType;
}  // namespace eprosima::fastdds::dds

namespace pixyslam::dds {

// CDR payloads of the project's messages, exactly as a Fast DDS 2.9 DataWriter
// puts them on the wire: the 4-byte encapsulation header (0x00 0x01 0x00 0x00
// = CDR_LE on this host, options 0) followed by the plain CDR of the sample,
// produced by the generated PubSubType::serialize (what DataWriter::write
// calls). This is also how the rosbag2 MCAP storage and Fast DDS recorders
// store samples with message_encoding "cdr". A reader strips the first 4 bytes
// to get the plain CDR stream (little-endian when byte 1 is 0x01).
//
// The TopicDataType overloads are not thread-safe for one `type` object (the
// generated types keep scratch buffers): use one per thread.

// Serializes `sample` (a pointer to the type's message) with `type`. Throws
// std::runtime_error if it does not fit the type's bounds.
std::vector<std::uint8_t> serialize_payload(eprosima::fastdds::dds::TopicDataType& type, const void* sample);
// Deserializes a whole payload (encapsulation header included) into `sample`.
// Returns false with `error` set if it is not a valid payload of that type.
bool deserialize_payload(eprosima::fastdds::dds::TopicDataType& type, const std::uint8_t* data,
                         std::size_t size, void* sample, std::string& error);

template <class Message>
std::vector<std::uint8_t> to_cdr(const Message& message) {
  typename dds::MessageTraits<Message>::PubSubType type;
  return serialize_payload(type, &message);
}

template <class Message>
bool from_cdr(const std::vector<std::uint8_t>& bytes, Message& message, std::string& error) {
  typename dds::MessageTraits<Message>::PubSubType type;
  return deserialize_payload(type, bytes.data(), bytes.size(), &message, error);
}

// One topic the logger can record: DDS topic name, DDS type name (also the
// MCAP schema name, e.g. "pixyslam::msg::Odometry") and IDL file stem.
struct TopicInfo {
  std::string topic;
  std::string type_name;
  std::string idl_stem;
};

// Every topic of the system (dds/topics.h), in a fixed order.
const std::vector<TopicInfo>& known_topics();
// Their names, in the same order.
const std::vector<std::string>& known_topic_names();
// nullptr if `topic` is not one of them.
const TopicInfo* find_topic(std::string_view topic);

// The header of a decoded sample.
struct SampleHeader {
  std::uint64_t stamp_ns = 0;
  std::uint64_t seq = 0;
  std::string robot_id;
  std::string frame_id;
};

// Decodes a payload of DDS type `type_name` (one of known_topics()) with the
// project's generated type and returns its header. Strict: the payload must
// be exactly what serializing the decoded sample again gives (up to 3 bytes of
// trailing alignment padding and the encapsulation options), so truncated,
// padded-with-garbage or mistyped payloads are rejected. Returns false with
// `error` set otherwise (also for an unknown type name). Thread-safe.
bool decode_header(std::string_view type_name, const std::uint8_t* data, std::size_t size,
                   SampleHeader& header, std::string& error);

}  // namespace pixyslam::dds
