#include "pixyslam/launcher/launch_plan.h"

#include <algorithm>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::launcher {

std::string substitute(const std::string& text, const std::map<std::string, std::string>& variables) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t start = text.find("${", i);
    if (start == std::string::npos) {
      out.append(text, i, std::string::npos);
      break;
    }
    const std::size_t end = text.find('}', start);
    if (end == std::string::npos) throw std::invalid_argument("unterminated ${ in '" + text + "'");
    const std::string name = text.substr(start + 2, end - start - 2);
    auto it = variables.find(name);
    if (it == variables.end()) throw std::invalid_argument("unknown variable ${" + name + "} in '" + text + "'");
    out.append(text, i, start - i);
    out += it->second;
    i = end + 1;
  }
  return out;
}

namespace {

constexpr const char* kDurationArgument = "duration";

// One process of `item` with these variables.
ProcessSpec read_process(config::YamlReader& item, const std::map<std::string, std::string>& variables,
                         const std::vector<LaunchArgument>& arguments) {
  const auto expand = [&](const std::string& word, config::YamlReader& where, const std::string& key_name) {
    try {
      return substitute(word, variables);
    } catch (const std::invalid_argument& e) {
      where.fail(key_name, e.what());
    }
    return std::string();
  };
  ProcessSpec p;
  p.name = expand(item.text("name"), item, "name");
  for (const std::string& word : item.text_list("command")) p.command.push_back(expand(word, item, "command"));
  if (p.command.empty()) item.fail("command", "must list the program and its arguments");
  if (item.has("if_given")) {
    config::YamlReader extra = item.child("if_given");
    for (const std::string& name : extra.keys()) {
      const bool declared = std::any_of(arguments.begin(), arguments.end(),
                                        [&](const LaunchArgument& a) { return a.name == name; });
      if (!declared) extra.fail(name, "not a declared launch argument (launch.arguments)");
      const std::vector<std::string> words = extra.text_list(name);
      if (variables.at(name).empty()) continue;
      for (const std::string& word : words) p.command.push_back(expand(word, extra, name));
    }
    extra.finish();
  }
  p.delay_s = item.number("delay_s", 0.0, 600.0, 0.0);
  p.ends_run = item.boolean("ends_run", false);
  const std::string role = item.text("role", "essential");
  if (role != "essential" && role != "optional") {
    item.fail("role", "'" + role + "' is not a role (essential | optional)");
  }
  p.optional = role == "optional";
  if (p.optional && p.ends_run) item.fail("role", "an optional process cannot end the run (ends_run)");
  return p;
}

std::vector<ProcessSpec> read_processes(config::YamlReader& launch, const std::string& key,
                                        const std::map<std::string, std::string>& variables,
                                        const std::vector<LaunchArgument>& arguments, std::set<std::string>& names) {
  std::vector<ProcessSpec> out;
  if (!launch.has(key)) return out;
  for (config::YamlReader& item : launch.mapping_list(key)) {
    // for_each: {NAME: 'A,B,...'}: one process per value, ${NAME} set to it.
    std::string each_name;
    std::vector<std::string> each_values = {""};
    if (item.has("for_each")) {
      config::YamlReader each = item.child("for_each");
      const std::vector<std::string> keys = each.keys();
      if (keys.size() != 1) item.fail("for_each", "needs exactly one NAME: 'VALUE,VALUE,...'");
      each_name = keys.front();
      if (variables.count(each_name) != 0) {
        each.fail(each_name, "is already a variable (a launch argument or the launcher's)");
      }
      try {
        each_values = parameters::split_list(substitute(each.text(each_name), variables));
      } catch (const std::invalid_argument& e) {
        each.fail(each_name, e.what());
      }
      if (each_values.empty()) each.fail(each_name, "no value (a comma-separated list is required)");
      each.finish();
    }
    for (const std::string& value : each_values) {
      std::map<std::string, std::string> process_variables = variables;
      if (!each_name.empty()) process_variables[each_name] = value;
      ProcessSpec p = read_process(item, process_variables, arguments);
      if (p.name.empty() || !names.insert(p.name).second) {
        item.fail("name", "'" + p.name + "' is empty or used twice" +
                              (each_name.empty() ? "" : " (with for_each, put ${" + each_name + "} in the name)"));
      }
      out.push_back(std::move(p));
    }
    item.finish();
  }
  return out;
}

}  // namespace

