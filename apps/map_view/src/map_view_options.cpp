#include "pixyslam/map_view/map_view_options.h"

#include <sstream>
#include <stdexcept>

#include "pixyslam/app/command_line.h"

namespace pixyslam::map_view {

MapViewOptions read_map_view_options(config::YamlReader& root, const std::string& config_dir,
                                     const std::string& default_profiles_file) {
  MapViewOptions o;
  o.dds.profiles_file = default_profiles_file;
  if (root.has("map_view")) {
    config::YamlReader s = root.child("map_view");
    RenderOptions& r = o.render;
    r.width_px = static_cast<int>(s.integer("width_px", kMinMapSidePx, 16384, r.width_px));
    r.height_px = static_cast<int>(s.integer("height_px", kMinMapSidePx, 16384, r.height_px));
    r.footer_px = static_cast<int>(s.integer("footer_px", 0, 16384, r.footer_px));
    r.sigma_scale = s.number("sigma_scale", 0.1, 10.0, r.sigma_scale);
    r.min_span_m = s.number("min_span_m", 0.01, 1e6, r.min_span_m);
    r.ground_truth = s.boolean("ground_truth", r.ground_truth);
    r.landmark_ids = s.boolean("landmark_ids", r.landmark_ids);
    r.grid = s.boolean("grid", r.grid);
    r.legend = s.boolean("legend", r.legend);
    r.scale_bar = s.boolean("scale_bar", r.scale_bar);
    o.trajectory_min_step_m = s.number("trajectory_min_step_m", 0.0, 100.0, o.trajectory_min_step_m);
    o.snapshot_period_s = s.number("snapshot_period_s", 0.05, 3600.0, o.snapshot_period_s);
    o.snapshot_dir = s.text("snapshot_dir", o.snapshot_dir);
    if (o.snapshot_dir.empty()) s.fail("snapshot_dir", "must not be empty");
    o.window = s.boolean("window", o.window);
    s.finish();
    s.check_mapping([&] { validate(r); });
  }
  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, config_dir);
  }
  root.finish();
  return o;
}

MapViewOptions read_map_view_options_file(const std::string& path, const std::string& default_profiles_file) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_map_view_options(root, app::folder_of(path), default_profiles_file);
}

std::string to_yaml(const MapViewOptions& o) {
  const RenderOptions& r = o.render;
  auto flag = [](bool b) { return b ? "true" : "false"; };
  std::ostringstream os;
  os << "map_view:\n"
     << "  width_px: " << r.width_px << "\n"
     << "  height_px: " << r.height_px << "\n"
     << "  footer_px: " << r.footer_px << "\n"
     << "  sigma_scale: " << r.sigma_scale << "\n"
     << "  min_span_m: " << r.min_span_m << "\n"
     << "  ground_truth: " << flag(r.ground_truth) << "\n"
     << "  landmark_ids: " << flag(r.landmark_ids) << "\n"
     << "  grid: " << flag(r.grid) << "\n"
     << "  legend: " << flag(r.legend) << "\n"
     << "  scale_bar: " << flag(r.scale_bar) << "\n"
     << "  trajectory_min_step_m: " << o.trajectory_min_step_m << "\n"
     << "  snapshot_period_s: " << o.snapshot_period_s << "\n"
     << "  snapshot_dir: '" << o.snapshot_dir << "'\n"
     << "  window: " << flag(o.window) << "\n"
     << dds::to_yaml(o.dds);
  return os.str();
}

}  // namespace pixyslam::map_view
