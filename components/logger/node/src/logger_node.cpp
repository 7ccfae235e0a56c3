#include "pixyslam/logger_node/logger_node.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/topic_selection.h"

namespace pixyslam::logger_node {

namespace detail {

// A DDS reader of one topic feeding the node's queue.
class Subscription {
 public:
  virtual ~Subscription() = default;
  virtual ReaderCounts reader_counts() const = 0;

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

  ReaderCounts reader_counts() const override {
    return {reader_.lost(), reader_.malformed() + reader_.callback_errors(), reader_.seq_jumps()};
  }

 private:
  // On a Fast DDS thread, one sample at a time per reader (type_ is ours alone).
  void on_sample(const Message& message) {
    std::vector<std::uint8_t> payload;
    bool serialized = true;
    try {
      payload = dds::serialize_payload(type_, &message);
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
  const std::vector<std::string>& all = dds::known_topic_names();
  if (options_.topics.empty()) {
    options_.topics = all;
  } else {
    const dds::TopicSelection selection = dds::select_topics(options_.topics, all);
    if (!selection.error.empty()) {
      throw std::invalid_argument("logger: topics[" + std::to_string(selection.bad_pattern) + "] '" +
                                  options_.topics[selection.bad_pattern] + "': " + selection.error);
    }
    options_.topics = selection.topics;
  }
  for (const std::string& name : options_.topics) {
    const dds::TopicInfo* info = dds::find_topic(name);
    if (info == nullptr) throw std::invalid_argument("logger: unknown topic '" + name + "'");
    topic_infos_.push_back(info);
    TopicCounters counters;
    counters.topic = name;
    topics_.push_back(counters);
  }
  open_first_file();

  participant_ = std::make_unique<dds::Participant>(options_.dds, "logger");
  for (std::size_t i = 0; i < options_.topics.size(); ++i) {
    const std::string& name = options_.topics[i];
    if (!dds::visit_topic_type(name, [&](auto tag) { subscribe<typename decltype(tag)::type>(i); })) {
      throw std::logic_error("logger: no reader for topic '" + name + "'");
    }
  }
  diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
      *participant_, "logger", options_.dds.diagnostics_period_s, [this] { return diagnostics_snapshot(); });
}

diagnostics::Snapshot LoggerNode::diagnostics_snapshot() const {
  const LoggerCounters c = counters();
  diagnostics::Snapshot s;
  for (const TopicCounters& t : c.topics) {
    const std::string name = t.topic.substr(t.topic.find('/') + 1);
    s.counters.push_back({name + "_written", t.written, false});
    s.counters.push_back({name + "_dropped", t.dropped, true});
    s.counters.push_back({name + "_seq_gaps", t.reader.seq_gaps, true});
    s.counters.push_back({name + "_malformed", t.reader.malformed, true});
    s.counters.push_back({name + "_seq_jumps", t.reader.seq_jumps, true});
  }
  s.counters.push_back({"files", c.files.size(), false});
  s.counters.push_back({"bytes_written", c.file.bytes_written, false});
  s.counters.push_back({"queue_peak_bytes", c.queue_peak_bytes, false});
  s.counters.push_back({"write_failures", c.write_failures, true});
  s.error = !c.error.empty() ? c.error
            : c.recording    ? std::string()
                             : "not recording after a write failure (retrying): " + c.last_write_error;
  return s;
}

void LoggerNode::open_first_file() {
  // An existing recording is never overwritten (a restarted logger, a reused
  // run folder): the indexed name after the highest one holding data is taken instead.
  const auto holds_data = [](const std::string& path) {
    std::error_code error;
    return std::filesystem::is_regular_file(path, error) && std::filesystem::file_size(path, error) > 0;
  };
  const bool rotating = rotation_enabled(options_);
  if (!rotating && !holds_data(options_.output_file)) {
    open_file(0);
    return;
  }
  // After the highest index that holds a recording: with keep_files the lowest
  // ones of an earlier run are gone, and its newest must not be overwritten.
  std::size_t index = rotating ? 0 : 1;
  const std::filesystem::path base(options_.output_file);
  const std::filesystem::path folder = base.has_parent_path() ? base.parent_path() : std::filesystem::path(".");
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name =
        base.has_parent_path() ? (folder / entry.path().filename()).string() : entry.path().filename().string();
    const std::optional<std::size_t> taken = rotated_file_index(options_.output_file, name);
    if (taken && holds_data(name)) index = std::max(index, *taken + 1);
  }
  const std::string path = rotated_file_name(options_.output_file, index);
  if (!rotating || index > 0) {
    std::fprintf(stderr, "logger: WARN: %s already holds a recording: writing %s\n",
                 (rotating ? rotated_file_name(options_.output_file, 0) : options_.output_file).c_str(), path.c_str());
  }
  open_file(index, path);
}

void LoggerNode::open_file(std::size_t index, const std::string& path_override) {
  mcap::McapWriterOptions file;
  file.chunk_size_bytes = options_.chunk_size_bytes;
  file.compression = options_.compression;
  file.sync_after_chunk = options_.fsync;
  const std::string path = !path_override.empty()       ? path_override
                           : rotation_enabled(options_) ? rotated_file_name(options_.output_file, index)
                                                        : options_.output_file;
  writer_.open(path, file);
  file_given_up_ = false;
  file_index_ = index;
  file_opened_ = std::chrono::steady_clock::now();

  const std::map<std::string, std::string> metadata_base = {
      {"robot_id", options_.dds.robot_id}, {"dds_domain_id", std::to_string(options_.dds.domain_id)}};
  for (std::size_t i = 0; i < topic_infos_.size(); ++i) {
    const dds::TopicInfo& info = *topic_infos_[i];
    const std::uint16_t schema = writer_.add_schema(info.type_name, "omgidl", msg::idl_text(info.idl_stem));
    std::map<std::string, std::string> metadata = metadata_base;
    metadata["type_name"] = info.type_name;
    const std::uint16_t channel = writer_.add_channel(info.topic, "cdr", schema, metadata);
    if (topics_[i].channel_id == 0) {
      topics_[i].channel_id = channel;  // the first file; the same in every file: same order
    } else if (topics_[i].channel_id != channel) {
      throw std::logic_error("logger: channel ids differ between rotated files");
    }
  }
}

void LoggerNode::rotate() {
  writer_.close();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_files_.push_back(LoggedFile{writer_.path(), writer_.counters(), true});
    file_given_up_ = true;  // listed; open_file() clears it
  }
  open_file(file_index_ + 1);
  remove_old_files();
  std::lock_guard<std::mutex> lock(mutex_);
  update_file_counters();
}

void LoggerNode::remove_old_files() {
  if (options_.keep_files == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t on_disk = 1;  // the open file
  for (const LoggedFile& f : closed_files_) on_disk += f.removed ? 0 : 1;
  for (LoggedFile& f : closed_files_) {
    if (on_disk <= options_.keep_files) break;
    if (f.removed) continue;
    std::error_code error;
    std::filesystem::remove(f.path, error);
    f.removed = true;
    --on_disk;
    if (error) {
      std::fprintf(stderr, "logger: WARN: cannot delete %s (keep_files %zu): %s\n", f.path.c_str(),
                   options_.keep_files, error.message().c_str());
    } else {
      std::fprintf(stderr, "logger: deleted %s (keep_files %zu)\n", f.path.c_str(), options_.keep_files);
    }
  }
}

bool LoggerNode::size_limit_reached() const {
  return options_.rotate_size_bytes > 0 &&
         writer_.counters().bytes_written + writer_.chunk_bytes_buffered() >= options_.rotate_size_bytes;
}

void LoggerNode::update_file_counters() {
  totals_.files = closed_files_;
  if (!file_given_up_) totals_.files.push_back(LoggedFile{writer_.path(), writer_.counters(), !writer_.is_open()});
  totals_.recording = writer_.is_open() || !file_given_up_;
  mcap::McapWriterCounters sum;
  for (const LoggedFile& f : totals_.files) {
    sum.messages += f.counters.messages;
    sum.schemas += f.counters.schemas;
    sum.channels += f.counters.channels;
    sum.chunks += f.counters.chunks;
    sum.bytes_written += f.counters.bytes_written;
    sum.message_bytes += f.counters.message_bytes;
  }
  totals_.file = sum;
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
  diagnostics_.reset();
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
    std::vector<ReaderCounts> counts;
    for (const auto& s : subscriptions_) counts.push_back(s->reader_counts());
    subscriptions_.clear();
    std::lock_guard<std::mutex> queue_lock(mutex_);
    for (std::size_t i = 0; i < counts.size(); ++i) topics_[i].reader = counts[i];
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
  if (diagnostics_) diagnostics_->stop();
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
  const auto to_duration = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const bool timed = options_.flush_period_s > 0.0;
  const bool rotate_by_time = options_.rotate_period_s > 0.0;
  const auto period = to_duration(options_.flush_period_s);
  const auto rotate_period = to_duration(options_.rotate_period_s);
  auto next_flush = Clock::now() + period;
  std::deque<Pending> batch;
  for (;;) {
    bool stopping = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [this] { return !queue_.empty() || stopping_; };
      auto deadline = Clock::time_point::max();
      if (timed) deadline = next_flush;
      if (rotate_by_time) deadline = std::min(deadline, file_opened_ + rotate_period);
      if (file_given_up_) deadline = std::min(deadline, retry_at_);
      if (deadline != Clock::time_point::max()) {
        cv_.wait_until(lock, deadline, ready);
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
          on_write_failure(e.what());
        }
      }
      next_flush = Clock::now() + period;
    }
    if (!stopping && rotate_by_time && writer_.is_open() && Clock::now() >= file_opened_ + rotate_period) {
      try {
        rotate();
      } catch (const std::exception& e) {
        on_write_failure(e.what());
      }
    }
    if (!stopping && file_given_up_ && Clock::now() >= retry_at_) reopen_after_failure();
    if (stopping) break;
  }
  try {
    writer_.close();
  } catch (const std::exception& e) {
    on_write_failure(e.what());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  update_file_counters();
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
      } catch (const std::exception& e) {
        error = e.what();
        ++dropped[p.topic];
        continue;
      }
      try {
        if (size_limit_reached()) rotate();
      } catch (const std::exception& e) {
        error = e.what();
      }
      continue;
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
    update_file_counters();
  }
  if (!error.empty()) on_write_failure(error);
}