LaunchPlan read_launch_plan(const std::string& path, const std::map<std::string, std::string>& variables,
                            const std::map<std::string, std::string>& given) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader launch = root.child("launch");
  LaunchPlan plan;
  plan.duration_s = launch.number("duration_s", 0.0, kMaxDurationS, plan.duration_s);
  plan.stop_timeout_s = launch.number("stop_timeout_s", 0.1, 600.0, plan.stop_timeout_s);
  std::map<std::string, std::string> values = variables;
  if (launch.has("arguments")) {
    config::YamlReader declared = launch.child("arguments");
    for (const std::string& name : declared.keys()) {
      if (name == kDurationArgument || variables.count(name) != 0 || name.empty() ||
          name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos) {
        declared.fail(name, "not a free argument name (lower case, digits, '_'; not duration or a launcher variable)");
      }
      config::YamlReader a = declared.child(name);
      LaunchArgument argument{name, a.text("default", ""), a.text("help")};
      a.finish();
      const auto it = given.find(name);
      values[name] = it != given.end() ? it->second : argument.default_value;
      plan.arguments.push_back(std::move(argument));
    }
    declared.finish();
  }
  for (const auto& [name, value] : given) {
    if (name == kDurationArgument) {
      const std::optional<double> seconds = parameters::parse_number(value);
      if (!seconds || !(*seconds >= 0.0 && *seconds <= kMaxDurationS)) {
        throw config::ConfigError("duration:=" + value + ": must be seconds in [0, " +
                                  parameters::number_text(kMaxDurationS) + "] (0: no limit)");
      }
      plan.duration_s = *seconds;
    } else if (values.count(name) == 0 || variables.count(name) != 0) {
      std::string known = kDurationArgument;
      for (const LaunchArgument& a : plan.arguments) known += ", " + a.name;
      throw config::ConfigError(path + ": no launch argument '" + name + "' (this file declares: " + known + ")");
    }
  }
  std::set<std::string> names;
  plan.processes = read_processes(launch, "processes", values, plan.arguments, names);
  if (plan.processes.empty()) launch.fail("processes", "must list at least one process");
  plan.after_run = read_processes(launch, "after_run", values, plan.arguments, names);
  launch.finish();
  root.finish();
  return plan;
}

std::map<std::string, std::string> split_launch_arguments(std::vector<std::string>& words) {
  std::map<std::string, std::string> given;
  std::vector<std::string> rest;
  for (const std::string& word : words) {
    const auto op = word.find(":=");
    if (op == std::string::npos || word.rfind("-", 0) == 0) {
      rest.push_back(word);
      continue;
    }
    const std::string name = word.substr(0, op);
    if (name.empty()) throw std::invalid_argument("'" + word + "': NAME:=VALUE needs a name");
    if (!given.emplace(name, word.substr(op + 2)).second) {
      throw std::invalid_argument("launch argument '" + name + "' given twice");
    }
  }
  words = std::move(rest);
  return given;
}

std::string arguments_text(const LaunchPlan& plan) {
  char duration[32];
  std::snprintf(duration, sizeof duration, "%g", plan.duration_s);
  std::string out = "launch arguments (NAME:=VALUE):\n  duration  seconds until the run is stopped (0: no limit), default " +
                    std::string(duration) + "\n";
  for (const LaunchArgument& a : plan.arguments) {
    out += "  " + a.name + "  " + a.help + (a.default_value.empty() ? "" : ", default '" + a.default_value + "'") +
           "\n";
  }
  return out;
}

std::vector<std::string> LineSplitter::feed(const char* data, std::size_t size) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      lines.push_back(std::move(pending_));
      pending_.clear();
    } else {
      pending_.push_back(data[i]);
      if (pending_.size() >= max_line_) {
        lines.push_back(std::move(pending_));
        pending_.clear();
      }
    }
  }
  return lines;
}

std::vector<std::string> LineSplitter::finish() {
  std::vector<std::string> lines;
  if (!pending_.empty()) lines.push_back(std::move(pending_));
  pending_.clear();
  return lines;
}

}  // namespace pixyslam::launcher
