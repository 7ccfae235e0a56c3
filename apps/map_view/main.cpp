// map_view: the estimator's map as an image (seed paper Fig. 6b): particles,
// mean trajectory, landmarks with n-sigma ellipses and ids, ground truth, the
// map optimiser's solution.
//   map_view live   [--config FILE] [--out-dir DIR] [--period S] [--no-window] [--domain N] [--verbose]
//   map_view render LOG.mcap --out FILE.png [--config FILE] [--width N] [--height N] [--no-truth]
//   map_view video  LOG.mcap --out FILE.avi|DIR [--config FILE] [--fps N] [--speed X]
//                   [--width N] [--height N] [--no-truth]
// --config: a map_view.yaml (config/map_view.yaml); without it the defaults
// and, live, the loopback profile on domain 0. Exit status: 0 done, 2 a bad
// command line, config, input log or output path (the message names it),
// 1 any other failure.
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "map_view_commands.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/map_view/map_log.h"

#ifndef PIXYSLAM_DEFAULT_PROFILES_FILE
#define PIXYSLAM_DEFAULT_PROFILES_FILE ""
#endif

namespace {

using pixyslam::map_view::InputError;

constexpr const char* kUsage =
    "usage: map_view live   [--config FILE] [--out-dir DIR] [--period S] [--no-window] [--domain N] [--verbose]\n"
    "       map_view render LOG.mcap --out FILE.png [--config FILE] [--width N] [--height N] [--no-truth]\n"
    "       map_view video  LOG.mcap --out FILE.avi|DIR [--config FILE] [--fps N] [--speed X]\n"
    "                       [--width N] [--height N] [--no-truth]\n"
    "--config: a map_view.yaml (e.g. config/map_view.yaml); live default: " PIXYSLAM_DEFAULT_PROFILES_FILE
    ", domain 0\n";

// Flags after the subcommand: `--name value`, switches, positional words.
struct Arguments {
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;
  std::set<std::string> switches;

  bool has(const std::string& flag) const { return values.count(flag) != 0; }
  double number(const std::string& flag, double fallback, double min, double max) const {
    const auto it = values.find(flag);
    if (it == values.end()) return fallback;
    std::size_t used = 0;
    double v = std::nan("");
    try {
      v = std::stod(it->second, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != it->second.size() || !(v >= min && v <= max)) {
      char range[64];
      std::snprintf(range, sizeof range, "[%g, %g]", min, max);
      throw std::invalid_argument(flag + " needs a number in " + range + ", got '" + it->second + "'");
    }
    return v;
  }
  int integer(const std::string& flag, int fallback, int min, int max) const {
    const double v = number(flag, fallback, min, max);
    if (v != std::floor(v)) throw std::invalid_argument(flag + " needs an integer, got '" + values.at(flag) + "'");
    return static_cast<int>(v);
  }
};

Arguments parse(const std::vector<std::string>& args, const std::set<std::string>& value_flags,
                const std::set<std::string>& switch_flags, std::size_t positional) {
  Arguments a;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (value_flags.count(arg) != 0) {
      if (i + 1 >= args.size()) throw std::invalid_argument(arg + " needs a value");
      if (!a.values.emplace(arg, args[++i]).second) throw std::invalid_argument(arg + " given twice");
    } else if (switch_flags.count(arg) != 0) {
      a.switches.insert(arg);
    } else if (arg.rfind("-", 0) == 0 && arg.size() > 1) {
      throw std::invalid_argument("unknown option '" + arg + "' for " + args[0]);
    } else {
      a.positional.push_back(arg);
    }
  }
  if (a.positional.size() != positional) {
    throw std::invalid_argument(args[0] + (positional == 0 ? " takes no file argument" : " needs exactly one LOG.mcap"));
  }
  return a;
}

pixyslam::map_view::MapViewOptions load_options(const Arguments& a) {
  using namespace pixyslam::map_view;
  MapViewOptions o;
  o.dds.profiles_file = PIXYSLAM_DEFAULT_PROFILES_FILE;
  if (a.has("--config")) o = read_map_view_options_file(a.values.at("--config"), PIXYSLAM_DEFAULT_PROFILES_FILE);
  for (const auto& [flag, key] : {std::pair{"--width", "width_px"}, std::pair{"--height", "height_px"}}) {
    if (!a.has(flag)) continue;
    try {
      pixyslam::parameters::set_from_text(o.render, render_parameters(), "map_view", key, a.values.at(flag));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(flag) + ": " + e.what());
    }
  }
  if (a.switches.count("--no-truth") != 0) o.render.ground_truth = false;
  try {
    validate(o.render);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--width/--height: ") + e.what());
  }
  return o;
}

int dispatch(const std::vector<std::string>& args) {
  using namespace pixyslam::map_view;
  const std::string& command = args[0];
  if (command == "render") {
    const Arguments a = parse(args, {"--out", "--config", "--width", "--height"}, {"--no-truth"}, 1);
    if (!a.has("--out")) throw std::invalid_argument("render needs --out FILE.png");
    const MapViewOptions o = load_options(a);
    return run_render(o, {a.positional[0], a.values.at("--out")});
  }
  if (command == "video") {
    const Arguments a =
        parse(args, {"--out", "--config", "--width", "--height", "--fps", "--speed"}, {"--no-truth"}, 1);
    if (!a.has("--out")) throw std::invalid_argument("video needs --out FILE.avi or a folder");
    const MapViewOptions o = load_options(a);
    VideoRequest r;
    r.log = a.positional[0];
    r.out = a.values.at("--out");
    r.fps = a.number("--fps", r.fps, 0.1, 240.0);
    r.speed = a.number("--speed", r.speed, 0.01, 10000.0);
    return run_video(o, r);
  }
  if (command == "live") {
    const Arguments a = parse(args, {"--out-dir", "--config", "--period", "--domain"}, {"--no-window", "--verbose"}, 0);
    MapViewOptions o = load_options(a);
    if (a.has("--period")) {
      try {
        pixyslam::parameters::set_from_text(o, pixyslam::map_view::map_view_parameters(), "map_view",
                                            "snapshot_period_s", a.values.at("--period"));
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("--period: ") + e.what());
      }
    }
    pixyslam::dds::resolve_settings(o.dds, a.has("--domain") ? std::vector<std::string>{pixyslam::dds::domain_override(a.values.at("--domain"))}
                                                   : std::vector<std::string>{});
    LiveRequest r;
    r.out_given = a.has("--out-dir");
    r.out_dir = r.out_given ? a.values.at("--out-dir") : "";
    r.no_window = a.switches.count("--no-window") != 0;
    if (a.switches.count("--verbose") != 0) pixyslam::app::print_effective_configuration("map_view", to_yaml(o));
    return run_live(o, r);
  }
  throw std::invalid_argument("unknown command '" + command + "'");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const auto status = app::usage_exit(args, kUsage)) return *status;
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  try {
    return dispatch(args);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "map_view: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "map_view: config error: %s\n", e.what());
    return 2;
  } catch (const map_view::InputError& e) {
    std::fprintf(stderr, "map_view: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map_view: %s\n", e.what());
    return 1;
  }
}
