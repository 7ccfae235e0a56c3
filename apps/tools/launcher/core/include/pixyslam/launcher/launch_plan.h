#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace pixyslam::launcher {

// One process of a run: its argv (argv[0] is looked up in the launcher's own
// folder first, then PATH), a start delay after the previous one, and whether
// its clean exit ends the run (e.g. a simulator that drives one lap).
struct ProcessSpec {
  std::string name;
  std::vector<std::string> command;
  double delay_s = 0.0;
  bool ends_run = false;
  std::vector<std::pair<std::string, std::string>> environment;  // set in the child (deployment)
  // `role: essential` (default: the run stops when it fails) or `optional`
  // (logger, viewers, evaluators: a failure is reported and the process
  // restarted with back-off, the others go on).
  bool optional = false;
};

// A launch argument, declared in the file (`launch.arguments:`) and given on
// the command line as NAME:=VALUE, as in `ros2 launch`. Its value is the
// variable ${NAME} in commands; a process's `if_given: {NAME: [words]}` adds
// the words only when the value is not empty.
struct LaunchArgument {
  std::string name;
  std::string default_value;  // "" (the default): the process's own configuration decides
  std::string help;
};

// The longest run a launch file, duration:= or --duration may ask for.
inline constexpr double kMaxDurationS = 1e6;

// A run as a launch file describes it (config/launch_*.yaml).
struct LaunchPlan {
  std::vector<LaunchArgument> arguments;  // as declared, in file order
  double duration_s = 0.0;      // stop after this long; 0 = until Ctrl-C or ends_run (at most kMaxDurationS)
  double stop_timeout_s = 5.0;  // SIGINT, then SIGKILL after this
  std::vector<ProcessSpec> processes;
  std::vector<ProcessSpec> after_run;  // run one after another once all have stopped
};

// Reads the `launch:` mapping of a file. A process with `for_each: {NAME:
// 'A,B'}` (a comma-separated list, launch arguments substituted) stands for one
// process per value, ${NAME} set to it in its name and command (e.g. one
// estimator per robot: `for_each: {robot: '${robots}'}`). In every command word, ${name} is
// replaced by variables[name] or a launch argument's value (unknown names are
// errors); the launcher defines config_dir (the launch file's folder), bin_dir
// and run_dir. `given` are the command line's NAME:=VALUE (split_launch_arguments);
// `duration` is built in (duration_s), any other must be declared. Unknown
// keys, duplicate names, empty commands and undeclared arguments throw
// config::ConfigError naming the file and key.
LaunchPlan read_launch_plan(const std::string& path, const std::map<std::string, std::string>& variables,
                            const std::map<std::string, std::string>& given = {});

// The NAME:=VALUE words of a command line (moved out of `words`); throws
// std::invalid_argument for an empty or repeated name.
std::map<std::string, std::string> split_launch_arguments(std::vector<std::string>& words);

// The declared arguments, one per line with default and help (--show-args).
std::string arguments_text(const LaunchPlan& plan);

// Replaces every ${name}; throws std::invalid_argument naming an unknown variable.
std::string substitute(const std::string& text, const std::map<std::string, std::string>& variables);

// Splits a byte stream into lines for prefixing: feed() returns the complete
// lines (without '\n'); finish() the unterminated rest, if any. Lines longer
// than `max_line` are cut into pieces of that size.
class LineSplitter {
 public:
  explicit LineSplitter(std::size_t max_line = 4096) : max_line_(max_line) {}
  std::vector<std::string> feed(const char* data, std::size_t size);
  std::vector<std::string> finish();

 private:
  std::size_t max_line_;
  std::string pending_;
};

}  // namespace pixyslam::launcher
