#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "pixyslam/dds/topics.h"

namespace pixyslam::dds {

// The generated TopicDataType of Message, with a deserialize() that never
// throws: any participant on the domain can send any bytes, and an exception
// out of Fast CDR (bad encapsulation, a length past the payload, bad_alloc for
// a huge sequence) would leave Fast DDS's take() and abort the process. A
// sample that does not decode is counted and reported as not deserialisable
// (false), so Fast DDS drops it; so is one larger than the type's largest
// sample (every sequence at its IDL bound, 255 bytes a string: no writer of
// the system sends more), which decodes but would make a reader keep what a
// sender chose (a 1 MB frame_id in each of thousands of queued samples).
// Every reader of the system decodes through this type (type_support() below);
// so do the log tools.
template <class Message>
class GuardedPubSubType : public MessageTraits<Message>::PubSubType {
 public:
  using Base = typename MessageTraits<Message>::PubSubType;

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    bool ok = false;
    try {
      ok = payload != nullptr && payload->data != nullptr && payload->length >= 4 &&
           (this->m_typeSize == 0 || payload->length <= this->m_typeSize) && Base::deserialize(payload, data);
    } catch (...) {
      ok = false;
    }
    if (!ok) malformed_->fetch_add(1, std::memory_order_relaxed);
    return ok;
  }

  // Samples that did not decode since this type was made (shared by copies).
  std::uint64_t malformed() const { return malformed_->load(std::memory_order_relaxed); }

 private:
  std::shared_ptr<std::atomic<std::uint64_t>> malformed_ = std::make_shared<std::atomic<std::uint64_t>>(0);
};

}  // namespace pixyslam::dds
