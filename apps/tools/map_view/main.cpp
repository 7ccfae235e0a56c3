// map_view: the estimator's map as an image (seed paper Fig. 6b): particles,
// mean trajectory, landmarks with n-sigma ellipses and ids, ground truth, the
// map optimiser's solution.
//   map_view live   [--config FILE] [--out-dir DIR] [--period S] [--no-window] [--domain N] [--verbose]
//   map_view render LOG.mcap --out FILE.png [--config FILE] [--width N] [--height N] [--no-truth]
//   map_view video  LOG.mcap --out FILE.avi|--out-dir DIR [--config FILE] [--fps N] [--rate R]
//                   [--width N] [--height N] [--no-truth]
// --config: a map_view.yaml (config/map_view.yaml); without it the defaults
// and, live, the loopback profile on domain 0. Exit status: 0 done, 2 a bad
// command line, config or output path (the message names it), 1 a log it
// cannot read or any other failure.
#include <cmath>
#include <cstdio>
#include <tuple>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/map_view/image_output.h"
#include "pixyslam/map_view/map_log.h"
#include "pixyslam/map_view/map_view_commands.h"

namespace {

// The render options every command shares: --config, --width, --height, --no-truth.
struct ViewArguments {
  std::string config;
  std::string width, height;  // as given (checked by the render table)
  bool no_truth = false;
  std::vector<std::string> overrides;  // --set

  void add_to(pixyslam::app::Cli& command, bool truth_switch) {
    command
        .option("--config", config,
                std::string("a map_view.yaml (e.g. config/map_view.yaml); live default: ") +
                    pixyslam::dds::default_profiles_file() + ", domain 0")
        .existing_file()
        .type("FILE");
    command.option("--width", width, "image width in pixels (default: the config's)").type("N");
    command.option("--height", height, "image height in pixels (default: the config's)").type("N");
    if (truth_switch) command.flag("--no-truth", no_truth, "leave out the ground truth");
    pixyslam::app::add_set(command, overrides, "map_view.sigma_scale=3");
  }

  // The options: --config, then --set (map_view. keys; the dds. ones are
  // left in `dds_overrides`), then --width/--height/--no-truth.
  pixyslam::map_view::MapViewOptions load(const pixyslam::app::Cli& command, std::vector<std::string>& dds_overrides) const {
    using namespace pixyslam::map_view;
    MapViewOptions o;
    o.dds.profiles_file = pixyslam::dds::default_profiles_file();
    if (command.given("--config")) o = read_map_view_options_file(config, pixyslam::dds::default_profiles_file());
    dds_overrides = overrides;
    try {
      apply_overrides(o, dds_overrides);
    } catch (const std::invalid_argument& e) {
      throw pixyslam::app::UsageError(std::string("--set ") + e.what());
    }
    for (const auto& [flag, key, text] :
         {std::tuple{"--width", "width_px", width}, std::tuple{"--height", "height_px", height}}) {
      if (!command.given(flag)) continue;
      try {
        pixyslam::parameters::set_from_text(o.render, render_parameters(), "map_view", key, text);
      } catch (const std::invalid_argument& e) {
        throw pixyslam::app::UsageError(std::string(flag) + ": " + e.what());
      }
    }
    if (no_truth) o.render.ground_truth = false;
    try {
      validate(o.render);
    } catch (const std::invalid_argument& e) {
      throw pixyslam::app::UsageError(std::string("--width/--height: ") + e.what());
    }
    return o;
  }
};

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  using namespace pixyslam::map_view;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  app::Cli cli{"map_view",
               "The estimator's map as an image (seed paper Fig. 6b): particles, mean trajectory, landmarks with "
               "n-sigma ellipses and ids, ground truth, the map optimiser's solution."};
  cli.footer(help_text() + "Exit status: 0 done, 2 a bad command line, config or output path, 1 a log it cannot read (unreadable, "
             "not MCAP, no MapState) or any other failure.");

