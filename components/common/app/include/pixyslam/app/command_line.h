#pragma once

#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace pixyslam::app {

// A command-line mistake (unknown or repeated flag, missing value, not a
// number): run_main() exits with 2, as for a config error.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// `--key value` flags of a process. Unknown flags, a flag without its value and
// a repeated flag are errors (UsageError naming the flag); `--help` and `-h`
// set help(). Thread-compatible.
class CommandLine {
 public:
  CommandLine(int argc, char** argv, const std::set<std::string>& known_flags);

  bool has(const std::string& flag) const { return values_.count(flag) != 0; }
  // The value of a required flag (error naming it if absent).
  const std::string& get(const std::string& flag) const;
  std::string get(const std::string& flag, const std::string& fallback) const;
  double number(const std::string& flag, double fallback) const;
  bool help() const { return help_; }

 private:
  std::map<std::string, std::string> values_;
  bool help_ = false;
};

// For programs taking a subcommand or positional arguments: with no arguments
// prints `usage` to stderr and returns 2; with --help / -h first, to stdout and
// returns 0; otherwise returns nullopt (go on).
std::optional<int> usage_exit(const std::vector<std::string>& args, const char* usage);

// Throws UsageError "<file>: no such file" for the first of `files` that does
// not exist (an input named on the command line: exit 2, as any usage error).
void require_files(const std::vector<std::string>& files);

// Folder of a file path ("." for a bare file name), for resolving paths that a
// config file gives relative to itself.
std::string folder_of(const std::string& path);

}  // namespace pixyslam::app
