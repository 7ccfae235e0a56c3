// pixyslam_spy: one inspection tool for the live system and its recordings,
// decoding with the project's own types (no XTypes needed).
//   pixyslam_spy participants | topics                     [DDS options] [--duration S]
//   pixyslam_spy echo TOPIC [--json] [--count N] [--duration S] [DDS options]
//   pixyslam_spy hz TOPIC [--duration S]                    [DDS options]
//   pixyslam_spy diagnostics [--duration S]                 [DDS options]
//   pixyslam_spy info FILE.mcap
//   pixyslam_spy check FILE.mcap [--expect TOPIC=N ...] [--allow-recovered]
//   pixyslam_spy print FILE.mcap [--topic T] [--json]
//   pixyslam_spy compare A.mcap B.mcap --topic T [--ignore F,...] [--tolerance X]
// DDS options: --config FILE (a YAML with a `dds:` mapping, e.g.
// config/slam_estimator.yaml; default: config/dds/profiles.xml on domain 0),
// --domain N. The same program is also built as pixyslam_log (info/check).
// Exit status: 0 ok, 1 check failed / too few samples / file unreadable or
// damaged (info, print, check; a file its writer did not close is not
// damaged: info and print exit 0, check needs --allow-recovered),
// 2 command-line or config error.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "log_commands.h"
#include "pixyslam/app/command_line.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "spy_commands.h"

#ifndef PIXYSLAM_TOOL_NAME  // pixyslam_spy or pixyslam_log: the same program
#define PIXYSLAM_TOOL_NAME "pixyslam_spy"
#endif
#ifndef PIXYSLAM_DEFAULT_PROFILES_FILE
#define PIXYSLAM_DEFAULT_PROFILES_FILE ""
#endif

namespace {

constexpr const char* kUsage =
    "usage: " PIXYSLAM_TOOL_NAME " participants [--duration S] [DDS options]\n"
    "       " PIXYSLAM_TOOL_NAME " topics [--duration S] [DDS options]\n"
    "       " PIXYSLAM_TOOL_NAME " echo TOPIC [--json] [--count N] [--duration S] [DDS options]\n"
    "       " PIXYSLAM_TOOL_NAME " hz TOPIC [--duration S] [DDS options]\n"
    "       " PIXYSLAM_TOOL_NAME " diagnostics [--duration S] [DDS options]\n"
    "       " PIXYSLAM_TOOL_NAME " info FILE.mcap\n"
    "       " PIXYSLAM_TOOL_NAME " check FILE.mcap [--expect TOPIC=N ...] [--allow-recovered]\n"
    "       " PIXYSLAM_TOOL_NAME " print FILE.mcap [--topic TOPIC] [--json]\n"
    "       " PIXYSLAM_TOOL_NAME " compare A.mcap B.mcap --topic TOPIC [--ignore FIELD,...] [--tolerance X]\n"
    "DDS options: --config FILE (YAML with a dds: mapping; default " PIXYSLAM_DEFAULT_PROFILES_FILE
    ", domain 0)\n"
    "             --domain N (overrides the file's domain_id)\n"
    "TOPIC: pixyslam/odometry, pixyslam/landmark_observation, pixyslam/map_state, pixyslam/ground_truth,\n"
    "       pixyslam/diagnostics, pixyslam/optimised_map\n";

// TOPIC=N, N a non-negative integer.
void add_expectation(const std::string& text, pixyslam::log_tool::CheckRequest& request) {
  const auto eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("--expect needs TOPIC=N, got '" + text + "'");
  }
  const std::string count = text.substr(eq + 1);
  if (count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18) {
    throw std::invalid_argument("--expect " + text + ": N must be a non-negative integer");
  }
  if (!request.expected.emplace(text.substr(0, eq), std::stoull(count)).second) {
    throw std::invalid_argument("--expect given twice for '" + text.substr(0, eq) + "'");
  }
}

double non_negative_number(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double v = -1.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v >= 0.0)) throw std::invalid_argument(flag + " needs a number >= 0, got '" + text + "'");
  return v;
}

// Everything after the subcommand.
struct Arguments {
  std::vector<std::string> positional;
  std::string dds_config;
  std::vector<std::string> dds_overrides;  // --domain
  double seconds = -1.0;  // -1: the command's default
  std::size_t count = 0;
  bool json = false;
  std::string topic;  // print --topic
  pixyslam::log_tool::CheckRequest check;
  pixyslam::log_tool::CompareRequest compare;
};

