#pragma once

#include <algorithm>
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

#include "pixyslam/dds/guarded_type.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/dds/topics.h"

namespace pixyslam::dds {

namespace detail {
template <class Message>
eprosima::fastdds::dds::TypeSupport type_support() {
  MessageTraits<Message>::register_type_object();
  return eprosima::fastdds::dds::TypeSupport(new GuardedPubSubType<Message>());
}
}  // namespace detail

// Per-writer sequence accounting that no writer can poison: a gap larger than
// the writer could have published since its previous sample (at most
// kMaxRateHz, plus kSlack) is a jump (a replayed or hostile writer), counted
// once, not as millions of lost messages; so is a seq that goes back (one
// writer numbers 1, 2, ...; a restarted process is a new writer). Not
// thread-safe (one per reader listener).
class SeqTracker {
 public:
  static constexpr double kMaxRateHz = 10000.0;
  static constexpr std::uint64_t kSlack = 1000;

  struct Result {
    std::uint64_t lost = 0;
    bool jump = false;
  };
  Result update(std::uint64_t seq, double elapsed_s) {
    Result r;
    if (seq < last_) r.jump = true;
    if (seq > last_ && seq - last_ > 1) {
      const std::uint64_t gap = seq - last_ - 1;
      const double plausible = kMaxRateHz * std::max(0.0, elapsed_s) + static_cast<double>(kSlack);
      if (static_cast<double>(gap) > plausible) {
        r.jump = true;
      } else {
        r.lost = gap;
      }
    }
    last_ = seq;
    return r;
  }

 private:
  std::uint64_t last_ = 0;
};

// Publishes Message on its topic with the XML data_writer profile named like
// the topic. publish() fills the header's seq (1, 2, ...) and robot_id; the
// caller sets stamp_ns and frame_id. Thread-safe (one writer, serialised).
template <class Message>
class Writer {
 public:
  // `robot_id`: written into each header by publish() ("" = the participant's
  // dds.robot_id; a process publishing for several robots names each).
  explicit Writer(Participant& participant, std::string robot_id = "")
      : participant_(participant),
        robot_id_(robot_id.empty() ? participant.options().robot_id : std::move(robot_id)) {
    const std::string topic(MessageTraits<Message>::topic);
    writer_ = participant.publisher().create_datawriter_with_profile(
        &participant.topic(topic, detail::type_support<Message>()), topic);
    if (writer_ == nullptr) {
      throw std::runtime_error("cannot create DDS writer for '" + topic +
                               "': is there a data_writer profile of that name in '" +
                               participant.options().profiles_file + "'?");
    }
  }
  // The last samples reach the readers that matched: a process that stops right
  // after publishing (the estimator's last MapStates before the logger stops)
  // waits up to kFinalAckTimeout for their acknowledgement before the writer
  // goes (best-effort writers and writers without readers return at once).
  ~Writer() {
    if (seq_ > 0 && matched_readers() > 0) wait_for_acknowledgments(kFinalAckTimeout);
    participant_.publisher().delete_datawriter(writer_);
  }
  static constexpr std::chrono::milliseconds kFinalAckTimeout{500};
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Returns false if DDS refused the sample (e.g. history full and timed out).
  bool publish(Message& message) {
    message.header().seq(++seq_);
    message.header().robot_id(robot_id_);
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
  std::string robot_id_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::uint64_t seq_ = 0;
  std::uint64_t failures_ = 0;
};

// Receives Message from its topic (XML data_reader profile named like the
// topic) and calls `on_message` for every valid sample, on a Fast DDS thread:
// keep the callback short (enqueue). Counts samples, per matched writer the
// header seq numbers skipped (lost messages) and implausible jumps
// (SeqTracker), and samples that did not decode (GuardedPubSubType). No
// exception leaves the listener: one thrown by the callback is counted in
// callback_errors() and the sample dropped.
template <class Message>
class Reader : private eprosima::fastdds::dds::DataReaderListener {
 public:
  using Callback = std::function<void(const Message&)>;

