#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pixyslam/dds/participant.h"
#include "pixyslam/dds/topics.h"

namespace pixyslam::dds {

namespace detail {
template <class Message>
eprosima::fastdds::dds::TypeSupport type_support() {
  MessageTraits<Message>::register_type_object();
  return eprosima::fastdds::dds::TypeSupport(new typename MessageTraits<Message>::PubSubType());
}
}  // namespace detail

// Publishes Message on its topic with the XML data_writer profile named like
// the topic. publish() fills the header's seq (1, 2, ...) and robot_id; the
// caller sets stamp_ns and frame_id. Thread-safe (one writer, serialised).
template <class Message>
class Writer {
 public:
  explicit Writer(Participant& participant) : participant_(participant) {
    const std::string topic(MessageTraits<Message>::topic);
    writer_ = participant.publisher().create_datawriter_with_profile(
        &participant.topic(topic, detail::type_support<Message>()), topic);
    if (writer_ == nullptr) {
      throw std::runtime_error("cannot create DDS writer for '" + topic +
                               "': is there a data_writer profile of that name in '" +
                               participant.options().profiles_file + "'?");
    }
  }
  ~Writer() { participant_.publisher().delete_datawriter(writer_); }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Returns false if DDS refused the sample (e.g. history full and timed out).
  bool publish(Message& message) {
    message.header().seq(++seq_);
    message.header().robot_id(participant_.options().robot_id);
    const bool ok = writer_->write(&message);
    if (!ok) ++failures_;
    return ok;
  }

  // Publishes `message` with its header untouched (a log replay keeps the
  // recorded seq, stamp and robot id). Counts in published().
  bool publish_as_is(const Message& message) {
    ++seq_;
    const bool ok = writer_->write(const_cast<Message*>(&message));
    if (!ok) ++failures_;
    return ok;
  }

  std::uint64_t published() const { return seq_; }
  std::uint64_t failures() const { return failures_; }
  int matched_readers() const {
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    writer_->get_publication_matched_status(status);
    return status.current_count;
  }
  // Waits until at least `count` readers matched; false on timeout.
  bool wait_for_readers(int count, std::chrono::milliseconds timeout) const {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (matched_readers() < count) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
  }
  // Blocks until reliable readers acknowledged everything sent (or timeout).
  bool wait_for_acknowledgments(std::chrono::milliseconds timeout) {
    return writer_->wait_for_acknowledgments(
               eprosima::fastrtps::Duration_t(static_cast<double>(timeout.count()) / 1000.0)) ==
           ReturnCode_t::RETCODE_OK;
  }
  eprosima::fastdds::dds::DataWriter& native() { return *writer_; }

 private:
  Participant& participant_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::uint64_t seq_ = 0;
  std::uint64_t failures_ = 0;
};

// Receives Message from its topic (XML data_reader profile named like the
// topic) and calls `on_message` for every valid sample, on a Fast DDS thread:
// keep the callback short (enqueue). Counts samples, and per matched writer the
// header seq numbers skipped (lost messages).
template <class Message>
class Reader : private eprosima::fastdds::dds::DataReaderListener {
 public:
  using Callback = std::function<void(const Message&)>;

  Reader(Participant& participant, Callback on_message)
      : participant_(participant), on_message_(std::move(on_message)) {
    const std::string topic(MessageTraits<Message>::topic);
    reader_ = participant.subscriber().create_datareader_with_profile(
        &participant.topic(topic, detail::type_support<Message>()), topic, this);
    if (reader_ == nullptr) {
      throw std::runtime_error("cannot create DDS reader for '" + topic +
                               "': is there a data_reader profile of that name in '" +
                               participant.options().profiles_file + "'?");
    }
  }
  ~Reader() override {
    reader_->set_listener(nullptr);
    participant_.subscriber().delete_datareader(reader_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  std::uint64_t received() const { return received_.load(); }
  std::uint64_t lost() const { return lost_.load(); }  // seq numbers skipped
  int matched_writers() const {
    eprosima::fastdds::dds::SubscriptionMatchedStatus status;
    reader_->get_subscription_matched_status(status);
    return status.current_count;
  }
  eprosima::fastdds::dds::DataReader& native() { return *reader_; }

 private:
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const std::uint64_t seq = sample_.header().seq();
      std::uint64_t& last = last_seq_[info.publication_handle];
      if (seq > last + 1) lost_ += seq - last - 1;
      last = seq;
      ++received_;
      on_message_(sample_);
    }
  }

  Participant& participant_;
  Callback on_message_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  Message sample_;
  std::map<eprosima::fastdds::dds::InstanceHandle_t, std::uint64_t> last_seq_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
};

}  // namespace pixyslam::dds
