// The launcher: launch-file parsing, line splitting, process supervision.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>
#include <utility>

#include <gtest/gtest.h>

#include "pixyslam/launcher/deployment.h"
#include "pixyslam/launcher/launch_plan.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/launcher/process_group.h"

namespace pixyslam::launcher {
namespace {

std::string write_temp(const std::string& text) {
  char path[] = "/tmp/pixyslam_launch_test_XXXXXX";
  const int fd = mkstemp(path);
  EXPECT_GE(fd, 0);
  EXPECT_EQ(write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(fd);
  return path;
}

TEST(LaunchPlan, ReadsProcessesAndSubstitutesVariables) {
  const std::string path = write_temp(
      "launch:\n  duration_s: 12\n  processes:\n"
      "    - name: a\n      command: [prog, --config, '${config_dir}/a.yaml']\n"
      "    - name: b\n      command: [other]\n      delay_s: 1.5\n      ends_run: true\n"
      "  after_run:\n    - name: eval\n      command: [eval, '${run_dir}/log']\n");
  const LaunchPlan plan = read_launch_plan(path, {{"config_dir", "/c"}, {"run_dir", "/r"}});
  std::remove(path.c_str());
  ASSERT_EQ(plan.processes.size(), 2u);
  EXPECT_DOUBLE_EQ(plan.duration_s, 12.0);
  EXPECT_EQ(plan.processes[0].command[2], "/c/a.yaml");
  EXPECT_DOUBLE_EQ(plan.processes[1].delay_s, 1.5);
  EXPECT_TRUE(plan.processes[1].ends_run);
  ASSERT_EQ(plan.after_run.size(), 1u);
  EXPECT_EQ(plan.after_run[0].command[1], "/r/log");
}

TEST(LaunchPlan, ErrorsNameFileAndKey) {
  const std::string path = write_temp(
      "launch:\n  processes:\n    - name: a\n      command: [p]\n      colour: red\n");
  try {
    read_launch_plan(path, {});
    FAIL() << "expected an error";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("launch.processes[0].colour"), std::string::npos) << what;
  }
  std::remove(path.c_str());
}

TEST(LaunchPlan, RolesAreEssentialByDefaultAndCheckedByName) {
  const std::string path = write_temp(
      "launch:\n  processes:\n    - {name: a, command: [p]}\n    - {name: b, command: [q], role: optional}\n"
      "    - {name: c, command: [r], role: essential}\n");
  const LaunchPlan plan = read_launch_plan(path, {});
  std::remove(path.c_str());
  ASSERT_EQ(plan.processes.size(), 3u);
  EXPECT_FALSE(plan.processes[0].optional);
  EXPECT_TRUE(plan.processes[1].optional);
  EXPECT_FALSE(plan.processes[2].optional);
  for (const char* bad : {"role: spare", "role: optional, ends_run: true"}) {
    const std::string file =
        write_temp(std::string("launch:\n  processes:\n    - {name: a, command: [p], ") + bad + "}\n");
    try {
      read_launch_plan(file, {});
      ADD_FAILURE() << "expected an error for " << bad;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("launch.processes[0].role"), std::string::npos) << e.what();
    }
    std::remove(file.c_str());
  }
}

TEST(LaunchPlan, UnknownVariableAndDuplicateNameAreErrors) {
  const std::string unknown = write_temp("launch:\n  processes:\n    - name: a\n      command: ['${nope}']\n");
  EXPECT_THROW(read_launch_plan(unknown, {}), config::ConfigError);
  std::remove(unknown.c_str());
  const std::string twice = write_temp(
      "launch:\n  processes:\n    - {name: a, command: [p]}\n    - {name: a, command: [q]}\n");
  EXPECT_THROW(read_launch_plan(twice, {}), config::ConfigError);
  std::remove(twice.c_str());
}

// Launch arguments: NAME:=VALUE as in `ros2 launch`, declared in the file.
TEST(LaunchPlan, LaunchArgumentsSubstituteAndAddWordsOnlyWhenGiven) {
  const std::string path = write_temp(
      "launch:\n  arguments:\n    particles: {help: particle count}\n"
      "    rate: {default: '10', help: publish rate}\n  processes:\n"
      "    - name: slam\n      command: [slam, --rate, '${rate}']\n"
      "      if_given: {particles: [--set, 'filter.particles=${particles}']}\n");
  const LaunchPlan defaults = read_launch_plan(path, {});
  EXPECT_EQ(defaults.processes[0].command, (std::vector<std::string>{"slam", "--rate", "10"}));
  ASSERT_EQ(defaults.arguments.size(), 2u);
  EXPECT_NE(arguments_text(defaults).find("particles  particle count"), std::string::npos) << arguments_text(defaults);

  std::vector<std::string> words{"particles:=300", "--run-dir", "d", "rate:=5", "duration:=30"};
  const auto given = split_launch_arguments(words);
  EXPECT_EQ(words, (std::vector<std::string>{"--run-dir", "d"}));
  const LaunchPlan plan = read_launch_plan(path, {}, given);
  EXPECT_EQ(plan.processes[0].command,
            (std::vector<std::string>{"slam", "--rate", "5", "--set", "filter.particles=300"}));
  EXPECT_DOUBLE_EQ(plan.duration_s, 30.0);

  // An undeclared name lists the declared ones; a bad duration and a repeated name are refused.
  try {
    read_launch_plan(path, {}, {{"particle", "3"}});
    ADD_FAILURE() << "expected an error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("particles, rate"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_launch_plan(path, {}, {{"duration", "soon"}}), config::ConfigError);
  std::vector<std::string> twice{"a:=1", "a:=2"};
  EXPECT_THROW(split_launch_arguments(twice), std::invalid_argument);
  std::remove(path.c_str());
  const std::string clash = write_temp("launch:\n  arguments:\n    run_dir: {help: x}\n  processes:\n"
                                       "    - {name: a, command: [p]}\n");
  EXPECT_THROW(read_launch_plan(clash, {{"run_dir", "/r"}}), config::ConfigError);
  std::remove(clash.c_str());
}

// One block for N robots: for_each expands it, ${robot} in name and command.
TEST(LaunchPlan, ForEachMakesOneProcessPerValue) {
  const std::string path = write_temp(
      "launch:\n  arguments:\n    robots: {default: '1,3', help: robots}\n    seed: {help: seed}\n"
      "  processes:\n    - name: estimator_${robot}\n      for_each: {robot: '${robots}'}\n"
      "      command: [slam_estimator, --set, 'dds.robot_id=robot${robot}', --out-dir, '${run_dir}/robot${robot}']\n"
      "      if_given: {seed: [--seed, '${seed}${robot}']}\n    - {name: logger, command: [logger]}\n");
  const LaunchPlan plan = read_launch_plan(path, {{"run_dir", "/r"}}, {{"seed", "7"}});
  ASSERT_EQ(plan.processes.size(), 3u);
  EXPECT_EQ(plan.processes[0].name, "estimator_1");
  EXPECT_EQ(plan.processes[1].command,
            (std::vector<std::string>{"slam_estimator", "--set", "dds.robot_id=robot3", "--out-dir", "/r/robot3",
                                      "--seed", "73"}));
  EXPECT_EQ(plan.processes[2].name, "logger");
  const LaunchPlan five = read_launch_plan(path, {{"run_dir", "/r"}}, {{"robots", "1,2,3,4,5"}});
  EXPECT_EQ(five.processes.size(), 6u);
  EXPECT_THROW(read_launch_plan(path, {{"run_dir", "/r"}}, {{"robots", ""}}), config::ConfigError);  // no robot
  std::remove(path.c_str());
  // The name must tell the copies apart.
  const std::string same = write_temp(
      "launch:\n  processes:\n    - {name: e, for_each: {robot: '1,2'}, command: [p, '${robot}']}\n");
  EXPECT_THROW(read_launch_plan(same, {}), config::ConfigError);
  std::remove(same.c_str());
}

TEST(LineSplitter, SplitsAtNewlinesAcrossChunksAndCutsLongLines) {
  LineSplitter splitter(8);
  auto lines = splitter.feed("ab\ncd", 5);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "ab");
  lines = splitter.feed("e\n0123456789", 12);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "cde");
  EXPECT_EQ(lines[1], "01234567");
  lines = splitter.finish();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "89");
}