  ViewArguments render_view;
  RenderRequest render_request;
  app::Cli& render = cli.subcommand("render", "the final map of a log as a PNG");
  render.option("log", render_request.log, "the logger's MCAP file").required().input_file().type("LOG.mcap");
  render.option("--out", render_request.out, "the PNG to write").required().type("FILE.png");
  render_view.add_to(render, true);

  ViewArguments video_view;
  VideoRequest video_request;
  app::Cli& video = cli.subcommand("video", "the map along the log's time under one fixed view");
  video.option("log", video_request.log, "the logger's MCAP file").required().input_file().type("LOG.mcap");
  std::string video_out_dir;
  app::Cli::Option& video_out = video.option("--out", video_request.out, "the MJPG video to write").type("FILE.avi");
  app::Cli::Option& video_frames =
      video.option("--out-dir", video_out_dir, "a folder for numbered PNG frames instead").type("DIR");
  video_out.excludes(video_frames);
  video.option("--fps", video_request.fps, "frames per second of video").range(0.1, 240.0).type("N");
  // --rate: a speed factor, as in pixyslam_play and dataset_bridge (--speed: its old name, still accepted).
  video.option("--rate,--speed", video_request.rate, "log seconds per video second (--speed: its old name, deprecated)")
      .range(0.01, 10000.0)
      .type("R");
  video_view.add_to(video, true);

  ViewArguments live_view;
  LiveRequest live_request;
  std::string period;
  std::vector<std::string> dds_overrides;
  bool verbose = false;
  app::Cli& live = cli.subcommand("live", "the estimator's map over DDS, in a window or as snapshots");
  live.option("--out-dir", live_request.out_dir, "write DIR/map_latest.png every period (also with a window)")
      .type("DIR");
  live.option("--period", period, "seconds between snapshots (default: the config's snapshot_period_s)").type("S");
  live.flag("--no-window", live_request.no_window, "snapshots only, no window");
  app::add_domain(live, dds_overrides);
  app::add_verbose(live, verbose);
  live_view.add_to(live, false);

  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("map_view", [&]() -> int {
    try {
      std::vector<std::string> left;  // render and video join no DDS domain: only map_view. keys
      const auto no_dds = [&left] {
        if (!left.empty()) throw app::UsageError("--set " + left.front() + ": not a map_view. parameter");
      };
      if (render.chosen()) {
        MapViewOptions o = render_view.load(render, left);
        no_dds();
        return run_render(o, render_request);
      }
      if (video.chosen()) {
        if (!video.given("--out") && !video.given("--out-dir")) throw app::UsageError("--out FILE.avi or --out-dir DIR is required");
        if (video.given("--out") && !is_video_path(video_request.out)) {
          throw app::UsageError("--out " + video_request.out + ": not a .avi file (PNG frames: --out-dir DIR)");
        }
        if (video.given("--out-dir")) {
          if (is_video_path(video_out_dir)) throw app::UsageError("--out-dir " + video_out_dir + ": a folder, not a .avi file");
          video_request.out = video_out_dir;
        }
        MapViewOptions o = video_view.load(video, left);
        no_dds();
        return run_video(o, video_request);
      }
      std::vector<std::string> set_dds;
      MapViewOptions o = live_view.load(live, set_dds);
      if (live.given("--period")) {
        try {
          parameters::set_from_text(o, map_view_parameters(), "map_view", "snapshot_period_s", period);
        } catch (const std::invalid_argument& e) {
          throw app::UsageError(std::string("--period: ") + e.what());
        }
      }
      set_dds.insert(set_dds.end(), dds_overrides.begin(), dds_overrides.end());  // --domain last: it wins
      dds::resolve_settings(o.dds, set_dds);
      live_request.out_given = live.given("--out-dir");
      if (verbose) app::print_effective_configuration("map_view", to_yaml(o));
      return run_live(o, live_request);
    } catch (const InputError& e) {  // a bad option or output path: exit 2
      std::fprintf(stderr, "map_view: %s\n", e.what());
      return 2;
    } catch (const LogError& e) {  // a log it cannot read: exit 1
      std::fprintf(stderr, "map_view: %s\n", e.what());
      return 1;
    }
  });
}