void LoggerNode::on_write_failure(const std::string& what) {
  // A failed McapWriter has closed itself; anything else is closed here as
  // far as it goes. The file keeps what reached it: readable up to its last
  // complete chunk (docs/mcap.md).
  if (writer_.is_open()) {
    try {
      writer_.close();
    } catch (const std::exception&) {
    }
  }
  const double retry_s = options_.retry_period_s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++totals_.write_failures;
    totals_.last_write_error = what;
    if (!file_given_up_ && !writer_.path().empty()) {
      closed_files_.push_back(LoggedFile{writer_.path(), writer_.counters(), false});
    }
    file_given_up_ = true;
    retry_at_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(retry_s));
    update_file_counters();
  }
  std::fprintf(stderr, "logger: ERROR: %s; samples are dropped (counted) until a new file opens, next try in %.1f s\n",
               what.c_str(), retry_s);
}

void LoggerNode::reopen_after_failure() {
  ++retries_;
  std::string path = rotated_file_name(options_.output_file, file_index_ + 1);
  if (!options_.fallback_dir.empty() && retries_ % 2 == 1) {
    path = (std::filesystem::path(options_.fallback_dir) / std::filesystem::path(path).filename()).string();
  }
  try {
    open_file(file_index_ + 1, path);
  } catch (const std::exception& e) {
    on_write_failure(e.what());
    return;
  }
  std::fprintf(stderr, "logger: recording again, to %s\n", path.c_str());
  remove_old_files();
  std::lock_guard<std::mutex> lock(mutex_);
  update_file_counters();
}

LoggerCounters LoggerNode::counters() const {
  std::vector<ReaderCounts> counts;
  {
    std::lock_guard<std::mutex> lock(subscriptions_mutex_);
    for (const auto& s : subscriptions_) counts.push_back(s->reader_counts());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  LoggerCounters c = totals_;
  c.topics = topics_;
  for (std::size_t i = 0; i < counts.size() && i < c.topics.size(); ++i) c.topics[i].reader = counts[i];
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
       << ", seq gaps " << t.reader.seq_gaps << ", malformed " << t.reader.malformed << ", seq jumps "
       << t.reader.seq_jumps << "\n";
  }
  return os.str();
}

}  // namespace pixyslam::logger_node
