#include "pixyslam/launcher/process_group.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace pixyslam::launcher {

bool ExitStatus::ok() const { return exited ? code == 0 : stopped_by_us && code == SIGINT; }

std::string ExitStatus::describe() const {
  if (exited) return "exit code " + std::to_string(code);
  return std::string("signal ") + std::to_string(code) + " (" + strsignal(code) + ")" +
         (stopped_by_us ? ", stopped by the launcher" : "");
}

std::string ExitStatus::resources() const {
  char text[80];
  std::snprintf(text, sizeof(text), "CPU %.2f s, peak RSS %.1f MB", cpu_s, static_cast<double>(max_rss_kb) / 1024.0);
  return text;
}

struct ProcessGroup::Child {
  ProcessSpec spec;
  pid_t pid = -1;
  int output_fd = -1;  // read end of the child's stdout+stderr pipe
  LineSplitter splitter;
  bool running = false;
  ExitStatus status;
};

ProcessGroup::ProcessGroup(std::string bin_dir, std::FILE* out)
    : bin_dir_(std::move(bin_dir)), out_(out) {
  // Descendants orphaned while the group runs (a child's child that left its
  // session with setsid) are re-parented here instead of to init: stop_all()
  // finds and stops them.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
}

namespace {

// A signal to a child's process group, and to the child itself if it left the
// group (setsid): each process gets it once.
void signal_child(pid_t pid, int signal_number) {
  if (getpgid(pid) != pid) kill(pid, signal_number);
  kill(-pid, signal_number);
}

// Processes whose parent is this one: our children and adopted orphans.
std::vector<pid_t> own_children() {
  std::vector<pid_t> out;
  std::error_code error;
  const pid_t self = getpid();
  for (const auto& entry : std::filesystem::directory_iterator("/proc", error)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // pid (comm) state ppid ...: comm may hold spaces and parentheses.
    const std::size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    long ppid = 0;
    if (std::sscanf(line.c_str() + close + 1, " %c %ld", &state, &ppid) == 2 && ppid == self && state != 'Z') {
      out.push_back(static_cast<pid_t>(std::stol(name)));
    }
  }
  return out;
}

}  // namespace

ProcessGroup::~ProcessGroup() {
  for (auto& child : children_) {
    if (child->running) signal_child(child->pid, SIGKILL);
  }
  for (auto& child : children_) {
    if (child->running) waitpid(child->pid, nullptr, 0);
    if (child->output_fd >= 0) close(child->output_fd);
  }
}

std::string ProcessGroup::resolve(const std::string& program) const {
  auto executable = [](const std::string& path) { return access(path.c_str(), X_OK) == 0; };
  if (program.find('/') != std::string::npos) {
    if (executable(program)) return program;
    throw std::runtime_error("program '" + program + "' not found or not executable");
  }
  if (!bin_dir_.empty() && executable(bin_dir_ + "/" + program)) return bin_dir_ + "/" + program;
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = dirs.substr(start, end - start);
    if (!dir.empty() && executable(dir + "/" + program)) return dir + "/" + program;
    start = end + 1;
  }
  throw std::runtime_error("program '" + program + "' not found in " + bin_dir_ + " or PATH");
}

std::size_t ProcessGroup::start(const ProcessSpec& spec) {
  auto child = std::make_unique<Child>();
  child->spec = spec;
  const std::string program = resolve(spec.command.front());
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::vector<char*> argv;
  for (const std::string& word : spec.command) argv.push_back(const_cast<char*>(word.c_str()));
  argv.push_back(nullptr);

  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    // Child: own process group (a terminal's Ctrl-C reaches only the launcher,
    // which stops the children in order), output into the pipe, signals
    // unblocked and at their defaults (a launcher started with & from a script
    // ignores SIGINT, and exec would pass that on), and SIGTERM when the
    // launcher dies, whatever kills it (kept across setsid and exec).
    setpgid(0, 0);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    for (int number = 1; number < NSIG; ++number) {
      if (number != SIGKILL && number != SIGSTOP) signal(number, SIG_DFL);
    }
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);  // the launcher died before prctl
    for (const auto& [name, value] : spec.environment) setenv(name.c_str(), value.c_str(), 1);
    execv(program.c_str(), argv.data());
    std::fprintf(stderr, "cannot execute %s: %s\n", program.c_str(), std::strerror(errno));
    _exit(127);
  }
  setpgid(pid, pid);  // also here: no race with a stop right after fork
  close(fds[1]);
  fcntl(fds[0], F_SETFL, O_NONBLOCK);
  child->pid = pid;
  child->output_fd = fds[0];
  child->running = true;
  std::fprintf(out_, "[launch] started %s (pid %d): %s\n", spec.name.c_str(), pid, program.c_str());
  std::fflush(out_);
  for (std::size_t i = 0; i < children_.size(); ++i) {
    Child& ended = *children_[i];
    if (!ended.running && ended.output_fd < 0 && ended.spec.name == spec.name) {
      children_[i] = std::move(child);
      return i;
    }
  }
  children_.push_back(std::move(child));
  return children_.size() - 1;
}

