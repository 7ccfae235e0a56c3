// logger: records DDS topics to an MCAP file until SIGINT/SIGTERM.
//   logger --config config/logger.yaml [--out FILE.mcap] [--topics LIST]
// --out overrides logger.output_file (with rotation: the base of the names,
// run.mcap -> run_000.mcap, run_001.mcap, ...); --topics logger.topics
// (comma-separated names or patterns, as the config's list). Prints the effective
// configuration to stdout, logs to stderr; on a stop it drains what was
// received, closes the file (summary and footer) and prints per-topic counts,
// then one line per file: "logger: file PATH: M messages, C chunks, B bytes".
// A write failure (disk full) does not stop it: the file so far is kept, the
// samples are dropped and counted, and a new file is tried every
// logger.retry_period_s (alternating with logger.fallback_dir).
// Exit status: 0 after a clean stop, 2 for a configuration or command-line
// error, 1 for any other failure (the first file could not be created, or
// samples were lost to write failures).
#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/logger_node/cdr_payload.h"
#include "pixyslam/logger_node/logger_node.h"
#include "pixyslam/logger_node/topic_selection.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  constexpr const char* kUsage =
      "usage: logger --config FILE [--out FILE.mcap] [--topics LIST]\n"
      "  --out FILE.mcap  the recording (overrides logger.output_file)\n"
      "  --topics LIST    topics to record, comma-separated names or patterns (overrides logger.topics),\n"
      "                   e.g. pixyslam/odometry,pixyslam/map_state or 'pixyslam/*,!pixyslam/diagnostics'";

  logger_node::LoggerOptions options;
  try {
    const app::CommandLine args(argc, argv, {"config", "out", "topics"});
    if (args.help()) {
      std::puts(kUsage);
      return 0;
    }
    options = logger_node::read_logger_options_file(args.get("config"));
    if (args.has("out")) options.output_file = args.get("out");
    if (args.has("topics")) {
      const std::vector<std::string> patterns = config::split_comma_list(args.get("topics"));
      std::vector<std::string> known;
      for (const logger_node::TopicInfo& t : logger_node::known_topics()) known.push_back(t.topic);
      const logger_node::TopicSelection selection = logger_node::select_topics(patterns, known);
      if (patterns.empty() || !selection.error.empty()) {
        throw std::invalid_argument("--topics: " + (patterns.empty() ? std::string("empty list")
                                                                     : "'" + patterns[selection.bad_pattern] +
                                                                           "': " + selection.error));
      }
      options.topics = selection.topics;
    }
    pixyslam::dds::resolve_settings(options.dds);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "logger: config error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "logger: %s\n%s\n", e.what(), kUsage);
    return 2;
  }
  std::printf("# logger: effective configuration\n%s", logger_node::to_yaml(options).c_str());
  std::fflush(stdout);

  try {
    logger_node::LoggerNode node(options);
    node.start();
    std::fprintf(stderr, "logger: recording %zu topics to %s%s\n", options.topics.size(),
                 options.output_file.c_str(), logger_node::rotation_enabled(options) ? " (rotating: _000, _001, ...)" : "");
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
      if (node.failed()) break;
    }
    node.stop();
    const logger_node::LoggerCounters c = node.counters();
    for (const logger_node::TopicCounters& t : c.topics) {
      std::fprintf(stderr,
                   "logger: %s: received %llu, written %llu, dropped %llu, seq gaps %llu, malformed %llu, "
                   "seq jumps %llu\n",
                   t.topic.c_str(), static_cast<unsigned long long>(t.received),
                   static_cast<unsigned long long>(t.written), static_cast<unsigned long long>(t.dropped),
                   static_cast<unsigned long long>(t.reader.seq_gaps),
                   static_cast<unsigned long long>(t.reader.malformed),
                   static_cast<unsigned long long>(t.reader.seq_jumps));
    }
    for (const logger_node::LoggedFile& f : c.files) {
      std::fprintf(stderr, "logger: file %s: %llu messages, %llu chunks, %llu bytes\n", f.path.c_str(),
                   static_cast<unsigned long long>(f.counters.messages),
                   static_cast<unsigned long long>(f.counters.chunks),
                   static_cast<unsigned long long>(f.counters.bytes_written));
    }
    std::fprintf(stderr, "logger: %s: %zu file(s), %llu messages, %llu chunks, %llu bytes; queue peak %zu messages / %zu bytes\n",
                 options.output_file.c_str(), c.files.size(), static_cast<unsigned long long>(c.file.messages),
                 static_cast<unsigned long long>(c.file.chunks),
                 static_cast<unsigned long long>(c.file.bytes_written), c.queue_peak_messages,
                 c.queue_peak_bytes);
    if (!c.error.empty()) {
      std::fprintf(stderr, "logger: recording failed: %s\n", c.error.c_str());
      return 1;
    }
    if (c.write_failures > 0) {
      std::fprintf(stderr, "logger: %llu write failure(s), samples lost while not recording; last: %s\n",
                   static_cast<unsigned long long>(c.write_failures), c.last_write_error.c_str());
      return 1;
    }
    std::fprintf(stderr, "logger: stopped (signal %d)\n", app::StopSignal::signal_number());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "logger: %s\n", e.what());
    return 1;
  }
}
