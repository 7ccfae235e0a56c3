// pixyslam_spy: one inspection tool for the live system and its recordings,
// decoding with the project's own types (no XTypes needed).
//   pixyslam_spy participants | topics [--json]            [DDS options] [--duration S]
//   pixyslam_spy echo TOPIC [--json] [--count N] [--duration S] [DDS options]
//   pixyslam_spy hz TOPIC [--json] [--duration S]           [DDS options]
//   pixyslam_spy diagnostics [--json] [--duration S]        [DDS options]
//   pixyslam_spy record [TOPIC ...] [--out FILE.mcap] [--duration S] [--set logger.KEY=V] [DDS options]
//   pixyslam_spy info FILE.mcap [--json]
//   pixyslam_spy check FILE.mcap [--expect TOPIC=N ...] [--allow-recovered]
//   pixyslam_spy print FILE.mcap [--topics T] [--json]
//   pixyslam_spy compare A.mcap B.mcap --topic T [--ignore F,...] [--tolerance X] [--match F,... [--max-unmatched N]]
// DDS options: --config FILE (a YAML with a `dds:` mapping, e.g.
// config/slam_estimator.yaml; default: config/dds/profiles.xml on domain 0),
// --domain N. The same program is also built as pixyslam_log (info/check).
// Exit status: 0 ok, 1 check failed / too few samples / file unreadable or
// damaged (info, print, check; a file its writer did not close is not
// damaged: info and print exit 0, check needs --allow-recovered),
// 2 command-line or config error.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pixyslam/log_tool/log_commands.h"
#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/log_tool/spy_commands.h"
#include "pixyslam/logger_node/logger_run.h"

#ifndef PIXYSLAM_TOOL_NAME  // pixyslam_spy or pixyslam_log: the same program
#define PIXYSLAM_TOOL_NAME "pixyslam_spy"
#endif

namespace {

// TOPIC=N, N a non-negative integer.
void add_expectation(const std::string& text, pixyslam::log_tool::CheckRequest& request) {
  const auto eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw pixyslam::app::UsageError("--expect needs TOPIC=N, got '" + text + "'");
  }
  const std::string count = text.substr(eq + 1);
  if (count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18) {
    throw pixyslam::app::UsageError("--expect " + text + ": N must be a non-negative integer");
  }
  if (!request.expected.emplace(text.substr(0, eq), std::stoull(count)).second) {
    throw pixyslam::app::UsageError("--expect given twice for '" + text.substr(0, eq) + "'");
  }
}

// "TOPIC: pixyslam/odometry, ..." for the help footers: every topic of the system, wrapped.
std::string topics_help() {
  std::string out = "TOPIC: ", line = out;
  const auto& topics = pixyslam::dds::known_topics();
  for (std::size_t i = 0; i < topics.size(); ++i) {
    const std::string item = std::string(topics[i].topic) + (i + 1 < topics.size() ? "," : "");
    if (line.size() + item.size() + 1 > 100) {
      out += "\n       ";
      line = "       ";
    } else if (i > 0) {
      out += " ";
      line += " ";
    }
    out += item;
    line += item;
  }
  return out;
}

// The DDS settings of a live command: --config FILE, --domain N.
struct DdsArguments {
  std::string config;
  std::vector<std::string> overrides;  // --domain

  void add_to(pixyslam::app::Cli& command) {
    command
        .option("--config", config,
                std::string("a YAML with a dds: mapping (default ") + pixyslam::dds::default_profiles_file() + ", domain 0)")
        .existing_file()
        .type("FILE");
    pixyslam::app::add_domain(command, overrides);
  }
  pixyslam::dds::DdsOptions resolve() const {
    pixyslam::dds::DdsOptions o = pixyslam::dds::read_dds_options_file(config, pixyslam::dds::default_profiles_file());
    pixyslam::dds::resolve_settings(o, overrides);
    return o;
  }
};

