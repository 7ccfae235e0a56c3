#pragma once

#include <string>
#include <vector>

namespace pixyslam::config {

// Scalars for YAML that YamlReader reads back to the same values (the
// effective-configuration dumps, to_yaml()).

// Shortest text that reads back as the same double ("0.1", "1e-05").
std::string yaml_number(double value);
// A double-quoted YAML string (" and \ escaped).
std::string yaml_quoted(const std::string& text);

}  // namespace pixyslam::config
