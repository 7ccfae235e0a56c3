#pragma once

// Reading an options struct's YAML section with its parameter table
// (pixyslam/parameters/parameters.h): every key read with the table's range,
// nested mappings by the paths' prefixes, unknown keys refused (finish()),
// required keys demanded.
#include <cstdio>
#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::config {

// The key to read `p` from in this mapping: its former name when the file
// still uses that (with a warning on stderr naming the file and both keys), else `key`.
template <class Options>
std::string renamed_key(const YamlReader& section, const parameters::Parameter<Options>& p, const std::string& prefix,
                        const std::string& key) {
  if (p.old_path.empty() || p.old_path.compare(0, prefix.size(), prefix) != 0) return key;
  const std::string old_key = p.old_path.substr(prefix.size());
  if (!section.has(old_key)) return key;
  if (section.has(key)) section.fail(old_key, "renamed '" + section.key_path(key) + "', which is given too: keep one");
  std::fprintf(stderr, "%s: key '%s' is deprecated: it was renamed '%s' (read as that; rename it in the file)\n",
               section.origin().c_str(), section.key_path(old_key).c_str(), section.key_path(key).c_str());
  return old_key;
}

// Reads the keys of `table` under `section` (paths below `prefix`) into `o`;
// absent keys keep o's value. Finishes the nested mappings it opens; the
// caller finishes `section`. Throws ConfigError naming file, key and range.
template <class Options>
void read_parameters(YamlReader& section, const parameters::Table<Options>& table, Options& o,
                     const std::string& prefix = "") {
  std::vector<std::string> groups;
  for (const parameters::Parameter<Options>& p : table) {
    if (p.path.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string path = p.path.substr(prefix.size());
    const auto dot = path.find('.');
    if (dot != std::string::npos) {
      const std::string group = path.substr(0, dot);
      bool seen = false;
      for (const std::string& g : groups) seen = seen || g == group;
      if (!seen) groups.push_back(group);
      continue;
    }
    const std::string key = renamed_key(section, p, prefix, path);
    if (p.required && !section.has(key)) section.fail(key, "missing (required: " + p.help + ")");
    switch (p.kind) {
      case parameters::Kind::kReal: p.set(o, section.number(key, p.min, p.max, p.get(o))); break;
      case parameters::Kind::kInteger:
        p.set(o, static_cast<double>(section.integer(key, static_cast<std::int64_t>(p.min),
                                                     static_cast<std::int64_t>(p.max),
                                                     static_cast<std::int64_t>(p.get(o)))));
        break;
      case parameters::Kind::kBoolean: p.set(o, section.boolean(key, p.get(o) != 0.0) ? 1.0 : 0.0); break;
      case parameters::Kind::kChoice: p.set_choice(o, section.choice(key, p.choices, p.get_choice(o))); break;
      case parameters::Kind::kText:
      case parameters::Kind::kList:
        if (!section.has(key)) break;
        if (p.kind == parameters::Kind::kText) {
          p.set_choice(o, section.text(key));
        } else {
          std::string joined;
          for (const std::string& item : section.text_list(key)) {
            if (item.find(',') != std::string::npos) section.fail(key, "'" + item + "' contains a comma");
            joined += (joined.empty() ? "" : ",") + item;
          }
          p.set_choice(o, joined);
        }
        try {
          parameters::check_text(p, o);
        } catch (const std::invalid_argument& e) {
          section.fail(key, "value " + parameters::value_text(p, o) + " is " + e.what());
        }
        break;
    }
  }
  for (const std::string& group : groups) {
    if (!section.has(group)) continue;
    YamlReader child = section.child(group);
    read_parameters(child, table, o, prefix + group + ".");
    child.finish();
  }
}

// Runs `validate` (the rules between a section's keys): a
// parameters::RuleError becomes the error on its key, any other
// std::invalid_argument an error on the section. Throws ConfigError.
template <class Validate>
void check_rules(const YamlReader& section, const Validate& validate) {
  try {
    validate();
  } catch (const parameters::RuleError& e) {
    section.fail(e.path(), e.reason());
  } catch (const std::invalid_argument& e) {
    section.check_mapping([&] { throw e; });
  }
}

}  // namespace pixyslam::config