// pixyslam_YYYY_MM_DD-HH_MM_SS.mcap in local time, as ros2 bag names its bags.
std::string default_recording_name() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof(name), "pixyslam_%Y_%m_%d-%H_%M_%S.mcap", &local);
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  app::Cli cli{PIXYSLAM_TOOL_NAME,
               "Inspects the live system (participants, topics, echo, hz, diagnostics), records it (record) and "
               "reads its recordings (info, check, print, compare), decoding with the project's own types."};
  cli.footer(topics_help() + "\nExit status: 0 ok, 1 check failed / too few samples / file unreadable or "
                                    "damaged, 2 command-line or config error.");
  DdsArguments dds_args;
  bool json = false;  // --json of participants, topics, diagnostics, hz, info
  const char* json_help = "JSON lines (one object per line) instead of the table";
  double seconds = -1.0;  // -1: the command's default
  auto add_duration = [&](app::Cli& command, const char* default_s) {
    command.option("--duration", seconds, std::string("listen S seconds (default ") + default_s + ")")
        .non_negative()
        .type("S");
  };
  app::Cli& participants = cli.subcommand("participants", "the participants on the domain: process, host, pid");
  add_duration(participants, "4");
  participants.flag("--json", json, json_help);
  dds_args.add_to(participants);
  app::Cli& topics = cli.subcommand("topics", "the topics on the domain with their types, writers and readers");
  add_duration(topics, "4");
  topics.flag("--json", json, json_help);
  dds_args.add_to(topics);
  app::Cli& diagnostics = cli.subcommand("diagnostics", "each process's counters (the diagnostics topic)");
  add_duration(diagnostics, "3");
  diagnostics.flag("--json", json, json_help);
  dds_args.add_to(diagnostics);

  log_tool::EchoRequest echo_request;
  int count = 0;
  app::Cli& echo = cli.subcommand("echo", "prints a topic's samples, the newest kept one first");
  echo.option("topic", echo_request.topic, "the topic").required().type("TOPIC");
  echo.flag("--json", echo_request.json, "one JSON object per line");
  echo.option("--count", count, "stop after N samples (0: no limit)").non_negative().type("N");
  // --robot-id as in dds.robot_id (--robot elsewhere is an MRCLAM robot number); --robot still accepted.
  echo.option("--robot-id,--robot", echo_request.robot,
              "only this robot's samples (header.robot_id; --robot: its old name, deprecated)")
      .type("ID");
  add_duration(echo, "0: until Ctrl-C or --count");
  dds_args.add_to(echo);

  std::string hz_topic;
  app::Cli& hz = cli.subcommand("hz", "a topic's rate, updated every second like ros2 topic hz");
  hz.option("topic", hz_topic, "the topic").required().type("TOPIC");
  hz.flag("--json", json, "a JSON line every second and one for the summary");
  std::string hz_robot;
  hz.option("--robot-id,--robot", hz_robot, "only this robot's samples (header.robot_id; --robot: its old name, deprecated)")
      .type("ID");
  add_duration(hz, "5");
  dds_args.add_to(hz);

  std::vector<std::string> record_topics;
  std::string record_out;
  std::vector<std::string> record_sets;
  app::Cli& record =
      cli.subcommand("record", "records topics to an MCAP file until Ctrl-C or --duration, like ros2 bag record");
  record.option("topics", record_topics, "names or patterns, '!' to leave out (default: every topic)")
      .type("TOPIC");
  std::string record_topic_list;
  record.option("--topics", record_topic_list, "the same as a comma-separated list, as the logger's --topics")
      .type("LIST");
  record
      .option("--out", record_out,
              "the recording (default pixyslam_YYYY_MM_DD-HH_MM_SS.mcap; a file holding data is kept and the next "
              "free _NNN name written)")
      .type("FILE.mcap");
  add_duration(record, "0: until Ctrl-C");
  app::add_set(record, record_sets, "logger.compression=lz4");
  dds_args.add_to(record);
  record.footer(topics_help() + "\nParameters for --set (and dds.KEY: the logger's --help):\n" +
                parameters::help_text(logger_node::logger_parameters(), "logger") +
                "Exit status: 0 stopped by Ctrl-C or --duration, 1 the recording failed or lost samples to write "
                "failures, 2 command-line or config error.");

  std::string info_file;
  app::Cli& info = cli.subcommand("info", "a recording's topics, counts, rates and times");
  info.option("file", info_file, "the MCAP file").required().input_file().type("FILE.mcap");
  info.flag("--json", json, "one JSON object instead of the text");

  log_tool::CheckRequest check_request;
  app::Cli& check = cli.subcommand("check", "a recording is whole: every sequence 1..N, no damage");
  check.option("file", check_request.path, "the MCAP file").required().input_file().type("FILE.mcap");
  check
      .option_each(
          "--expect", [&](const std::string& e) { add_expectation(e, check_request); },
          "TOPIC holds exactly N messages (repeatable)")
      .type("TOPIC=N");
  check.flag("--allow-recovered", check_request.allow_recovered, "a file its writer did not close passes");

  log_tool::PrintRequest print_request;
  app::Cli& print = cli.subcommand("print", "a recording's messages, decoded");
  print.option("file", print_request.path, "the MCAP file").required().input_file().type("FILE.mcap");
  std::string print_topics;
  print.option("--topics,--topic", print_topics,
               "comma-separated names, globs, !exclusions, as pixyslam_play's (default: every topic; --topic: its "
               "old name)")
      .type("LIST");
  print.flag("--json", print_request.json, "one JSON object per line");

  log_tool::CompareRequest compare_request;
  std::vector<std::string> compare_files;
  std::string ignored;
  app::Cli& compare = cli.subcommand("compare", "two recordings' messages of one topic, field by field");
  compare.option("files", compare_files, "the two MCAP files").required().input_file().type("A.mcap B.mcap");
  compare.option("--topic", compare_request.topic, "the topic").required().type("TOPIC");
  compare.option("--ignore", ignored, "fields not compared").type("FIELD,...");
  compare.option("--tolerance", compare_request.tolerance, "largest difference of a number taken as equal")
      .non_negative()
      .type("X");
  std::string match;
  compare.option("--match", match,
                 "pair messages by these fields instead of by position (e.g. odometry_sequence,observation_sequence: "
                 "MapStates that include the same inputs)")
      .type("FIELD,...");
  compare.option("--max-unmatched", compare_request.max_unmatched,
                 "messages of each file without a partner that still pass (default 0)")
      .type("N");
  compare.flag("--until-unmatched", compare_request.until_unmatched,
               "with --match: pairs after the first message without a partner may differ (inputs taken in "
               "another order from there); those before it must agree, and at least half of all pairs must");

  log_tool::FoxgloveRequest foxglove_request;
  std::vector<std::string> foxglove_files;
  app::Cli& foxglove = cli.subcommand(
      "foxglove", "a copy of a recording with 3D scene channels for Foxglove (SceneUpdate, PosesInFrame, FrameTransform)");
  foxglove.option("files", foxglove_files, "the recording and the new file").required().type("IN.mcap OUT.mcap");
  foxglove.option("--compression", foxglove_request.compression, "chunk compression of OUT")
      .choices({"none", "zstd", "lz4"});

  try {
    if (const auto done = cli.parse(argc, argv)) return *done;
  } catch (const app::UsageError& e) {  // from --expect
    std::fprintf(stderr, PIXYSLAM_TOOL_NAME ": %s (see --help)\n", e.what());
    return 2;
  }
  return app::run_main(PIXYSLAM_TOOL_NAME, [&]() -> int {
    if (info.chosen()) return log_tool::run_info(info_file, json, std::cout, std::cerr);
    if (print.chosen()) {
      print_request.topics = parameters::split_list(print_topics);
      if (print.given("--topics") && print_request.topics.empty()) {
        throw app::UsageError("--topics needs at least one topic");
      }
      return log_tool::run_print(print_request, std::cout, std::cerr);
    }
    if (check.chosen()) return log_tool::run_check(check_request, std::cout, std::cerr);
    if (compare.chosen()) {
      if (compare_files.size() != 2) throw app::UsageError("compare needs exactly two MCAP files");
      compare_request.first_path = compare_files[0];
      compare_request.second_path = compare_files[1];
      for (std::string& field : parameters::split_list(ignored)) compare_request.ignored.push_back(std::move(field));
      for (std::string& field : parameters::split_list(match)) compare_request.match.push_back(std::move(field));
      if (compare_request.until_unmatched && compare_request.match.empty()) {
        throw app::UsageError("--until-unmatched needs --match");
      }
      return log_tool::run_compare(compare_request, std::cout);
    }
    if (foxglove.chosen()) {
      if (foxglove_files.size() != 2) throw app::UsageError("foxglove needs the recording and the new file");
      foxglove_request.input_path = foxglove_files[0];
      foxglove_request.output_path = foxglove_files[1];
      if (std::filesystem::exists(foxglove_request.output_path) &&
          std::filesystem::equivalent(foxglove_request.input_path, foxglove_request.output_path)) {
        throw app::UsageError("foxglove: OUT is IN; write a new file");
      }
      return log_tool::run_foxglove(foxglove_request, std::cerr);
    }
    if (record.chosen()) {
      logger_node::LoggerOptions o;
      try {
        o.output_file = record_out.empty() ? default_recording_name() : record_out;
        for (const std::string& t : parameters::split_list(record_topic_list)) record_topics.push_back(t);
        o.topics = logger_node::select_known_topics(record_topics.empty() ? std::vector<std::string>{"*"} : record_topics,
                                                    "record");
        o.dds = dds::read_dds_options_file(dds_args.config, dds::default_profiles_file());
        record_sets.insert(record_sets.end(), dds_args.overrides.begin(), dds_args.overrides.end());
        logger_node::apply_overrides(o, record_sets);
      } catch (const std::invalid_argument& e) {
        throw app::UsageError(e.what());
      }
      return logger_node::record_until_stopped(o, PIXYSLAM_TOOL_NAME, seconds < 0 ? 0.0 : seconds);
    }
    const dds::DdsOptions options = dds_args.resolve();
    if (participants.chosen()) return log_tool::run_participants(options, seconds < 0 ? 4.0 : seconds, json, std::cout);
    if (topics.chosen()) return log_tool::run_topics(options, seconds < 0 ? 4.0 : seconds, json, std::cout);
    if (diagnostics.chosen()) return log_tool::run_diagnostics(options, seconds < 0 ? 3.0 : seconds, json, std::cout);
    if (hz.chosen()) return log_tool::run_hz(options, hz_topic, seconds < 0 ? 5.0 : seconds, json, std::cout, hz_robot);
    echo_request.count = static_cast<std::size_t>(count);
    echo_request.seconds = seconds < 0 ? 0.0 : seconds;
    return log_tool::run_echo(options, echo_request, std::cout);
  });
}