std::string read_all(std::FILE* f) {
  std::rewind(f);
  std::string out;
  char buffer[256];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), f)) > 0) out.append(buffer, n);
  return out;
}

TEST(ProcessGroup, ForwardsOutputWithPrefixAndReportsExitCodes) {
  std::FILE* out = std::tmpfile();
  {
    ProcessGroup group("", out);
    group.start({"ok", {"/bin/sh", "-c", "echo hello; echo world >&2"}, 0.0, false, {}});
    group.start({"bad", {"/bin/sh", "-c", "exit 3"}, 0.0, false, {}});
    // A child that burns about 0.2 s of CPU: its own time is counted (wait4), not the launcher's.
    group.start({"busy", {"/bin/sh", "-c", "i=0; while [ $i -lt 20000 ]; do i=$((i+1)); done"}, 0.0, false, {}});
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (group.any_running() && std::chrono::steady_clock::now() < end) {
      group.poll(std::chrono::milliseconds(50));
    }
    ASSERT_FALSE(group.any_running());
    EXPECT_TRUE(group.status(0).ok());
    EXPECT_FALSE(group.status(1).ok());
    EXPECT_EQ(group.status(1).code, 3);
    EXPECT_GT(group.status(2).cpu_s, group.status(1).cpu_s);
    EXPECT_GT(group.status(0).max_rss_kb, 0);
    EXPECT_NE(group.status(2).resources().find("CPU "), std::string::npos);
  }
  const std::string text = read_all(out);
  std::fclose(out);
  EXPECT_NE(text.find("[ok] hello\n"), std::string::npos) << text;
  EXPECT_NE(text.find("[ok] world\n"), std::string::npos) << text;
}

