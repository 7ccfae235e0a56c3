#pragma once

#include <string>

#include "pixyslam/map_view/map_view_options.h"

namespace pixyslam::map_view {

// `map_view render LOG --out FILE.png`: the final map of a log.
struct RenderRequest {
  std::string log;
  std::string out;
};
int run_render(const MapViewOptions& options, const RenderRequest& request);

// `map_view video LOG --out FILE.avi|DIR`: frames along the log's time under
// one fixed view (the bounds of the whole run).
struct VideoRequest {
  std::string log;
  std::string out;
  double fps = 10.0;
  double rate = 1.0;  // log seconds per video second (--rate)
};
int run_video(const MapViewOptions& options, const VideoRequest& request);

// `map_view live`: the estimator's map over DDS, in a window when a display
// works, else (or with --out) as DIR/map_latest.png every period. Runs until
// SIGINT/SIGTERM (app::StopSignal), 'q'/Esc or the window is closed.
struct LiveRequest {
  std::string out_dir;    // "" : options.snapshot_dir, snapshots only without a window
  bool out_given = false; // --out: snapshots also with a window
  bool no_window = false;
};
int run_live(const MapViewOptions& options, const LiveRequest& request);

}  // namespace pixyslam::map_view
