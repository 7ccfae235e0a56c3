#include "pixyslam/logger_node/logger_node.h"

#include <chrono>
#include <exception>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pixyslam/dds/endpoints.h"
#include "pixyslam/logger_node/cdr_payload.h"

namespace pixyslam::logger_node {

namespace detail {

// A DDS reader of one topic feeding the node's queue.
class Subscription {
 public:
  virtual ~Subscription() = default;
  virtual std::uint64_t lost() const = 0;

 protected:
  static void deliver(LoggerNode& node, std::size_t topic, std::uint64_t seq, std::uint64_t stamp_ns,
                      std::vector<std::uint8_t>&& payload, bool serialized) {
    node.enqueue(topic, seq, stamp_ns, std::move(payload), serialized);
  }
};

template <class Message>
class TypedSubscription final : public Subscription {
 public:
  TypedSubscription(dds::Participant& participant, LoggerNode& node, std::size_t topic)
      : node_(node), topic_(topic), reader_(participant, [this](const Message& m) { on_sample(m); }) {}

  std::uint64_t lost() const override { return reader_.lost(); }

 private:
  // On a Fast DDS thread, one sample at a time per reader (type_ is ours alone).
  void on_sample(const Message& message) {
    std::vector<std::uint8_t> payload;
    bool serialized = true;
    try {
      payload = serialize_payload(type_, &message);
    } catch (...) {  // nothing may escape into Fast DDS
      serialized = false;
    }
    deliver(node_, topic_, message.header().seq(), message.header().stamp_ns(), std::move(payload), serialized);
  }

  LoggerNode& node_;
  std::size_t topic_;
  typename dds::MessageTraits<Message>::PubSubType type_;
  dds::Reader<Message> reader_;  // last: its callback uses the members above
};

}  // namespace detail

LoggerNode::LoggerNode(const LoggerOptions& options) : options_(options) {
  if (options_.topics.empty()) {
    for (const TopicInfo& t : known_topics()) options_.topics.push_back(t.topic);
  }
  logger::McapWriterOptions file;
  file.chunk_size_bytes = options_.chunk_size_bytes;
  file.compression = options_.compression;
  file.sync_after_chunk = options_.fsync;
  writer_.open(options_.output_file, file);

  const std::map<std::string, std::string> metadata_base = {
      {"robot_id", options_.dds.robot_id}, {"dds_domain_id", std::to_string(options_.dds.domain_id)}};
  for (const std::string& name : options_.topics) {
    const TopicInfo* info = find_topic(name);
    if (info == nullptr) throw std::invalid_argument("logger: unknown topic '" + name + "'");
    const std::uint16_t schema = writer_.add_schema(info->type_name, "omgidl", msg::idl_text(info->idl_stem));
    std::map<std::string, std::string> metadata = metadata_base;
    metadata["type_name"] = info->type_name;
    TopicCounters counters;
    counters.topic = name;
    counters.channel_id = writer_.add_channel(info->topic, "cdr", schema, metadata);
    topics_.push_back(counters);
  }

  participant_ = std::make_unique<dds::Participant>(options_.dds, "logger");
  for (std::size_t i = 0; i < options_.topics.size(); ++i) {
    const std::string& name = options_.topics[i];
    if (name == dds::kOdometryTopic) {
      subscribe<msg::Odometry>(i);
    } else if (name == dds::kLandmarkObservationTopic) {
      subscribe<msg::LandmarkObservation>(i);
    } else if (name == dds::kMapStateTopic) {
      subscribe<msg::MapState>(i);
    } else if (name == dds::kGroundTruthTopic) {
      subscribe<msg::GroundTruth>(i);
    } else {
      throw std::logic_error("logger: no reader for topic '" + name + "'");
    }
  }
}

template <class Message>
void LoggerNode::subscribe(std::size_t topic) {
  auto subscription = std::make_unique<detail::TypedSubscription<Message>>(*participant_, *this, topic);
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  subscriptions_.push_back(std::move(subscription));
}

LoggerNode::~LoggerNode() {
  try {
    stop();
  } catch (...) {  // a destructor must not throw; counters().error has the cause
  }
  participant_.reset();
}

void LoggerNode::start() {
  std::lock_guard<std::mutex> lock(lifecycle_mutex_);
  if (started_ || stopped_) return;
  started_ = true;
  thread_ = std::thread([this] { writer_loop(); });
}

void LoggerNode::stop() {
  std::lock_guard<std::mutex> lifecycle(lifecycle_mutex_);
  if (stopped_) return;
  stopped_ = true;
  {
    // Unsubscribe first: after this no callback runs, so the queue is final.
    std::lock_guard<std::mutex> lock(subscriptions_mutex_);
    std::vector<std::uint64_t> lost;
    for (const auto& s : subscriptions_) lost.push_back(s->lost());
    subscriptions_.clear();
    std::lock_guard<std::mutex> queue_lock(mutex_);
    for (std::size_t i = 0; i < lost.size(); ++i) topics_[i].seq_gaps = lost[i];
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    accepting_ = false;
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  } else {
    writer_loop();  // never started: write what is queued and close, here
  }
}

void LoggerNode::enqueue(std::size_t topic, std::uint64_t seq, std::uint64_t stamp_ns,
                         std::vector<std::uint8_t>&& payload, bool serialized) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    TopicCounters& t = topics_[topic];
    ++t.received;
    if (!serialized || !accepting_ || queued_bytes_ + payload.size() > options_.queue_max_bytes) {
      ++t.dropped;
      return;
    }
    queued_bytes_ += payload.size();
    ++queued_messages_;
    totals_.queue_peak_bytes = std::max(totals_.queue_peak_bytes, queued_bytes_);
    totals_.queue_peak_messages = std::max(totals_.queue_peak_messages, queued_messages_);
    // Taken under the lock so that log times never decrease in file order.
    queue_.push_back(Pending{topic, seq, dds::now_ns(), stamp_ns, std::move(payload)});
  }
  cv_.notify_one();
}