  // `robot_id` non-empty: only samples whose header.robot_id is that reach the
  // callback and the counts; the others are dropped and counted in
  // other_robot(). (Not a DDS content filter: that would drop malformed
  // samples uncounted, before they decode.)
  Reader(Participant& participant, Callback on_message, std::string robot_id = "")
      : participant_(participant), on_message_(std::move(on_message)), robot_id_(std::move(robot_id)) {
    const std::string topic(MessageTraits<Message>::topic);
    reader_ = participant.subscriber().create_datareader_with_profile(
        &participant.topic(topic, detail::type_support<Message>()), topic, this);
    if (reader_ == nullptr) {
      throw std::runtime_error("cannot create DDS reader for '" + topic +
                               "': is there a data_reader profile of that name in '" +
                               participant.options().profiles_file + "'?");
    }
    type_ = reader_->type();
  }
  ~Reader() override {
    reader_->set_listener(nullptr);
    participant_.subscriber().delete_datareader(reader_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  std::uint64_t received() const { return received_.load(); }
  std::uint64_t lost() const { return lost_.load(); }  // seq numbers skipped
  std::uint64_t seq_jumps() const { return seq_jumps_.load(); }
  // Samples of this topic that did not decode, in this participant.
  std::uint64_t malformed() const {
    const auto* guarded = dynamic_cast<const GuardedPubSubType<Message>*>(type_.get());
    return guarded != nullptr ? guarded->malformed() : 0;
  }
  std::uint64_t callback_errors() const { return callback_errors_.load(); }
  std::uint64_t other_robot() const { return other_robot_.load(); }
  int matched_writers() const {
    eprosima::fastdds::dds::SubscriptionMatchedStatus status;
    reader_->get_subscription_matched_status(status);
    return status.current_count;
  }
  eprosima::fastdds::dds::DataReader& native() { return *reader_; }

 private:
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    for (;;) {
      try {
        if (reader->take_next_sample(&sample_, &info) != ReturnCode_t::RETCODE_OK) return;
      } catch (...) {  // the guarded type does not throw; this is the last line
        ++callback_errors_;
        return;
      }
      if (!info.valid_data) continue;
      if (!robot_id_.empty() && sample_.header().robot_id() != robot_id_) {
        ++other_robot_;
        continue;
      }
      const auto now = std::chrono::steady_clock::now();
      // Writers that come and go are not forgotten one by one: past a bound
      // the accounting starts again (a few seq gaps go uncounted).
      if (writers_.size() >= kMaxWriters && writers_.count(info.publication_handle) == 0) writers_.clear();
      WriterSeq& writer = writers_[info.publication_handle];
      if (!writer.seen) {
        writer.seen = true;
        writer.last = created_;
      }
      const SeqTracker::Result seq =
          writer.seq.update(sample_.header().seq(), std::chrono::duration<double>(now - writer.last).count());
      writer.last = now;
      lost_ += seq.lost;
      if (seq.jump) ++seq_jumps_;
      ++received_;
      try {
        on_message_(sample_);
      } catch (...) {
        ++callback_errors_;
      }
    }
  }

  static constexpr std::size_t kMaxWriters = 1024;
  struct WriterSeq {
    bool seen = false;
    std::chrono::steady_clock::time_point last;
    SeqTracker seq;
  };

  Participant& participant_;
  Callback on_message_;
  std::string robot_id_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  eprosima::fastdds::dds::TypeSupport type_;
  Message sample_;
  const std::chrono::steady_clock::time_point created_ = std::chrono::steady_clock::now();
  std::map<eprosima::fastdds::dds::InstanceHandle_t, WriterSeq> writers_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<std::uint64_t> seq_jumps_{0};
  std::atomic<std::uint64_t> callback_errors_{0};
  std::atomic<std::uint64_t> other_robot_{0};
};

}  // namespace pixyslam::dds
