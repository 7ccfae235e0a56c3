#pragma once

#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/map_view/render_map.h"

namespace pixyslam::map_view {

// Everything map_view is configured with (config/map_view.yaml). Command-line
// flags override single fields.
struct MapViewOptions {
  // `map_view.width_px`, `height_px`, `footer_px`, `sigma_scale`, `min_span_m`,
  // `ground_truth`, `landmark_ids`, `grid`, `legend`, `scale_bar`.
  RenderOptions render;
  // `map_view.trajectory_min_step_m`: trajectories keep a point only this far
  // from the last one kept (0: every point).
  double trajectory_min_step_m = 0.005;
  // `map_view.snapshot_period_s`: live view redraw and snapshot period.
  double snapshot_period_s = 1.0;
  // `map_view.snapshot_dir`: live snapshots go to <dir>/map_latest.png
  // (relative to the working directory; `--out` overrides).
  std::string snapshot_dir = "map_view";
  // `map_view.window`: open a window when a display is available.
  bool window = true;
  dds::DdsOptions dds;  // `dds:` (live only)
};

// The viewer's own `map_view:` keys (the drawing's: render_parameters()).
const parameters::Table<MapViewOptions>& map_view_parameters();

// Reads `map_view:` and `dds:` (both optional) from the top level and calls
// root.finish(). `config_dir` resolves a relative dds.profiles_file; without
// a `dds:` mapping, dds.profiles_file is `default_profiles_file`. Throws
// config::ConfigError naming the file and key path.
MapViewOptions read_map_view_options(config::YamlReader& root, const std::string& config_dir,
                                     const std::string& default_profiles_file);
MapViewOptions read_map_view_options_file(const std::string& path, const std::string& default_profiles_file);

// The effective configuration, in the layout read_map_view_options() reads.
std::string to_yaml(const MapViewOptions& options);

// `--set map_view.KEY=V` applied and checked, taken out of `assignments`
// (dds. ones stay for dds::resolve_settings).
void apply_overrides(MapViewOptions& options, std::vector<std::string>& assignments);

// Every parameter --set reaches, for --help.
std::string help_text();

}  // namespace pixyslam::map_view
