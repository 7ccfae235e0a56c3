#pragma once

#include <string>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options.h"

namespace pixyslam::slam {

// Reads the `filter:` mapping (see config/slam_*.yaml for every key, its unit and
// range). Missing keys keep the FilterOptions defaults; unknown keys, wrong types
// and out-of-range values throw config::ConfigError naming file and key path.
FilterOptions read_filter_options(config::YamlReader& filter);

// Convenience for files that hold only a `filter:` mapping.
FilterOptions read_filter_options_file(const std::string& path);

}  // namespace pixyslam::slam
