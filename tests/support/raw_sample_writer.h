#pragma once

// A DDS writer of raw payload bytes (encapsulation header included) on one of
// the system's topics, under that topic's type name: what a broken or hostile
// participant on the domain can send. For tests only.

#include <cstdint>
#include <cstring>
#include <functional>
#include <thread>
#include <stdexcept>
#include <string>
#include <vector>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "pixyslam/dds/endpoints.h"

namespace pixyslam::test_support {

class RawPubSubType : public eprosima::fastdds::dds::TopicDataType {
 public:
  RawPubSubType(const std::string& type_name, std::uint32_t max_size) {
    setName(type_name.c_str());
    m_typeSize = max_size;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto& bytes = *static_cast<const std::vector<std::uint8_t>*>(data);
    if (bytes.size() > payload->max_size) return false;
    if (!bytes.empty()) std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<std::uint32_t>(bytes.size());
    payload->encapsulation = bytes.size() >= 2 ? bytes[1] : 0;
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t*, void*) override { return false; }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<std::vector<std::uint8_t>*>(data)->size()); };
  }
  void* createData() override { return new std::vector<std::uint8_t>(); }
  void deleteData(void* data) override { delete static_cast<std::vector<std::uint8_t>*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

// Writes raw payloads on Message's topic with the topic's writer profile. The
// participant must not have created that topic with the real type.
template <class Message>
class RawSampleWriter {
 public:
  explicit RawSampleWriter(dds::Participant& participant) : participant_(participant) {
    const std::string topic(dds::MessageTraits<Message>::topic);
    typename dds::MessageTraits<Message>::PubSubType real;
    writer_ = participant.publisher().create_datawriter_with_profile(
        &participant.topic(topic, eprosima::fastdds::dds::TypeSupport(new RawPubSubType(real.getName(), 1 << 20))),
        topic);
    if (writer_ == nullptr) throw std::runtime_error("cannot create a raw writer for '" + topic + "'");
  }
  ~RawSampleWriter() { participant_.publisher().delete_datawriter(writer_); }
  RawSampleWriter(const RawSampleWriter&) = delete;
  RawSampleWriter& operator=(const RawSampleWriter&) = delete;

  bool write(std::vector<std::uint8_t> bytes) { return writer_->write(&bytes); }
  bool wait_for_readers(int count, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    for (;;) {
      writer_->get_publication_matched_status(status);
      if (status.current_count >= count) return true;
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

 private:
  dds::Participant& participant_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
};

// The largest payload a sample of Message can have (its IDL bounds).
template <class Message>
std::uint32_t max_payload_size() {
  return typename dds::MessageTraits<Message>::PubSubType().m_typeSize;
}

// `message` as the bytes DataWriter::write puts on the wire.
template <class Message>
std::vector<std::uint8_t> wire_bytes(Message message) {
  typename dds::MessageTraits<Message>::PubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&message)());
  if (!type.serialize(&message, &payload)) throw std::runtime_error("cannot serialise the test sample");
  return std::vector<std::uint8_t>(payload.data, payload.data + payload.length);
}

// Payloads of Message that no reader can decode, one of each kind the network
// can deliver: `valid` is a correct serialised sample to damage.
// Malformed variants of a valid payload; with `max_size` (max_payload_size<M>())
// also the valid one padded past it: well-formed, but larger than any sample
// of the type.
inline std::vector<std::vector<std::uint8_t>> malformed_payloads(const std::vector<std::uint8_t>& valid,
                                                                 std::uint32_t max_size = 0) {
  std::vector<std::vector<std::uint8_t>> out;
  if (max_size > 0) {
    std::vector<std::uint8_t> oversized = valid;
    oversized.resize(std::size_t{max_size} + 64, 0);
    out.push_back(oversized);
  }
  std::vector<std::uint8_t> bad_encapsulation = valid;
  bad_encapsulation[0] = 0x07;  // first encapsulation byte must be 0
  out.push_back(bad_encapsulation);
  out.push_back(std::vector<std::uint8_t>(valid.begin(), valid.begin() + 6));  // cut short
  std::vector<std::uint8_t> huge_string = valid;
  // MessageHeader: stamp_ns, seq, then robot_id's length (bytes 20-23).
  for (std::size_t i = 4 + 16; i < huge_string.size() && i < 4 + 20; ++i) huge_string[i] = 0xff;
  out.push_back(huge_string);
  out.push_back({0x00, 0x01});  // encapsulation header only, half of it
  return out;
}

}  // namespace pixyslam::test_support
