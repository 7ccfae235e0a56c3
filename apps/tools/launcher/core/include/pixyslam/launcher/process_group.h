#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "pixyslam/launcher/launch_plan.h"

namespace pixyslam::launcher {

// How a child ended.
struct ExitStatus {
  bool exited = false;  // false: killed by a signal
  int code = 0;         // exit code, or the signal number
  bool stopped_by_us = false;
  double cpu_s = 0.0;             // user + system CPU time of the child (wait4)
  long max_rss_kb = 0;            // its peak resident set size
  // A clean exit, or death by the SIGINT the launcher sent.
  bool ok() const;
  std::string describe() const;
  // "CPU 12.34 s, peak RSS 45.6 MB".
  std::string resources() const;
};

// Child processes with their output (stdout and stderr) forwarded line by line
// to `out` as "[name] line". Each child runs in its own process group, with
// default signal dispositions, and gets SIGTERM if the process that started it
// dies (PR_SET_PDEATHSIG, whatever killed it). stop_all() sends SIGINT, waits
// up to a timeout, then SIGKILL; then it stops the descendants the children
// left behind (this process is their subreaper). The destructor kills and
// reaps whatever is left. Not thread-safe: one thread drives it; it reaps every
// child of the process (waitpid(-1)).
class ProcessGroup {
 public:
  ProcessGroup(std::string bin_dir, std::FILE* out);
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  // The path a command's program runs from: a path as given, else the first of
  // the launcher's folder and PATH that holds it. Throws std::runtime_error if
  // it is not there or not executable.
  std::string resolve(const std::string& program) const;
  // Starts a child and returns its index; throws std::runtime_error if the
  // program is not found. A child started again under the name of one that
  // ended (a restart) takes its index: a crash loop does not grow the group.
  std::size_t start(const ProcessSpec& spec);
  // Forwards output and reaps children for up to `timeout`; returns the indices
  // of children that ended during the call.
  std::vector<std::size_t> poll(std::chrono::milliseconds timeout);
  // Stops the running children one at a time, newest first: SIGINT, then
  // SIGKILL if one has not exited within `timeout`.
  void stop_all(std::chrono::milliseconds timeout);

  std::size_t size() const { return children_.size(); }
  bool running(std::size_t i) const;
  bool any_running() const;
  const ProcessSpec& spec(std::size_t i) const;
  const ExitStatus& status(std::size_t i) const;

 private:
  struct Child;
  void drain(Child& child, bool final);
  void reap();
  void stop_adopted(std::chrono::milliseconds timeout);

  std::string bin_dir_;
  std::FILE* out_;
  std::vector<std::unique_ptr<Child>> children_;
};

}  // namespace pixyslam::launcher
