// pixyslam_play: replays MCAP logs written by the logger onto DDS.
//   pixyslam_play LOG.mcap [LOG_001.mcap ...] [--rate R] [--start S] [--duration S]
//                 [--loop] [--topics LIST] [--restamp] [--wait-readers N]
//                 [--wait-timeout S] [--config FILE] [--domain N] [--quiet]
// Exit status: 0 played, 1 a file could not be read / nothing to play,
// 2 command-line or config error.
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/player/log_player.h"
#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/parameters/parameters.h"


int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  player::PlayerOptions o;
  std::string dds_config;
  std::vector<std::string> dds_overrides;  // --domain
  std::string topics;
  bool quiet = false;
  app::Cli cli{"pixyslam_play", "Replays MCAP logs written by the logger onto DDS, with the recorded timing."};
  cli.option("logs", o.files, "the MCAP files, merged by log time (a rotated log: LOG_000.mcap LOG_001.mcap ..., in any order)")
      .required()
      .input_file()
      .type("LOG.mcap");
  cli.option("--rate", o.playback.rate, "playback speed factor (1: the recorded timing)").type("R");
  cli.option("--start", o.playback.start_offset_s, "skip the first S seconds of the log").type("S");
  cli.option("--duration", o.playback.duration_s, "play S seconds of log time (default: to the end)").type("S");
  cli.flag("--loop", o.playback.loop, "start over at the end until Ctrl-C");
  cli.option("--topics", topics, "comma-separated names, globs, !exclusions (default: every topic)").type("LIST");
  cli.flag("--restamp", o.restamp, "shift header stamps onto the current clock (for a live estimator)");
  cli.option("--wait-readers", o.wait_readers, "wait for N readers per topic before playing (0: do not wait)")
      .range(0, 1000)
      .type("N");
  cli.option("--wait-timeout", o.wait_timeout_s, "then play anyway after S seconds").non_negative().type("S");
  cli.option("--config", dds_config,
             std::string("YAML with a dds: mapping (default ") + dds::default_profiles_file() + ", domain 0)")
      .existing_file()
      .type("FILE");
  app::add_domain(cli, dds_overrides);
  cli.flag("--quiet", quiet, "no progress lines");
  if (const auto done = cli.parse(argc, argv)) return *done;
  if (const auto failed = app::configure("pixyslam_play", [&] {
        if (cli.given("--topics")) {
          o.topics = parameters::split_list(topics);
          if (o.topics.empty()) throw std::invalid_argument("--topics needs at least one topic");
        }
        if (quiet) o.progress_period_s = 0.0;
        player::validate(o.playback);
        o.dds = dds::read_dds_options_file(dds_config, dds::default_profiles_file());
        dds::resolve_settings(o.dds, dds_overrides);
      })) {
    return *failed;
  }
  return app::run_main("pixyslam_play", [&] {
    try {
      player::LogPlayer player(o, std::cerr);
      player.play();
    } catch (const std::invalid_argument& e) {
      throw app::UsageError(e.what());  // e.g. a --topics pattern no log holds: exit 2
    }
    return 0;
  });
}