// An optional process in a crash loop is restarted every 30 s for days: each
// restart takes the place of its ended run, so the group does not grow.
TEST(ProcessGroup, ARestartTakesThePlaceOfTheEndedRun) {
  std::FILE* out = std::tmpfile();
  {
    ProcessGroup group("", out);
    EXPECT_EQ(group.start({"steady", {"/bin/sh", "-c", "sleep 5"}, 0.0, false, {}}), 0u);
    for (int run = 1; run <= 3; ++run) {
      const std::size_t i = group.start({"crashing", {"/bin/sh", "-c", "exit " + std::to_string(run)}, 0.0, false, {}});
      EXPECT_EQ(i, 1u) << run;
      const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (group.running(i) && std::chrono::steady_clock::now() < end) group.poll(std::chrono::milliseconds(20));
      // The output pipe closes with the process; one more poll reads its end.
      group.poll(std::chrono::milliseconds(20));
      ASSERT_FALSE(group.running(i));
      EXPECT_EQ(group.status(i).code, run);
    }
    EXPECT_EQ(group.size(), 2u);
    EXPECT_TRUE(group.running(0));
    group.stop_all(std::chrono::seconds(5));
  }
  std::fclose(out);
}

TEST(ProcessGroup, StopAllInterruptsAndEscalatesToKill) {
  std::FILE* out = std::tmpfile();
  ProcessGroup group("", out);
  group.start({"sleeper", {"/bin/sleep", "30"}, 0.0, false, {}});
  // Ignores SIGINT: must be killed after the timeout.
  group.start({"stubborn", {"/bin/sh", "-c", "trap '' INT; sleep 30"}, 0.0, false, {}});
  group.poll(std::chrono::milliseconds(200));
  const auto begin = std::chrono::steady_clock::now();
  group.stop_all(std::chrono::milliseconds(500));
  EXPECT_LT(std::chrono::steady_clock::now() - begin, std::chrono::seconds(5));
  EXPECT_FALSE(group.any_running());
  EXPECT_TRUE(group.status(0).ok());    // SIGINT from us
  EXPECT_FALSE(group.status(1).ok());   // needed SIGKILL
  std::fclose(out);
}

TEST(ProcessGroup, MissingProgramIsNamed) {
  ProcessGroup group("/nonexistent", stdout);
  try {
    group.start({"x", {"no_such_program_pixyslam"}, 0.0, false, {}});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_program_pixyslam"), std::string::npos);
  }
}

// Deployments: which host runs what, with which DDS settings.
LaunchPlan three_process_plan() {
  LaunchPlan plan;
  plan.processes = {{"sim", {"robot_sim"}, 0.0, true, {}},
                    {"estimator", {"slam_estimator"}, 0.0, false, {}},
                    {"logger", {"logger"}, 0.0, false, {}}};
  plan.after_run = {{"check", {"pixyslam_log", "check"}, 0.0, false, {}}};
  return plan;
}

