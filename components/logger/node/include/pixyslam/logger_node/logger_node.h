#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/diagnostics/diagnostics_publisher.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/mcap/mcap_writer.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/logger_node/logger_options.h"

namespace pixyslam::logger_node {

namespace detail {
class Subscription;
}  // namespace detail

// What a topic's DDS reader saw, since construction.
struct ReaderCounts {
  std::uint64_t seq_gaps = 0;   // header seq numbers skipped, per DDS writer (lost before us)
  std::uint64_t malformed = 0;  // samples that did not decode (dropped, never written)
  std::uint64_t seq_jumps = 0;  // implausible seq jumps (restarted or hostile writer)
};

// Per recorded topic, since construction.
struct TopicCounters {
  std::string topic;
  std::uint16_t channel_id = 0;  // MCAP channel
  std::uint64_t received = 0;    // samples DDS delivered
  std::uint64_t written = 0;     // MCAP messages written
  std::uint64_t dropped = 0;     // received but not written (queue full, write failure, stopped)
  ReaderCounts reader;
};

// One MCAP file of the recording.
struct LoggedFile {
  std::string path;
  mcap::McapWriterCounters counters;  // final once the file is closed
  bool closed = false;                  // summary and footer written
  bool removed = false;                 // deleted for LoggerOptions::keep_files
};

struct LoggerCounters {
  std::vector<TopicCounters> topics;  // in the order of options.topics
  std::size_t queue_peak_bytes = 0;   // most payload bytes ever waiting
  std::size_t queue_peak_messages = 0;
  mcap::McapWriterCounters file;    // totals over every file (final after stop())
  std::vector<LoggedFile> files;      // in order; one unless rotating
  std::string error;                  // a failure that stopped recording for good ("" if none)
  std::uint64_t write_failures = 0;   // files given up after a write failure (disk full, ...)
  std::string last_write_error;
  bool recording = true;              // false while waiting to retry after a write failure
};

// The logger process: subscribes to the configured topics and writes every
// sample to one MCAP file (docs/mcap.md), one channel per topic.
//
// Per sample: the CDR payload exactly as a Fast DDS writer sends it, 4-byte
// encapsulation header included (cdr_payload.h), on the topic's channel with
// sequence = header.seq (low 32 bits), log_time = receive time (dds::now_ns())
// and publish_time = header.stamp_ns. Channel: message_encoding "cdr",
// metadata type_name, robot_id (dds.robot_id of the logger) and dds_domain_id.
// Schema: encoding "omgidl", name = DDS type name ("pixyslam::msg::Odometry"),
// data = the IDL with its includes inlined (msg::idl_text).
//
// Rotation (rotate_size_bytes / rotate_period_s): the writer thread closes the
// file (summary, footer: each file is a complete MCAP with every schema and
// channel, same ids) and opens rotated_file_name(output_file, next index);
// without rotation the one file is output_file itself. Topics may be given as
// patterns (select_topics()); an invalid selection throws std::invalid_argument.
//
// DDS callbacks only serialize and enqueue (bounded by queue_max_bytes; a
// sample beyond the bound is dropped and counted); ONE writer thread writes
// the file and writes the open chunk every flush_period_s, so a crash loses at
// most about that much. The constructor creates the file (open_first_file) and
// subscribes; samples arriving before start() wait in the queue. stop()
// unsubscribes, drains the queue and closes the file (summary and footer);
// counters are final after it. Throws std::runtime_error if the file cannot be
// created or DDS entities cannot be made. Thread-safe.
class LoggerNode {
 public:
  explicit LoggerNode(const LoggerOptions& options);
  ~LoggerNode();
  LoggerNode(const LoggerNode&) = delete;
  LoggerNode& operator=(const LoggerNode&) = delete;

  // Starts the writer thread (once; no-op after stop()).
  void start();
  // Unsubscribes, writes everything queued, closes the file. Idempotent; the
  // destructor calls it.
  void stop();

  LoggerCounters counters() const;
  // True once recording stopped for good. A write failure (disk full, ...) is
  // not that: the file so far is kept, samples are dropped and counted until a
  // new file opens (LoggerOptions::retry_period_s, fallback_dir).
  bool failed() const;
  // One line per topic, "TOPIC: received R, written W, dropped D, seq gaps G".
  std::string counters_text() const;

 private:
  friend class detail::Subscription;

  struct Pending {
    std::size_t topic = 0;  // index into topics_
    std::uint64_t seq = 0;
    std::uint64_t log_time_ns = 0;
    std::uint64_t publish_time_ns = 0;
    std::vector<std::uint8_t> payload;
  };

  template <class Message>
  void subscribe(std::size_t topic);
  // Called from DDS callbacks; `serialized` false counts the sample as dropped.
  void enqueue(std::size_t topic, std::uint64_t seq, std::uint64_t stamp_ns,
               std::vector<std::uint8_t>&& payload, bool serialized);
  void writer_loop();
  void write_batch(std::deque<Pending>& batch);
  // Opens file `index` (rotated name when rotating, or `path`) with every
  // schema and channel.
  void open_file(std::size_t index, const std::string& path = "");
  // The constructor's file: output_file, or the first indexed name that holds
  // no recording yet.
  void open_first_file();
  // After a write failure: keeps the file as written, schedules a retry.
  void on_write_failure(const std::string& what);
  // The retry: the next rotated name, alternating with fallback_dir.
  void reopen_after_failure();
  // Closes the current file and opens the next one. Writer thread only.
  void rotate();
  // Deletes this run's oldest closed files beyond LoggerOptions::keep_files.
  void remove_old_files();
  bool size_limit_reached() const;
  // Copies the writer's counters into totals_ (mutex_ held).
  void update_file_counters();
  diagnostics::Snapshot diagnostics_snapshot() const;

  LoggerOptions options_;
  std::vector<const dds::TopicInfo*> topic_infos_;  // per topics_ entry
  mcap::McapWriter writer_;  // after construction: the writer thread's alone (stop()'s if never started)
  std::size_t file_index_ = 0;
  std::chrono::steady_clock::time_point file_opened_;
  bool file_given_up_ = false;  // the writer's file failed and is in closed_files_
  std::chrono::steady_clock::time_point retry_at_;
  std::uint64_t retries_ = 0;

  // Queue and counters.
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Pending> queue_;
  std::size_t queued_bytes_ = 0;  // payloads in queue_ and in the batch being written
  std::size_t queued_messages_ = 0;
  bool accepting_ = true;         // false once stop() began or writing failed
  bool stopping_ = false;
  std::vector<TopicCounters> topics_;
  LoggerCounters totals_;         // peaks, file counters, error (topics_ kept apart)
  std::vector<LoggedFile> closed_files_;

  std::mutex lifecycle_mutex_;    // start() / stop()
  bool started_ = false;
  bool stopped_ = false;
  std::thread thread_;

  // Declared last so they go first: no callback may outlive the queue.
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;
  mutable std::mutex subscriptions_mutex_;
  std::vector<std::unique_ptr<detail::Subscription>> subscriptions_;  // one per topics_ entry; cleared by stop()
};

}  // namespace pixyslam::logger_node
