#include "pixyslam/map_view/map_view_commands.h"

#include <cstdio>
#include <stdexcept>

#include "pixyslam/map_view/image_output.h"
#include "pixyslam/map_view/map_log.h"

namespace pixyslam::map_view {
namespace {

MapLog read_log(const std::string& path) {
  MapLog log = MapLog::read(path);
  if (!log.recovery_note().empty()) {
    std::fprintf(stderr, "map_view: warning: %s: %s\n", path.c_str(), log.recovery_note().c_str());
  }
  if (log.undecodable() > 0) {
    std::fprintf(stderr, "map_view: warning: %s: %zu payload(s) did not decode and were skipped\n", path.c_str(),
                 log.undecodable());
  }
  return log;
}

}  // namespace

int run_render(const MapViewOptions& options, const RenderRequest& request) {
  const MapLog log = read_log(request.log);
  const MapViewState state = final_state(log, options.trajectory_min_step_m);
  const cv::Mat image = render_map(state, options.render);
  try {
    write_png(request.out, image);
  } catch (const std::runtime_error& e) {
    throw InputError(std::string("--out: ") + e.what());
  }
  std::string optimised =
      log.optimised_maps().empty() ? "" : ", " + std::to_string(log.optimised_maps().size()) + " optimised maps";
  if (!log.fleet_maps().empty()) optimised += ", " + std::to_string(log.fleet_maps().size()) + " fleet maps";
  std::string robots;  // named when there are several
  for (const MapViewState& other : state.other_robots) robots += ", " + other.robot_id;
  if (!robots.empty()) robots = "; robots " + state.robot_id + robots;
  std::printf("map_view: %s: %zu map states, %zu ground-truth messages%s, %zu landmarks%s -> %s (%dx%d)\n",
              request.log.c_str(), log.map_states().size(), log.ground_truths().size(), optimised.c_str(),
              state.landmarks.size(), robots.c_str(), request.out.c_str(), image.cols, image.rows);
  return 0;
}

int run_video(const MapViewOptions& options, const VideoRequest& request) {
  const MapLog log = read_log(request.log);
  std::vector<std::uint64_t> times;
  try {
    times = frame_times(log.start_ns(), log.end_ns(), request.fps, request.rate);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--fps/--rate: ") + e.what());
  }
  RenderOptions render = options.render;
  render.view = run_bounds(log, render.sigma_scale, render.ground_truth);
  FrameSink sink(request.out, request.fps, cv::Size(render.width_px, render.height_px));
  LogPlayer player(log, options.trajectory_min_step_m);
  for (std::size_t i = 0; i < times.size(); ++i) {
    player.advance_to(times[i]);
    sink.write(render_map(player.state(), render));
    if ((i + 1) % 200 == 0) std::fprintf(stderr, "map_view: %zu / %zu frames\n", i + 1, times.size());
  }
  sink.close();
  std::printf("map_view: %s: %zu frames at %g fps (%gx log speed, %.1f s of log) -> %s%s\n", request.log.c_str(),
              sink.frames(), request.fps, request.rate, static_cast<double>(log.end_ns() - log.start_ns()) * 1e-9,
              request.out.c_str(), sink.is_video() ? " (MJPG)" : "/frame_NNNNN.png");
  return 0;
}

}  // namespace pixyslam::map_view
