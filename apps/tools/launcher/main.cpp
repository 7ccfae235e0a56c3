// pixyslam_launch: starts the processes of a launch file, forwards their output
// with a prefix, stops them all on Ctrl-C, after duration_s or when the
// processes marked ends_run have finished, then runs the after_run commands
// (evaluation).
//   pixyslam_launch config/launch_sim.yaml [NAME:=VALUE ...] [--run-dir DIR] [--duration S] [--input FILE]
//                   [--deployment DEPLOY.yaml --host NAME] [--show-args]
// NAME:=VALUE: launch arguments (duration, and those the file declares).
// --input defines ${input} for the launch file (e.g. the log launch_replay.yaml plays).
// With a deployment, only the host's share of the processes runs, with the
// deployment's DDS settings, and DDS liveliness of every process on the
// domain is reported ([health] lines; docs/deployment.md).
// SIGINT, SIGTERM and SIGHUP stop the run in order; the children get SIGTERM
// from the kernel if the launcher dies any other way (SIGKILL).
// A process with `role: optional` that fails is restarted with back-off (1, 2,
// 4, ... 30 s) while the run goes on; an essential one stops the run.
// Exit code 0 only if every process ended cleanly (optional ones included).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/launcher/deployment.h"
#include "pixyslam/launcher/health_monitor.h"
#include "pixyslam/launcher/launch_plan.h"
#include "pixyslam/app/cli.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/launcher/process_group.h"

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

// Back-off before restart n (1, 2, ...): 1, 2, 4, ... 30 s.
double restart_delay_s(int n) { return std::min(30.0, static_cast<double>(1 << std::min(n - 1, 5))); }

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

// One run of a launch plan: starts its processes (each after its delay),
// supervises them (an optional one that fails is restarted with back-off, an
// essential one's failure stops the run, as does the exit of the last process
// marked ends_run (with for_each, every robot's),
// the duration or a signal), stops them all, runs the after-run steps and
// prints the summary. Single-threaded; run() once.
class LaunchSession {
 public:
  LaunchSession(launcher::LaunchPlan plan, const std::string& bin_dir,
                std::unique_ptr<launcher::HealthMonitor> health)
      : plan_(std::move(plan)), group_(bin_dir, stdout), health_(std::move(health)) {
    ends_run_left_ = std::count_if(plan_.processes.begin(), plan_.processes.end(),
                                   [](const launcher::ProcessSpec& p) { return p.ends_run; });
  }

  // The exit status: 0 only if every process ended cleanly.
  int run(const std::string& run_dir) {
    bool running = true;
    for (const launcher::ProcessSpec& spec : plan_.processes) {
      if (spec.delay_s > 0) {
        running = supervise(Clock::now() + seconds(spec.delay_s));
        if (!running) break;
      }
      group_.start(spec);
    }
    const auto started = Clock::now();
    if (running) supervise(plan_.duration_s > 0 ? started + seconds(plan_.duration_s) : Clock::time_point::max());
    std::printf("[launch] stopping after %.1f s%s\n", std::chrono::duration<double>(Clock::now() - started).count(),
                app::StopSignal::requested() ? " (signal)" : failed_ ? " (a process failed)" : "");
    std::fflush(stdout);
    group_.stop_all(std::chrono::milliseconds(static_cast<long>(plan_.stop_timeout_s * 1000)));
    run_after_steps();
    return summary(run_dir);
  }

 private:
  // Forwards output until `until` or a stop; returns false if the run must end
  // early (stop requested, or a process ended: failed_ tells whether badly).
  bool supervise(Clock::time_point until) {
    while (Clock::now() < until) {
      print_health();
      for (std::size_t i : group_.poll(std::chrono::milliseconds(100))) {
        if (!on_exit(group_.status(i), group_.spec(i))) return false;
      }
      if (app::StopSignal::requested()) return false;
      start_due_restarts();
    }
    return true;
  }

  // A process ended; false if the run ends with it.
  bool on_exit(const launcher::ExitStatus& status, const launcher::ProcessSpec& spec) {
    std::printf("[launch] %s ended: %s\n", spec.name.c_str(), status.describe().c_str());
    if (!status.ok() && spec.optional && status.exited && status.code == 2) {
      std::printf("[launch] %s is optional: the run goes on; not restarted (exit code 2: a usage or "
                  "configuration error)\n", spec.name.c_str());
      return true;
    }
    if (!status.ok() && spec.optional && !app::StopSignal::requested()) {
      const double delay = restart_delay_s(++failures_[spec.name]);
      std::printf("[launch] %s is optional: the run goes on; restart in %.0f s\n", spec.name.c_str(), delay);
      restarts_.push_back({spec, Clock::now() + seconds(delay)});
      return true;
    }
    if (!status.ok()) {
      failed_ = true;
      return false;
    }
    if (!spec.ends_run) return true;
    if (--ends_run_left_ > 0) {
      std::printf("[launch] %s finished; the run goes on until %ld more process(es) marked ends_run finish\n",
                  spec.name.c_str(), ends_run_left_);
      return true;
    }
    return false;
  }

