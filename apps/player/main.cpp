// pixyslam_play: replays MCAP logs written by the logger onto DDS.
//   pixyslam_play LOG.mcap [LOG_001.mcap ...] [--rate R] [--start S] [--duration S]
//                 [--loop] [--topics LIST] [--restamp] [--wait-readers N]
//                 [--wait-timeout S] [--config FILE] [--domain N] [--quiet]
// Exit status: 0 played, 1 a file could not be read / nothing to play,
// 2 command-line or config error.
#include <cstdio>
#include <exception>
#include <optional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "log_player.h"
#include "pixyslam/app/command_line.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/parameters/parameters.h"

#ifndef PIXYSLAM_DEFAULT_PROFILES_FILE
#define PIXYSLAM_DEFAULT_PROFILES_FILE ""
#endif

namespace {

constexpr const char* kUsage =
    "usage: pixyslam_play LOG.mcap [MORE.mcap ...] [options]\n"
    "  --rate R          playback speed factor (default 1: the recorded timing)\n"
    "  --start S         skip the first S seconds of the log\n"
    "  --duration S      play S seconds of log time (default: to the end)\n"
    "  --loop            start over at the end until Ctrl-C\n"
    "  --topics LIST     comma-separated names, globs, !exclusions (default: every topic)\n"
    "  --restamp         shift header stamps onto the current clock (for a live estimator)\n"
    "  --wait-readers N  wait for N readers per topic before playing (default 1; 0: do not wait)\n"
    "  --wait-timeout S  then play anyway (default 10)\n"
    "  --config FILE     YAML with a dds: mapping (default " PIXYSLAM_DEFAULT_PROFILES_FILE ", domain 0)\n"
    "  --domain N        overrides the domain id\n"
    "  --quiet           no progress lines\n";

double number(const std::string& flag, const std::string& text) {
  const std::optional<double> v = pixyslam::parameters::parse_number(text);
  if (!v) throw std::invalid_argument(flag + " needs a number, got '" + text + "'");
  return *v;
}

int integer(const std::string& flag, const std::string& text, int min, int max) {
  const double v = number(flag, text);
  if (v != static_cast<int>(v) || v < min || v > max) {
    throw std::invalid_argument(flag + " must be an integer " + std::to_string(min) + ".." + std::to_string(max) +
                                ", got '" + text + "'");
  }
  return static_cast<int>(v);
}

pixyslam::player::PlayerOptions parse(const std::vector<std::string>& args) {
  using namespace pixyslam;
  player::PlayerOptions o;
  std::string dds_config;
  std::vector<std::string> dds_overrides;  // --domain
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw std::invalid_argument(arg + " needs a value");
      return args[++i];
    };
    if (arg == "--rate") {
      o.playback.rate = number(arg, value());
    } else if (arg == "--start") {
      o.playback.start_offset_s = number(arg, value());
    } else if (arg == "--duration") {
      o.playback.duration_s = number(arg, value());
    } else if (arg == "--loop") {
      o.playback.loop = true;
    } else if (arg == "--topics") {
      o.topics = config::split_comma_list(value());
      if (o.topics.empty()) throw std::invalid_argument("--topics needs at least one topic");
    } else if (arg == "--restamp") {
      o.restamp = true;
    } else if (arg == "--wait-readers") {
      o.wait_readers = integer(arg, value(), 0, 1000);
    } else if (arg == "--wait-timeout") {
      o.wait_timeout_s = number(arg, value());
      if (!(o.wait_timeout_s >= 0)) throw std::invalid_argument("--wait-timeout must be >= 0");
    } else if (arg == "--config") {
      dds_config = value();
    } else if (arg == "--domain") {
      dds_overrides.push_back(dds::domain_override(value()));
    } else if (arg == "--quiet") {
      o.progress_period_s = 0.0;
    } else if (arg.rfind("-", 0) == 0) {
      throw std::invalid_argument("unknown option '" + arg + "'");
    } else {
      o.files.push_back(arg);
    }
  }
  if (o.files.empty()) throw std::invalid_argument("no MCAP file given");
  app::require_files(o.files);
  player::validate(o.playback);
  o.dds = dds::read_dds_options_file(dds_config, PIXYSLAM_DEFAULT_PROFILES_FILE);
  dds::resolve_settings(o.dds, dds_overrides);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const auto status = app::usage_exit(args, kUsage)) return *status;
  player::PlayerOptions options;
  try {
    options = parse(args);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "pixyslam_play: config error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "pixyslam_play: %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    player::LogPlayer player(options, std::cerr);
    player.play();
    return 0;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "pixyslam_play: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixyslam_play: %s\n", e.what());
    return 1;
  }
}
