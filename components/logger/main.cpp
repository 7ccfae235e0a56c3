// logger: records DDS topics to an MCAP file until SIGINT/SIGTERM.
//   logger --config config/logger.yaml [--out FILE.mcap] [--topics LIST] [--set KEY=VALUE ...] [--domain N] [--verbose]
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
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/logger_node/logger_run.h"

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
  std::vector<std::string> domain;
  app::add_set(cli, overrides, "logger.compression=lz4");
  app::add_domain(cli, domain);
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
    if (cli.given("--topics")) options.topics = logger_node::select_known_topics(parameters::split_list(topics), "--topics");
    overrides.insert(overrides.end(), domain.begin(), domain.end());  // --domain last: it wins
    logger_node::apply_overrides(options, overrides);
  });
  if (bad) return *bad;
  if (verbose) {
    std::printf("# logger: effective configuration\n%s", logger_node::to_yaml(options).c_str());
    std::fflush(stdout);
  }
  return logger_node::record_until_stopped(options, "logger");
}
