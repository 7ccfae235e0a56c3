#include "pixyslam/logger_node/logger_run.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>

#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/topic_selection.h"
#include "pixyslam/logger_node/logger_node.h"

namespace pixyslam::logger_node {

std::vector<std::string> select_known_topics(const std::vector<std::string>& patterns, const std::string& what) {
  if (patterns.empty()) throw std::invalid_argument(what + ": empty list");
  const dds::TopicSelection selection = dds::select_topics(patterns, dds::known_topic_names());
  if (!selection.error.empty()) {
    throw std::invalid_argument(what + ": '" + patterns[selection.bad_pattern] + "': " + selection.error);
  }
  return selection.topics;
}

namespace {

unsigned long long u(std::uint64_t v) { return static_cast<unsigned long long>(v); }

void print_counters(const LoggerOptions& options, const LoggerCounters& c, const char* tool) {
  for (const TopicCounters& t : c.topics) {
    std::fprintf(stderr,
                 "%s: %s: received %llu, written %llu, dropped %llu, seq gaps %llu, malformed %llu, seq jumps %llu\n",
                 tool, t.topic.c_str(), u(t.received), u(t.written), u(t.dropped), u(t.reader.seq_gaps),
                 u(t.reader.malformed), u(t.reader.seq_jumps));
  }
  for (const LoggedFile& f : c.files) {
    std::fprintf(stderr, "%s: file %s: %llu messages, %llu chunks, %llu bytes%s\n", tool, f.path.c_str(),
                 u(f.counters.messages), u(f.counters.chunks), u(f.counters.bytes_written),
                 f.removed ? " (deleted: keep_files)" : "");
  }
  std::fprintf(stderr,
               "%s: %s: %zu file(s), %llu messages, %llu chunks, %llu bytes; queue peak %zu messages / %zu bytes\n",
               tool, options.output_file.c_str(), c.files.size(), u(c.file.messages), u(c.file.chunks),
               u(c.file.bytes_written), c.queue_peak_messages, c.queue_peak_bytes);
}

}  // namespace

int record_until_stopped(const LoggerOptions& options, const std::string& tool_name, double duration_s) {
  const char* tool = tool_name.c_str();
  try {
    LoggerNode node(options);
    node.start();
    std::fprintf(stderr, "%s: recording %zu topics to %s%s\n", tool, options.topics.size(),
                 options.output_file.c_str(), rotation_enabled(options) ? " (rotating: _000, _001, ...)" : "");
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
    bool timed_out = false;
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(100))) {
      if (node.failed()) break;
      if (duration_s > 0.0 && std::chrono::steady_clock::now() >= end) {
        timed_out = true;
        break;
      }
    }
    node.stop();
    const LoggerCounters c = node.counters();
    print_counters(options, c, tool);
    if (!c.error.empty()) {
      std::fprintf(stderr, "%s: recording failed: %s\n", tool, c.error.c_str());
      return 1;
    }
    if (c.write_failures > 0) {
      std::fprintf(stderr, "%s: %llu write failure(s), samples lost while not recording; last: %s\n", tool,
                   u(c.write_failures), c.last_write_error.c_str());
      return 1;
    }
    if (timed_out) {
      std::fprintf(stderr, "%s: stopped after %g s\n", tool, duration_s);
    } else {
      std::fprintf(stderr, "%s: stopped (signal %d)\n", tool, app::StopSignal::signal_number());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return 1;
  }
}

}  // namespace pixyslam::logger_node
