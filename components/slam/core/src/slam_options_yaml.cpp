#include "pixyslam/slam/slam_options_yaml.h"

#include <stdexcept>

#include "pixyslam/config/parameters_yaml.h"

namespace pixyslam::slam {

FilterOptions read_filter_options(config::YamlReader& f) {
  FilterOptions o;
  config::read_parameters(f, filter_parameters(), o);
  f.finish();
  config::check_rules(f, [&] { validate(o); });
  return o;
}

FilterOptions read_filter_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader filter = root.child("filter");
  FilterOptions o = read_filter_options(filter);
  root.finish();
  return o;
}

}  // namespace pixyslam::slam