  void start_due_restarts() {
    for (auto it = restarts_.begin(); it != restarts_.end();) {
      if (Clock::now() < it->at) {
        ++it;
        continue;
      }
      std::printf("[launch] restarting %s (restart %d)\n", it->spec.name.c_str(), failures_[it->spec.name]);
      try {
        group_.start(it->spec);
      } catch (const std::exception& e) {
        std::printf("[launch] %s: %s\n", it->spec.name.c_str(), e.what());
      }
      it = restarts_.erase(it);
    }
  }

  // Evaluation and the like, one after another, also after a Ctrl-C (a run on
  // a host without an ends_run process ends that way); a second one skips them.
  void run_after_steps() {
    const int signals_before = app::StopSignal::signal_count();
    auto skipped = [&] { return signals_before > 1 || app::StopSignal::signal_count() > signals_before; };
    if (signals_before == 1 && !plan_.after_run.empty()) {
      std::printf("[launch] after-run steps (Ctrl-C again to skip them)\n");
      std::fflush(stdout);
    }
    for (const launcher::ProcessSpec& spec : plan_.after_run) {
      if (skipped()) break;
      const std::size_t step = group_.start(spec);
      while (group_.running(step) && !skipped()) group_.poll(std::chrono::milliseconds(100));
      if (group_.running(step)) group_.stop_all(std::chrono::seconds(5));
    }
  }

  int summary(const std::string& run_dir) {
    int bad = 0;
    std::printf("[launch] summary:\n");
    for (std::size_t i = 0; i < group_.size(); ++i) {
      const launcher::ExitStatus& status = group_.status(i);
      const launcher::ProcessSpec& spec = group_.spec(i);
      // A restarted process shows its last run; every failure still counts.
      const auto failures = failures_.find(spec.name);
      const int failed_before = failures == failures_.end() ? 0 : failures->second;
      const std::string restarts =
          failed_before > 0 ? ", " + std::to_string(failed_before) + " failure(s) in all, restarted after each" : "";
      std::printf("[launch]   %-16s %s%s%s  (%s%s)\n", spec.name.c_str(), status.describe().c_str(),
                  status.ok() ? "" : "  <- FAILED", spec.optional && !status.ok() ? " (optional)" : "",
                  status.resources().c_str(), restarts.c_str());
      if (!status.ok() || failed_before > 0) ++bad;
    }
    print_health();
    if (health_) std::printf("[launch] health: %d process(es) lost on the domain during the run\n", health_->lost());
    health_.reset();
    std::printf("[launch] run folder: %s\n", run_dir.c_str());
    std::fflush(stdout);
    return bad == 0 && !failed_ ? 0 : 1;
  }

  void print_health() {
    if (!health_) return;
    for (const std::string& event : health_->take_events()) std::printf("[health] %s\n", event.c_str());
    std::fflush(stdout);
  }

  // An optional process that failed, waiting for its restart.
  struct Restart {
    launcher::ProcessSpec spec;
    Clock::time_point at;
  };

  launcher::LaunchPlan plan_;
  launcher::ProcessGroup group_;
  std::unique_ptr<launcher::HealthMonitor> health_;
  std::vector<Restart> restarts_;
  std::map<std::string, int> failures_;  // per optional process name
  bool failed_ = false;
  long ends_run_left_ = 0;  // processes marked ends_run that have not finished yet
};

struct LaunchCommandLine {
  std::string launch_file;
  std::vector<std::string> arguments;  // NAME:=VALUE
  std::string run_dir, input, deployment, host;
  double duration_s = -1.0;  // -1: the file's
  bool show_args = false;
};

// Whether a command or environment value of the plan contains `text`.
bool uses_word(const launcher::LaunchPlan& plan, const std::string& text) {
  for (const auto* specs : {&plan.processes, &plan.after_run}) {
    for (const launcher::ProcessSpec& spec : *specs) {
      for (const std::string& word : spec.command) {
        if (word.find(text) != std::string::npos) return true;
      }
      for (const auto& variable : spec.environment) {
        if (variable.second.find(text) != std::string::npos) return true;
      }
    }
  }
  return false;
}

