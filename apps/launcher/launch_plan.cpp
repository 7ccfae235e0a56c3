#include "launch_plan.h"

#include <set>
#include <stdexcept>

#include "pixyslam/config/yaml_reader.h"

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

std::vector<ProcessSpec> read_processes(config::YamlReader& launch, const std::string& key,
                                        const std::map<std::string, std::string>& variables,
                                        std::set<std::string>& names) {
  std::vector<ProcessSpec> out;
  if (!launch.has(key)) return out;
  for (config::YamlReader& item : launch.mapping_list(key)) {
    ProcessSpec p;
    p.name = item.text("name");
    if (p.name.empty() || !names.insert(p.name).second) {
      item.fail("name", "'" + p.name + "' is empty or used twice");
    }
    for (const std::string& word : item.text_list("command")) {
      try {
        p.command.push_back(substitute(word, variables));
      } catch (const std::invalid_argument& e) {
        item.fail("command", e.what());
      }
    }
    if (p.command.empty()) item.fail("command", "must list the program and its arguments");
    p.delay_s = item.number("delay_s", 0.0, 600.0, 0.0);
    p.ends_run = item.boolean("ends_run", false);
    const std::string role = item.text("role", "essential");
    if (role != "essential" && role != "optional") {
      item.fail("role", "'" + role + "' is not a role (essential | optional)");
    }
    p.optional = role == "optional";
    if (p.optional && p.ends_run) item.fail("role", "an optional process cannot end the run (ends_run)");
    item.finish();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

LaunchPlan read_launch_plan(const std::string& path, const std::map<std::string, std::string>& variables) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader launch = root.child("launch");
  LaunchPlan plan;
  plan.duration_s = launch.number("duration_s", 0.0, 1e6, plan.duration_s);
  plan.stop_timeout_s = launch.number("stop_timeout_s", 0.1, 600.0, plan.stop_timeout_s);
  std::set<std::string> names;
  plan.processes = read_processes(launch, "processes", variables, names);
  if (plan.processes.empty()) launch.fail("processes", "must list at least one process");
  plan.after_run = read_processes(launch, "after_run", variables, names);
  launch.finish();
  root.finish();
  return plan;
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
