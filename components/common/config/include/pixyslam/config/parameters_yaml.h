#pragma once

// Reading an options struct's YAML section with its parameter table
// (pixyslam/parameters/parameters.h): every key read with the table's range,
// nested mappings by the paths' prefixes, unknown keys refused (finish()).
#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::config {

// Reads the keys of `table` under `section` (paths below `prefix`) into `o`;
// absent keys keep o's value. Finishes the nested mappings it opens; the
// caller finishes `section`. Throws ConfigError naming file, key and range.
template <class Options>
void read_parameters(YamlReader& section, const parameters::Table<Options>& table, Options& o,
                     const std::string& prefix = "") {
  std::vector<std::string> groups;
  for (const parameters::Parameter<Options>& p : table) {
    if (p.path.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string key = p.path.substr(prefix.size());
    const auto dot = key.find('.');
    if (dot != std::string::npos) {
      const std::string group = key.substr(0, dot);
      bool seen = false;
      for (const std::string& g : groups) seen = seen || g == group;
      if (!seen) groups.push_back(group);
      continue;
    }
    switch (p.kind) {
      case parameters::Kind::kReal: p.set(o, section.number(key, p.min, p.max, p.get(o))); break;
      case parameters::Kind::kInteger:
        p.set(o, static_cast<double>(section.integer(key, static_cast<std::int64_t>(p.min),
                                                     static_cast<std::int64_t>(p.max),
                                                     static_cast<std::int64_t>(p.get(o)))));
        break;
      case parameters::Kind::kBoolean: p.set(o, section.boolean(key, p.get(o) != 0.0) ? 1.0 : 0.0); break;
      case parameters::Kind::kChoice: p.set_choice(o, section.choice(key, p.choices, p.get_choice(o))); break;
    }
  }
  for (const std::string& group : groups) {
    if (!section.has(group)) continue;
    YamlReader child = section.child(group);
    read_parameters(child, table, o, prefix + group + ".");
    child.finish();
  }
}

}  // namespace pixyslam::config