int run(const LaunchCommandLine& args, const std::map<std::string, std::string>& given) {
  const std::string& launch_file = args.launch_file;
  const bool show_args = args.show_args;
  const std::string run_dir = args.run_dir.empty() ? default_run_dir() : args.run_dir;
  const std::string bin_dir = own_folder();
  std::map<std::string, std::string> variables{
      {"config_dir", std::filesystem::absolute(config::folder_of(launch_file)).string()},
      {"bin_dir", bin_dir},
      {"run_dir", std::filesystem::absolute(run_dir).string()}};
  // Without --input, ${input} is this placeholder: --show-args needs no file, a run does.
  const std::string no_input = "<--input FILE>";
  variables["input"] = args.input.empty() ? no_input : std::filesystem::absolute(args.input).string();
  launcher::LaunchPlan plan = launcher::read_launch_plan(launch_file, variables, given);
  std::unique_ptr<launcher::HealthMonitor> health;
  if (show_args) {
    std::fputs(launcher::arguments_text(plan).c_str(), stdout);
    return 0;
  }
  if (args.input.empty() && uses_word(plan, no_input)) {
    throw std::invalid_argument("this launch file needs --input FILE (" + launch_file + " uses ${input})");
  }
  if (!args.deployment.empty()) {
    const launcher::Deployment deployment = launcher::read_deployment(args.deployment);
    plan = launcher::plan_for_host(plan, deployment, args.host);
    // The launcher's own DDS participant (the health monitor) joins like its
    // processes: this process's environment, then the host's deployment settings.
    dds::DdsOptions options;
    const std::string profiles = variables["config_dir"] + "/dds/profiles.xml";
    options.profiles_file = std::filesystem::exists(profiles) ? profiles : dds::default_profiles_file();
    dds::resolve_settings(options);
    const auto host_env = launcher::host_environment(deployment, args.host);
    dds::apply_environment(options, [&](const char* name) -> const char* {
      for (const auto& [variable, value] : host_env) {
        if (variable == name) return value.c_str();
      }
      return nullptr;
    });
    try {
      health = std::make_unique<launcher::HealthMonitor>(options);
    } catch (const std::exception& e) {
      std::printf("[launch] warning: no health monitor: %s\n", e.what());
    }
    std::printf("[launch] host '%s' of %s: %zu processes, %zu after the run\n", args.host.c_str(),
                args.deployment.c_str(), plan.processes.size(), plan.after_run.size());
  }
  if (args.duration_s >= 0.0) plan.duration_s = args.duration_s;
  // Every program is found before anything starts: a misspelt one must not stop
  // a run half-way, its log unclosed.
  const launcher::ProcessGroup finder(bin_dir, stdout);
  auto check_programs = [&](const std::vector<launcher::ProcessSpec>& specs, const char* list) {
    for (const launcher::ProcessSpec& spec : specs) {
      try {
        finder.resolve(spec.command.front());
      } catch (const std::runtime_error& e) {
        throw std::invalid_argument(launch_file + ": launch." + list + " '" + spec.name + "': " + e.what());
      }
    }
  };
  check_programs(plan.processes, "processes");
  check_programs(plan.after_run, "after_run");
  std::filesystem::create_directories(run_dir);  // only once the files and arguments are good
  char duration[48] = "";
  if (plan.duration_s > 0) std::snprintf(duration, sizeof(duration), ", for %.1f s", plan.duration_s);
  std::printf("[launch] %zu processes from %s, run folder %s%s\n", plan.processes.size(), launch_file.c_str(),
              run_dir.c_str(), duration);
  std::fflush(stdout);

  return LaunchSession(std::move(plan), bin_dir, std::move(health)).run(run_dir);
}

}  // namespace

int main(int argc, char** argv) {
  app::StopSignal::install();
  // Output to a closed terminal or SSH pipe must not kill the launcher before
  // it has stopped its children (they get the default back).
  signal(SIGPIPE, SIG_IGN);
  LaunchCommandLine args;
  app::Cli cli{"pixyslam_launch", "Starts the processes of a launch file, forwards their output with a prefix, stops them all on "
               "Ctrl-C, after the duration or when the processes marked ends_run have finished, then runs the after_run "
               "steps. Exit code 0 only if every process ended cleanly."};
  cli.option("launch_file", args.launch_file, "e.g. config/launch_sim.yaml").required().existing_file()
      .type("LAUNCH.yaml");
  cli.option("arguments", args.arguments, "launch arguments, e.g. particles:=300 duration:=30 (--show-args)")
      .type("NAME:=VALUE");
  cli.option("--run-dir", args.run_dir, "the run's folder (${run_dir}; default ./pixyslam_runs/<time>)")
      .type("DIR");
  cli.option("--duration", args.duration_s, "the same as duration:=S").type("S").range(0.0, launcher::kMaxDurationS);
  cli.option("--input", args.input, "defines ${input} (e.g. the log launch_replay.yaml plays)").type("FILE");
  app::Cli::Option& deployment = cli.option("--deployment", args.deployment,
                                    "a deployment file: run one host's share with its DDS settings "
                                    "(docs/deployment.md)")
                         .type("DEPLOY.yaml")
                         .existing_file();
  app::Cli::Option& host = cli.option("--host", args.host, "the host of the deployment this is").type("NAME");
  deployment.needs(host);
  host.needs(deployment);
  cli.flag("--show-args", args.show_args, "the file's launch arguments, their defaults and help; starts nothing");
  if (const auto done = cli.parse(argc, argv)) return *done;
  try {
    for (const std::string& word : args.arguments) {
      if (word.find(":=") == std::string::npos) {
        throw std::invalid_argument("'" + word + "' is not a launch argument NAME:=VALUE (see --help)");
      }
    }
    std::vector<std::string> words = args.arguments;
    const std::map<std::string, std::string> given = launcher::split_launch_arguments(words);
    if (args.duration_s >= 0.0 && given.count("duration") != 0) {
      throw std::invalid_argument("--duration and duration:= given both");
    }
    return run(args, given);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "pixyslam_launch: config error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "pixyslam_launch: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixyslam_launch: %s\n", e.what());
    return 1;
  }
}