void LoggerNode::writer_loop() {
  using Clock = std::chrono::steady_clock;
  const bool timed = options_.flush_period_s > 0.0;
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.flush_period_s));
  auto next_flush = Clock::now() + period;
  std::deque<Pending> batch;
  for (;;) {
    bool stopping = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [this] { return !queue_.empty() || stopping_; };
      if (timed) {
        cv_.wait_until(lock, next_flush, ready);
      } else {
        cv_.wait(lock, ready);
      }
      batch.swap(queue_);
      stopping = stopping_;
    }
    write_batch(batch);
    if (timed && Clock::now() >= next_flush) {
      if (writer_.is_open()) {
        try {
          writer_.flush_chunk();
        } catch (const std::exception& e) {
          record_error(e.what());
        }
      }
      next_flush = Clock::now() + period;
    }
    if (stopping) break;
  }
  try {
    writer_.close();
  } catch (const std::exception& e) {
    record_error(e.what());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  totals_.file = writer_.counters();
}

void LoggerNode::write_batch(std::deque<Pending>& batch) {
  if (batch.empty()) return;
  std::vector<std::uint64_t> written(topics_.size(), 0);
  std::vector<std::uint64_t> dropped(topics_.size(), 0);
  std::size_t bytes = 0;
  std::string error;
  for (const Pending& p : batch) {
    bytes += p.payload.size();
    if (error.empty() && writer_.is_open()) {
      try {
        // channel_id is fixed after construction: no lock needed to read it.
        writer_.write_message(topics_[p.topic].channel_id, static_cast<std::uint32_t>(p.seq), p.log_time_ns,
                              p.publish_time_ns, p.payload);
        ++written[p.topic];
        continue;
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    ++dropped[p.topic];
  }
  const std::size_t count = batch.size();
  batch.clear();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < topics_.size(); ++i) {
      topics_[i].written += written[i];
      topics_[i].dropped += dropped[i];
    }
    queued_bytes_ -= bytes;
    queued_messages_ -= count;
    totals_.file = writer_.counters();
  }
  if (!error.empty()) record_error(error);
}

void LoggerNode::record_error(const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (totals_.error.empty()) totals_.error = what;
  accepting_ = false;
}

LoggerCounters LoggerNode::counters() const {
  std::vector<std::uint64_t> lost;
  {
    std::lock_guard<std::mutex> lock(subscriptions_mutex_);
    for (const auto& s : subscriptions_) lost.push_back(s->lost());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  LoggerCounters c = totals_;
  c.topics = topics_;
  for (std::size_t i = 0; i < lost.size() && i < c.topics.size(); ++i) c.topics[i].seq_gaps = lost[i];
  return c;
}

bool LoggerNode::failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !totals_.error.empty();
}

std::string LoggerNode::counters_text() const {
  const LoggerCounters c = counters();
  std::ostringstream os;
  for (const TopicCounters& t : c.topics) {
    os << t.topic << ": received " << t.received << ", written " << t.written << ", dropped " << t.dropped
       << ", seq gaps " << t.seq_gaps << "\n";
  }
  return os.str();
}

}  // namespace pixyslam::logger_node