void ProcessGroup::drain(Child& child, bool final) {
  if (child.output_fd < 0) return;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(child.output_fd, buffer, sizeof(buffer));
    if (n > 0) {
      for (const std::string& line : child.splitter.feed(buffer, static_cast<std::size_t>(n))) {
        std::fprintf(out_, "[%s] %s\n", child.spec.name.c_str(), line.c_str());
      }
      continue;
    }
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR) || final) {
      if (n == 0 || final) {
        for (const std::string& line : child.splitter.finish()) {
          std::fprintf(out_, "[%s] %s\n", child.spec.name.c_str(), line.c_str());
        }
      }
      if (n == 0) {
        close(child.output_fd);
        child.output_fd = -1;
      }
    }
    break;
  }
  std::fflush(out_);
}

void ProcessGroup::reap() {
  // Any child: ours, or an orphan adopted as subreaper (its status is not ours).
  for (;;) {
    int status = 0;
    struct rusage usage {};
    const pid_t r = wait4(-1, &status, WNOHANG, &usage);
    if (r <= 0) break;
    for (auto& child : children_) {
      if (!child->running || child->pid != r) continue;
      child->running = false;
      child->status.exited = WIFEXITED(status);
      child->status.code = WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status);
      child->status.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                            static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
      child->status.max_rss_kb = usage.ru_maxrss;
      drain(*child, true);
    }
  }
}

std::vector<std::size_t> ProcessGroup::poll(std::chrono::milliseconds timeout) {
  std::vector<bool> was_running;
  for (const auto& child : children_) was_running.push_back(child->running);
  std::vector<pollfd> fds;
  for (const auto& child : children_) {
    if (child->output_fd >= 0) fds.push_back({child->output_fd, POLLIN, 0});
  }
  if (fds.empty()) {
    std::this_thread::sleep_for(timeout);
  } else {
    ::poll(fds.data(), fds.size(), static_cast<int>(timeout.count()));
  }
  for (auto& child : children_) drain(*child, false);
  reap();
  std::vector<std::size_t> ended;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    if (was_running[i] && !children_[i]->running) ended.push_back(i);
  }
  return ended;
}

void ProcessGroup::stop_all(std::chrono::milliseconds timeout) {
  // Newest first, one at a time: sources stop before the estimator, which
  // publishes its last states before the logger (started first) stops.
  for (auto it = children_.rbegin(); it != children_.rend(); ++it) {
    Child& child = **it;
    if (!child.running) continue;
    child.status.stopped_by_us = true;
    signal_child(child.pid, SIGINT);
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (child.running && std::chrono::steady_clock::now() < end) poll(std::chrono::milliseconds(20));
    if (child.running) {
      std::fprintf(out_, "[launch] %s did not stop within %.1f s: SIGKILL\n", child.spec.name.c_str(),
                   static_cast<double>(timeout.count()) / 1000.0);
      signal_child(child.pid, SIGKILL);
      while (child.running) poll(std::chrono::milliseconds(20));
    }
  }
  stop_adopted(timeout);
}

void ProcessGroup::stop_adopted(std::chrono::milliseconds timeout) {
  std::vector<pid_t> left;
  for (pid_t pid : own_children()) {
    bool ours = false;
    for (const auto& child : children_) ours = ours || (child->running && child->pid == pid);
    if (!ours) left.push_back(pid);
  }
  if (left.empty()) return;
  std::fprintf(out_, "[launch] stopping %zu process(es) left behind by the children\n", left.size());
  std::fflush(out_);
  for (pid_t pid : left) kill(pid, SIGTERM);
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    reap();
    bool alive = false;
    for (pid_t pid : left) alive = alive || kill(pid, 0) == 0;
    if (!alive) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (pid_t pid : left) kill(pid, SIGKILL);
  for (pid_t pid : left) waitpid(pid, nullptr, 0);
}

bool ProcessGroup::running(std::size_t i) const { return children_.at(i)->running; }

bool ProcessGroup::any_running() const {
  for (const auto& child : children_) {
    if (child->running) return true;
  }
  return false;
}

const ProcessSpec& ProcessGroup::spec(std::size_t i) const { return children_.at(i)->spec; }
const ExitStatus& ProcessGroup::status(std::size_t i) const { return children_.at(i)->status; }

}  // namespace pixyslam::launcher
