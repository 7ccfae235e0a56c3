// logger: records DDS topics to an MCAP file until SIGINT/SIGTERM.
//   logger --config config/logger.yaml [--out FILE.mcap] [--topics LIST] [--set KEY=VALUE ...] [--verbose]
// --out overrides logger.output_file (with rotation: the base of the names,
// run.mcap -> run_000.mcap, run_001.mcap, ...); --topics logger.topics
// (comma-separated names or patterns, as the config's list). --verbose prints the
// effective configuration to stdout; logs go to stderr; on a stop it drains what was
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

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/logger_node/logger_node.h"
#include "pixyslam/dds/topic_selection.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  std::string config, out, topics;
  std::vector<std::string> overrides;
  bool verbose = false;
  app::Cli cli{"logger", "Records DDS topics to an MCAP file until SIGINT/SIGTERM."};
  app::add_config(cli, config, "config/logger.yaml: logger:, dds:");
  cli.option("--out", out, "the recording (overrides logger.output_file)").type("FILE.mcap");
  cli.option("--topics", topics,
                 "topics to record, comma-separated names or patterns (overrides logger.topics), e.g. "
                 "pixyslam/odometry,pixyslam/map_state or 'pixyslam/*,!pixyslam/diagnostics'")
      .type("LIST");
  app::add_set(cli, overrides, "logger.compression=lz4");
  app::add_verbose(cli, verbose);
  cli.footer("logger parameters (logger:; topics apart):\n" +
             parameters::help_text(logger_node::logger_parameters(), "logger") +
             "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
             parameters::help_text(pixyslam::dds::dds_parameters(), "dds"));
  if (const auto done = cli.parse(argc, argv)) return *done;

  logger_node::LoggerOptions options;
  const std::optional<int> bad = app::configure("logger", [&] {
    options = logger_node::read_logger_options_file(config);
    if (!out.empty()) options.output_file = out;
    if (cli.given("--topics")) {
      const std::vector<std::string> patterns = config::split_comma_list(topics);
      std::vector<std::string> known;
      for (const pixyslam::dds::TopicInfo& t : pixyslam::dds::known_topics()) known.push_back(t.topic);
      const pixyslam::dds::TopicSelection selection = pixyslam::dds::select_topics(patterns, known);
      if (patterns.empty() || !selection.error.empty()) {
        throw std::invalid_argument("--topics: " + (patterns.empty() ? std::string("empty list")
                                                                     : "'" + patterns[selection.bad_pattern] +
                                                                           "': " + selection.error));
      }
      options.topics = selection.topics;
    }
    logger_node::apply_overrides(options, overrides);
  });
  if (bad) return *bad;
  if (verbose) {
    std::printf("# logger: effective configuration\n%s", logger_node::to_yaml(options).c_str());
    std::fflush(stdout);
  }

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
