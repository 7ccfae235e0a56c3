#pragma once

#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::dds {

// The `topics` list of a process's section (names, globs, '!' exclusions:
// select_topics() over known_topics()), resolved to topic names in the order
// of known_topics(); every topic when the key is absent. A bad pattern or an
// empty list fails on `section` (file and key path).
std::vector<std::string> read_topic_patterns(config::YamlReader& section);

}  // namespace pixyslam::dds
