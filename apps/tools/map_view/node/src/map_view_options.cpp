#include "pixyslam/map_view/map_view_options.h"

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/parameters_yaml.h"

namespace pixyslam::map_view {

const parameters::Table<MapViewOptions>& map_view_parameters() {
  using O = MapViewOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("trajectory_min_step_m", 0.0, 100.0, "m", "trajectories keep a point only this far from the last",
                 [](O& o) -> double& { return o.trajectory_min_step_m; }),
      P::real<O>("snapshot_period_s", 0.05, 3600.0, "s", "live view redraw and snapshot period",
                 [](O& o) -> double& { return o.snapshot_period_s; }),
      P::text<O>("snapshot_dir", "live snapshots go to <dir>/map_latest.png", [](O& o) -> std::string& { return o.snapshot_dir; },
                 [](const std::string& v) {
                   if (v.empty()) throw std::invalid_argument("empty");
                 }),
      P::boolean<O>("window", "open a window when a display is available", [](O& o) -> bool& { return o.window; }),
  };
  return table;
}

void apply_overrides(MapViewOptions& o, std::vector<std::string>& assignments) {
  for (const std::string& a : parameters::take_section(assignments, "map_view")) {
    parameters::apply_override_to_either(o.render, render_parameters(), o, map_view_parameters(), "map_view", a);
  }
  validate(o.render);
  parameters::check_ranges(o, map_view_parameters(), "map_view");
}

std::string help_text() {
  return "map_view parameters (map_view:):\n" + parameters::help_text(render_parameters(), "map_view") +
         parameters::help_text(map_view_parameters(), "map_view") +
         "DDS settings of live (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

MapViewOptions read_map_view_options(config::YamlReader& root, const std::string& config_dir,
                                     const std::string& default_profiles_file) {
  MapViewOptions o;
  o.dds.profiles_file = default_profiles_file;
  if (root.has("map_view")) {
    config::YamlReader s = root.child("map_view");
    config::read_parameters(s, render_parameters(), o.render);
    config::read_parameters(s, map_view_parameters(), o);
    s.finish();
    config::check_rules(s, [&] { validate(o.render); });
  }
  o.dds = dds::read_dds_section(root, config_dir, o.dds);
  root.finish();
  return o;
}

MapViewOptions read_map_view_options_file(const std::string& path, const std::string& default_profiles_file) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_map_view_options(root, config::folder_of(path), default_profiles_file);
}

std::string to_yaml(const MapViewOptions& o) {
  return parameters::to_yaml(o.render, render_parameters(), "map_view") +
         parameters::to_yaml(o, map_view_parameters(), "map_view").substr(10) + dds::to_yaml(o.dds);
}

}  // namespace pixyslam::map_view
