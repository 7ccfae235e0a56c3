// pixyslam_launch: starts the processes of a launch file, forwards their output
// with a prefix, stops them all on Ctrl-C, after duration_s or when a process
// marked ends_run finishes, then runs the after_run commands (evaluation).
//   pixyslam_launch config/launch_sim.yaml [--run-dir DIR] [--duration S] [--input FILE]
// --input defines ${input} for the launch file (e.g. the log launch_replay.yaml plays).
// Exit code 0 only if every process ended cleanly.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "launch_plan.h"
#include "pixyslam/app/command_line.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "process_group.h"

namespace {

using namespace pixyslam;
using Clock = std::chrono::steady_clock;

std::string own_folder() {
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string() : exe.parent_path().string();
}

std::string default_run_dir() {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  return (std::filesystem::current_path() / "pixyslam_runs" / stamp).string();
}

// Forwards output until `until` or a stop; returns false if the run must end
// early (stop requested, or a process ended: `failed` tells whether badly).
bool supervise(launcher::ProcessGroup& group, Clock::time_point until, bool& failed, bool& finished) {
  while (Clock::now() < until) {
    for (std::size_t i : group.poll(std::chrono::milliseconds(100))) {
      const launcher::ExitStatus& status = group.status(i);
      std::printf("[launch] %s ended: %s\n", group.spec(i).name.c_str(), status.describe().c_str());
      if (!status.ok()) {
        failed = true;
        return false;
      }
      if (group.spec(i).ends_run) {
        finished = true;
        return false;
      }
    }
    if (app::StopSignal::requested()) return false;
  }
  return true;
}

int run(const std::string& launch_file, const app::CommandLine& args) {
  const std::string run_dir = args.get("run-dir", default_run_dir());
  std::filesystem::create_directories(run_dir);
  const std::string bin_dir = own_folder();
  std::map<std::string, std::string> variables{
      {"config_dir", std::filesystem::absolute(app::folder_of(launch_file)).string()},
      {"bin_dir", bin_dir},
      {"run_dir", std::filesystem::absolute(run_dir).string()}};
  if (args.has("input")) variables["input"] = std::filesystem::absolute(args.get("input")).string();
  launcher::LaunchPlan plan = launcher::read_launch_plan(launch_file, variables);
  plan.duration_s = args.number("duration", plan.duration_s);
  std::printf("[launch] %zu processes from %s, run folder %s%s\n", plan.processes.size(),
              launch_file.c_str(), run_dir.c_str(),
              plan.duration_s > 0 ? (", for " + std::to_string(plan.duration_s) + " s").c_str() : "");
  std::fflush(stdout);

  launcher::ProcessGroup group(bin_dir, stdout);
  bool failed = false;
  bool finished = false;
  bool running = true;
  for (const launcher::ProcessSpec& spec : plan.processes) {
    if (spec.delay_s > 0) {
      running = supervise(group, Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                    std::chrono::duration<double>(spec.delay_s)),
                          failed, finished);
      if (!running) break;
    }
    group.start(spec);
  }
  const auto started = Clock::now();
  if (running) {
    const auto until = plan.duration_s > 0
                           ? started + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(plan.duration_s))
                           : Clock::time_point::max();
    supervise(group, until, failed, finished);
  }
  std::printf("[launch] stopping after %.1f s%s\n",
              std::chrono::duration<double>(Clock::now() - started).count(),
              app::StopSignal::requested() ? " (signal)" : failed ? " (a process failed)" : "");
  std::fflush(stdout);
  group.stop_all(std::chrono::milliseconds(static_cast<long>(plan.stop_timeout_s * 1000)));

  // Evaluation and the like, one after another, unless interrupted.
  if (!app::StopSignal::requested()) {
    for (const launcher::ProcessSpec& spec : plan.after_run) {
      group.start(spec);
      while (group.running(group.size() - 1) && !app::StopSignal::requested()) {
        group.poll(std::chrono::milliseconds(100));
      }
      if (group.running(group.size() - 1)) group.stop_all(std::chrono::seconds(5));
    }
  }

  int bad = 0;
  std::printf("[launch] summary:\n");
  for (std::size_t i = 0; i < group.size(); ++i) {
    const launcher::ExitStatus& status = group.status(i);
    std::printf("[launch]   %-16s %s%s\n", group.spec(i).name.c_str(), status.describe().c_str(),
                status.ok() ? "" : "  <- FAILED");
    if (!status.ok()) ++bad;
  }
  std::printf("[launch] run folder: %s\n", run_dir.c_str());
  std::fflush(stdout);
  return bad == 0 && !failed ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  app::StopSignal::install();
  try {
    if (argc < 2 || argv[1][0] == '-') {
      std::fprintf(stderr, "usage: pixyslam_launch LAUNCH.yaml [--run-dir DIR] [--duration S] [--input FILE]\n");
      return argc < 2 ? 2 : 0;
    }
    // The launch file is positional; the rest are flags.
    std::vector<char*> flags{argv[0]};
    for (int i = 2; i < argc; ++i) flags.push_back(argv[i]);
    const app::CommandLine args(static_cast<int>(flags.size()), flags.data(), {"run-dir", "duration", "input"});
    return run(argv[1], args);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "pixyslam_launch: config error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixyslam_launch: %s\n", e.what());
    return 1;
  }
}