std::string env_of(const ProcessSpec& p, const std::string& name) {
  for (const auto& [n, v] : p.environment) {
    if (n == name) return v;
  }
  return "<unset>";
}

TEST(Deployment, EachHostGetsItsProcessesAndDdsSettings) {
  const std::string path = write_temp(
      "deployment:\n  profile: discovery_client\n  domain_id: 5\n"
      "  discovery_server: {host: server, port: 11900, id: 3}\n"
      "  hosts:\n"
      "    robot: {address: 10.0.0.1, processes: [sim]}\n"
      "    laptop: {address: 10.0.0.2, processes: [estimator, logger, check]}\n"
      "    server: {address: 10.0.0.3, processes: []}\n");
  const Deployment d = read_deployment(path);
  std::remove(path.c_str());
  const LaunchPlan robot = plan_for_host(three_process_plan(), d, "robot");
  ASSERT_EQ(robot.processes.size(), 1u);
  EXPECT_EQ(robot.processes[0].name, "sim");
  EXPECT_TRUE(robot.after_run.empty());
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_INTERFACES"), "10.0.0.1");
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_PEERS"), "10.0.0.1,10.0.0.2,10.0.0.3");
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_SERVER"), "10.0.0.3:11900");
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_SERVER_ID"), "3");
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_DOMAIN"), "5");
  EXPECT_EQ(env_of(robot.processes[0], "PIXYSLAM_DDS_PROFILE"), "discovery_client");
  const LaunchPlan laptop = plan_for_host(three_process_plan(), d, "laptop");
  ASSERT_EQ(laptop.processes.size(), 2u);
  EXPECT_EQ(laptop.processes[1].name, "logger");
  ASSERT_EQ(laptop.after_run.size(), 1u);
  EXPECT_EQ(env_of(laptop.after_run[0], "PIXYSLAM_DDS_INTERFACES"), "10.0.0.2");
  // The server host runs only the discovery server, on its own address.
  const LaunchPlan server = plan_for_host(three_process_plan(), d, "server");
  ASSERT_EQ(server.processes.size(), 1u);
  EXPECT_EQ(server.processes[0].command,
            (std::vector<std::string>{"fastdds", "discovery", "-i", "3", "-l", "10.0.0.3", "-p", "11900"}));
  EXPECT_THROW(plan_for_host(three_process_plan(), d, "nas"), std::invalid_argument);
}

TEST(Deployment, UnassignedOrUnknownProcessesAreErrors) {
  const std::string path = write_temp(
      "deployment:\n  hosts:\n    robot: {address: 10.0.0.1, processes: [sim, ghost]}\n"
      "    laptop: {address: 10.0.0.2, processes: [estimator]}\n");
  const Deployment d = read_deployment(path);
  std::remove(path.c_str());
  try {
    plan_for_host(three_process_plan(), d, "robot");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    // logger and check are on no host.
    EXPECT_NE(std::string(e.what()).find("on no host"), std::string::npos) << e.what();
  }
  LaunchPlan two = three_process_plan();
  two.processes.pop_back();
  two.after_run.clear();
  try {
    plan_for_host(two, d, "robot");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'ghost'"), std::string::npos) << e.what();
  }
}

TEST(Deployment, BadFilesNameTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"deployment:\n  hosts:\n    robot: {address: 10.0.0, processes: []}\n", "address"},
      {"deployment:\n  hosts:\n    a: {address: 10.0.0.1, processes: [x]}\n    b: {address: 10.0.0.2, processes: [x]}\n",
       "two hosts"},
      {"deployment:\n  hosts:\n    a: {address: 10.0.0.1, processes: []}\n    b: {address: 10.0.0.1, processes: []}\n",
       "used by two hosts"},
      {"deployment:\n  profile: discovery_client\n  hosts:\n    a: {address: 10.0.0.1, processes: []}\n",
       "discovery_server"},
      {"deployment:\n  profile: secure\n  hosts:\n    a: {address: 10.0.0.1, processes: []}\n", "security_dir"},
      {"deployment:\n  profile: wifi\n  hosts:\n    a: {address: 10.0.0.1, processes: []}\n", "profile"},
      {"deployment:\n  discovery_server: {host: nas}\n  hosts:\n    a: {address: 10.0.0.1, processes: []}\n",
       "nas"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string path = write_temp(text);
    try {
      read_deployment(path);
      ADD_FAILURE() << "expected an error for:\n" << text;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace pixyslam::launcher