Arguments parse(const std::string& command, const std::vector<std::string>& args) {
  const bool live = command == "participants" || command == "topics" || command == "echo" || command == "hz" ||
                    command == "diagnostics";
  Arguments a;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw std::invalid_argument(arg + " needs a value");
      return args[++i];
    };
    if (live && arg == "--config") {
      a.dds_config = value();
    } else if (live && arg == "--domain") {
      a.dds_overrides.push_back(pixyslam::dds::domain_override(value()));
    } else if (live && arg == "--duration") {
      a.seconds = non_negative_number(arg, value());
    } else if (command == "echo" && arg == "--count") {
      const double c = non_negative_number(arg, value());
      if (c != static_cast<double>(static_cast<std::size_t>(c))) throw std::invalid_argument("--count must be an integer");
      a.count = static_cast<std::size_t>(c);
    } else if ((command == "echo" || command == "print") && arg == "--json") {
      a.json = true;
    } else if (command == "check" && arg == "--expect") {
      add_expectation(value(), a.check);
    } else if (command == "check" && arg.rfind("--expect=", 0) == 0) {
      add_expectation(arg.substr(9), a.check);
    } else if (command == "check" && arg == "--allow-recovered") {
      a.check.allow_recovered = true;
    } else if (command == "print" && arg == "--topic") {
      a.topic = value();
    } else if (command == "compare" && arg == "--topic") {
      a.compare.topic = value();
    } else if (command == "compare" && arg == "--ignore") {
      for (std::string& field : pixyslam::config::split_comma_list(value())) {
        a.compare.ignored.push_back(std::move(field));
      }
    } else if (command == "compare" && arg == "--tolerance") {
      a.compare.tolerance = non_negative_number(arg, value());
    } else if (arg.rfind("-", 0) == 0) {
      throw std::invalid_argument("unknown option '" + arg + "' for " + command);
    } else {
      a.positional.push_back(arg);
    }
  }
  if (command == "compare") {
    if (a.positional.size() != 2) throw std::invalid_argument("compare needs exactly two MCAP files");
    if (a.compare.topic.empty()) throw std::invalid_argument("compare needs --topic");
    return a;
  }
  const std::size_t wanted = (command == "participants" || command == "topics" || command == "diagnostics") ? 0 : 1;
  if (a.positional.size() != wanted) {
    const char* what = command == "info" || command == "check" || command == "print" ? "an MCAP file" : "a TOPIC";
    if (wanted == 0) throw std::invalid_argument(command + " takes no positional argument");
    throw std::invalid_argument(command + " needs exactly " + what);
  }
  return a;
}

pixyslam::dds::DdsOptions dds_options(const Arguments& a) {
  using namespace pixyslam;
  dds::DdsOptions o = dds::read_dds_options_file(a.dds_config, PIXYSLAM_DEFAULT_PROFILES_FILE);
  dds::resolve_settings(o, a.dds_overrides);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const auto status = app::usage_exit(args, kUsage)) return *status;
  const std::string& command = args[0];
  Arguments a;
  try {
    if (command != "participants" && command != "topics" && command != "echo" && command != "hz" &&
        command != "diagnostics" &&
        command != "info" && command != "check" && command != "compare" &&
        command != "print") {
      throw std::invalid_argument("unknown command '" + command + "'");
    }
    a = parse(command, args);
    if (command == "info" || command == "check" || command == "compare" || command == "print") {
      app::require_files(a.positional);
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, PIXYSLAM_TOOL_NAME ": %s\n%s", e.what(), kUsage);
    return 2;
  }

  try {
    if (command == "info") return log_tool::run_info(a.positional[0], std::cout, std::cerr);
    if (command == "print") return log_tool::run_print({a.positional[0], a.topic, a.json}, std::cout, std::cerr);
    if (command == "compare") {
      a.compare.first_path = a.positional[0];
      a.compare.second_path = a.positional[1];
      return log_tool::run_compare(a.compare, std::cout);
    }
    if (command == "check") {
      a.check.path = a.positional[0];
      return log_tool::run_check(a.check, std::cout, std::cerr);
    }
    const dds::DdsOptions options = dds_options(a);
    if (command == "participants") return log_tool::run_participants(options, a.seconds < 0 ? 4.0 : a.seconds, std::cout);
    if (command == "topics") return log_tool::run_topics(options, a.seconds < 0 ? 4.0 : a.seconds, std::cout);
    if (command == "diagnostics") {
      return log_tool::run_diagnostics(options, a.seconds < 0 ? 3.0 : a.seconds, std::cout);
    }
    if (command == "hz") return log_tool::run_hz(options, a.positional[0], a.seconds < 0 ? 5.0 : a.seconds, std::cout);
    log_tool::EchoRequest request;
    request.topic = a.positional[0];
    request.json = a.json;
    request.count = a.count;
    request.seconds = a.seconds < 0 ? 0.0 : a.seconds;
    return log_tool::run_echo(options, request, std::cout);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, PIXYSLAM_TOOL_NAME ": config error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, PIXYSLAM_TOOL_NAME ": %s\n", e.what());
    return 1;
  }
}
